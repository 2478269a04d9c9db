#include <frictherm/mechanics/image.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
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

// Little-endian fields of a BMP header.
std::uint32_t u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint16_t u16(const unsigned char* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }

// ITU-R BT.601 luma, rounded; R = G = B gives that value back exactly.
std::uint16_t luma(int r, int g, int b) { return static_cast<std::uint16_t>((299 * r + 587 * g + 114 * b + 500) / 1000); }

// Images are regular files: a folder, /dev/zero, /dev/urandom or a FIFO would be read without end
// (or block), and their size cannot bound a header's claim.
void require_regular_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw std::runtime_error("cannot open image file '" + path + "'");
  if (!std::filesystem::is_regular_file(status))
    throw std::runtime_error("image file '" + path + "' is not a regular file (a folder, device or pipe)");
}

std::vector<unsigned char> read_all(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open image file '" + path + "'");
  std::ostringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  return std::vector<unsigned char>(text.begin(), text.end());
}
}  // namespace

GreyImage read_pgm(const std::string& path) {
  require_regular_file(path);
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
  if (static_cast<double>(img.width) * img.height > kMaxImagePixels)
    throw std::runtime_error("PGM file '" + path + "': " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                             " pixels; expected at most 25e6 pixels (kMaxImagePixels)");
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  // Header checked against the file size before the pixel buffer is sized: a P5 pixel takes 1 or 2
  // bytes, a P2 pixel at least one digit plus a separator (the last one none).
  const std::streamoff here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff left = in.tellg() - here;
  in.seekg(here);
  const double need = magic[1] == '2' ? 2.0 * static_cast<double>(n) - 1.0
                                      : static_cast<double>(n) * (img.max_value > 255 ? 2.0 : 1.0);
  if (here < 0 || static_cast<double>(left) < need)
    throw std::runtime_error("PGM file '" + path + "': header claims " + std::to_string(img.width) + "x" +
                             std::to_string(img.height) + " pixels but the file holds only " +
                             std::to_string(static_cast<long long>(left)) + " bytes after the header");
  img.pixels.resize(n);
  if (magic[1] == '2') {
    for (std::size_t k = 0; k < n; ++k) {
      int v;
      if (!(in >> v)) throw std::runtime_error("PGM file '" + path + "': fewer pixels than width*height");
      if (v < 0 || v > img.max_value)
        throw std::runtime_error("PGM file '" + path + "': pixel " + std::to_string(k) + " has value " +
                                 std::to_string(v) + ", outside [0, " + std::to_string(img.max_value) + "]");
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

GreyImage read_bmp(const std::string& path) {
  const std::vector<unsigned char> f = read_all(path);
  const std::string where = "BMP file '" + path + "': ";
  if (f.size() < 2 || f[0] != 'B' || f[1] != 'M')
    throw std::runtime_error("image file '" + path + "' is not a BMP (expected magic BM)");
  if (f.size() < 14 + 40) throw std::runtime_error(where + "truncated header");
  const std::uint32_t data_offset = u32(&f[10]);
  const std::uint32_t header_size = u32(&f[14]);
  if (header_size < 40)
    throw std::runtime_error(where + "unsupported header of " + std::to_string(header_size) +
                             " bytes (expected a BITMAPINFOHEADER or later, 40 bytes or more)");
  const auto width = static_cast<std::int32_t>(u32(&f[18]));
  const auto height_signed = static_cast<std::int32_t>(u32(&f[22]));
  const int planes = u16(&f[26]);
  const int bits = u16(&f[28]);
  const std::uint32_t compression = u32(&f[30]);
  std::uint32_t colours = u32(&f[46]);
  if (planes != 1) throw std::runtime_error(where + "expected 1 colour plane, found " + std::to_string(planes));
  if (bits != 8 && bits != 24)
    throw std::runtime_error(where + std::to_string(bits) +
                             " bits per pixel is not supported (expected 8-bit palettised or 24-bit)");
  if (compression != 0)
    throw std::runtime_error(where + "compression type " + std::to_string(compression) +
                             " is not supported (expected uncompressed BI_RGB, 0)");
  if (width <= 0 || height_signed == 0 || height_signed == INT32_MIN || width > 1000000 ||
      std::abs(height_signed) > 1000000)
    throw std::runtime_error(where + "bad width or height");
  if (static_cast<double>(width) * std::abs(static_cast<double>(height_signed)) > kMaxImagePixels)
    throw std::runtime_error(where + std::to_string(width) + "x" + std::to_string(std::abs(height_signed)) +
                             " pixels; expected at most 25e6 pixels (kMaxImagePixels)");
  const bool top_down = height_signed < 0;
  const int height = std::abs(height_signed);
  // Palette (8 bit): entries of B, G, R, 0 right after the info header.
  std::vector<std::uint16_t> palette;
  if (bits == 8) {
    if (colours == 0) colours = 256;
    if (colours > 256) throw std::runtime_error(where + "palette of " + std::to_string(colours) + " colours (at most 256)");
    const std::size_t p0 = 14 + static_cast<std::size_t>(header_size);
    if (p0 + 4 * static_cast<std::size_t>(colours) > f.size()) throw std::runtime_error(where + "truncated palette");
    for (std::uint32_t c = 0; c < colours; ++c) {
      const unsigned char* e = &f[p0 + 4 * c];
      palette.push_back(luma(e[2], e[1], e[0]));
    }
  }
  const std::size_t bytes_pp = static_cast<std::size_t>(bits / 8);
  const std::size_t stride = (static_cast<std::size_t>(width) * bytes_pp + 3) / 4 * 4;  // rows padded to 4 bytes
  if (data_offset > f.size() || f.size() - data_offset < stride * static_cast<std::size_t>(height))
    throw std::runtime_error(where + "fewer pixels than width*height");
  GreyImage img;
  img.width = width;
  img.height = height;
  img.max_value = 255;
  img.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int r = 0; r < height; ++r) {
    const int file_row = top_down ? r : height - 1 - r;  // bottom-up files store the bottom row first
    const unsigned char* row = &f[data_offset + stride * static_cast<std::size_t>(file_row)];
    for (int c = 0; c < width; ++c) {
      std::uint16_t v;
      if (bits == 8) {
        const unsigned idx = row[c];
        if (idx >= palette.size())
          throw std::runtime_error(where + "pixel index " + std::to_string(idx) + " outside the palette of " +
                                   std::to_string(palette.size()) + " colours");
        v = palette[idx];
      } else {
        const unsigned char* p = row + 3 * static_cast<std::size_t>(c);
        v = luma(p[2], p[1], p[0]);
      }
      img.pixels[static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c)] = v;
    }
  }
  return img;
}

GreyImage read_grey_image(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open image file '" + path + "'");
  char magic[2] = {0, 0};
  in.read(magic, 2);
  if (in && magic[0] == 'P' && (magic[1] == '2' || magic[1] == '5')) return read_pgm(path);
  if (in && magic[0] == 'B' && magic[1] == 'M') return read_bmp(path);
  if (in && static_cast<unsigned char>(magic[0]) == 0x89 && magic[1] == 'P') return read_png(path);
  if (in && ((magic[0] == 'I' && magic[1] == 'I') || (magic[0] == 'M' && magic[1] == 'M'))) return read_tiff(path);
  throw std::runtime_error("image file '" + path +
                           "' is none of PGM (magic P2 or P5), BMP (BM), PNG (\\x89PNG) or TIFF (II or MM)");
}

void write_pgm(const GreyImage& image, const std::string& path, const std::string& comment) {
  const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != n || image.max_value <= 0 ||
      image.max_value > 65535)
    throw std::runtime_error("write_pgm('" + path + "'): the image is empty or inconsistent");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot create image file '" + path + "'");
  out << "P5\n";
  if (!comment.empty()) {
    std::string line = comment;
    for (char& c : line)
      if (c == '\n' || c == '\r') c = ' ';
    out << "# " << line << '\n';
  }
  out << image.width << ' ' << image.height << '\n' << image.max_value << '\n';
  const bool wide = image.max_value > 255;
  std::vector<unsigned char> raw(n * (wide ? 2 : 1));
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint16_t v = std::min<std::uint16_t>(image.pixels[k], static_cast<std::uint16_t>(image.max_value));
    if (wide) {
      raw[2 * k] = static_cast<unsigned char>(v >> 8);
      raw[2 * k + 1] = static_cast<unsigned char>(v & 0xff);
    } else {
      raw[k] = static_cast<unsigned char>(v);
    }
  }
  out.write(reinterpret_cast<const char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write image file '" + path + "'");
}

}  // namespace frictherm::mechanics
