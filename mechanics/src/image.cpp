#include <frictherm/mechanics/image.hpp>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace frictherm::mechanics {

namespace {
// Next header integer of a PGM, skipping whitespace and '#' comments.
int read_header_int(std::istream& in, const std::string& path) {
  int c;
  while ((c = in.peek()) != EOF) {
    if (std::isspace(c)) {
      in.get();
    } else if (c == '#') {
      std::string line;
      std::getline(in, line);
    } else {
      break;
    }
  }
  int v = -1;
  if (!(in >> v)) throw std::runtime_error("PGM file '" + path + "': truncated or malformed header");
  return v;
}
}  // namespace

GreyImage read_pgm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open image file '" + path + "'");
  char magic[2] = {0, 0};
  in.read(magic, 2);
  if (!in || magic[0] != 'P' || (magic[1] != '2' && magic[1] != '5'))
    throw std::runtime_error("image file '" + path + "' is not a PGM (expected magic P2 or P5)");
  GreyImage img;
  img.width = read_header_int(in, path);
  img.height = read_header_int(in, path);
  img.max_value = read_header_int(in, path);
  if (img.width <= 0 || img.height <= 0 || img.max_value <= 0 || img.max_value > 65535)
    throw std::runtime_error("PGM file '" + path + "': bad width, height or maximum grey value");
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  img.pixels.resize(n);
  if (magic[1] == '2') {
    for (std::size_t k = 0; k < n; ++k) {
      int v;
      if (!(in >> v)) throw std::runtime_error("PGM file '" + path + "': fewer pixels than width*height");
      img.pixels[k] = static_cast<std::uint16_t>(v);
    }
  } else {
    in.get();  // exactly one whitespace byte after the header
    const bool wide = img.max_value > 255;
    std::vector<unsigned char> raw(n * (wide ? 2 : 1));
    in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
    if (static_cast<std::size_t>(in.gcount()) != raw.size())
      throw std::runtime_error("PGM file '" + path + "': fewer pixels than width*height");
    for (std::size_t k = 0; k < n; ++k)
      img.pixels[k] = wide ? static_cast<std::uint16_t>((raw[2 * k] << 8) | raw[2 * k + 1]) : raw[k];
  }
  return img;
}

}  // namespace frictherm::mechanics
