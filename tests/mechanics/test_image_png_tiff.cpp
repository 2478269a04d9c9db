// PNG and TIFF micrographs (mechanics/src/image_png_tiff.cpp): small images written here with libpng
// and libtiff read back to the same grey levels, hence the same phase map, as the equivalent PGM;
// colour by the documented luma rule; truncated and corrupt files refused with the file named.
#include <frictherm/mechanics/image.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <png.h>
#include <tiffio.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fm = frictherm::mechanics;
namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

std::string temp(const std::string& name) {
  return (fs::temp_directory_path() / ("frictherm_img_" + std::to_string(getpid()) + "_" + name)).string();
}

// A 7 x 5 test picture: a grain of level `hi` in a binder of level `lo`, plus a ramp row.
std::vector<unsigned> picture(int w, int h, unsigned lo, unsigned hi) {
  std::vector<unsigned> v(static_cast<std::size_t>(w * h), lo);
  for (int r = 1; r < 4; ++r)
    for (int c = 2; c < 5; ++c) v[static_cast<std::size_t>(r * w + c)] = hi;
  for (int c = 0; c < w; ++c) v[static_cast<std::size_t>((h - 1) * w + c)] = lo + (hi - lo) * static_cast<unsigned>(c) / static_cast<unsigned>(w - 1);
  return v;
}

// channels 1 (grey) or 3 (RGB, each pixel's channels given by rgb()), depth 8 or 16.
void write_png(const std::string& path, int w, int h, int channels, int depth, const std::vector<unsigned>& samples) {
  FILE* fp = std::fopen(path.c_str(), "wb");
  ASSERT_NE(fp, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, fp);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), depth,
               channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  const std::size_t bytes = depth / 8;
  std::vector<unsigned char> row(static_cast<std::size_t>(w * channels) * bytes);
  for (int r = 0; r < h; ++r) {
    for (int k = 0; k < w * channels; ++k) {
      const unsigned v = samples[static_cast<std::size_t>(r * w * channels + k)];
      if (bytes == 2) {
        row[2 * static_cast<std::size_t>(k)] = static_cast<unsigned char>(v >> 8);
        row[2 * static_cast<std::size_t>(k) + 1] = static_cast<unsigned char>(v & 0xff);
      } else {
        row[static_cast<std::size_t>(k)] = static_cast<unsigned char>(v);
      }
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(fp);
}

void write_tiff(const std::string& path, int w, int h, int channels, int depth, const std::vector<unsigned>& samples,
                std::uint16_t compression) {
  TIFF* t = TIFFOpen(path.c_str(), "w");
  ASSERT_NE(t, nullptr);
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(w));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(h));
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, static_cast<std::uint16_t>(depth));
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, static_cast<std::uint16_t>(channels));
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, channels == 1 ? PHOTOMETRIC_MINISBLACK : PHOTOMETRIC_RGB);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_COMPRESSION, compression);
  TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, static_cast<std::uint32_t>(2));
  std::vector<unsigned char> line(static_cast<std::size_t>(w * channels * depth / 8));
  for (int r = 0; r < h; ++r) {
    for (int k = 0; k < w * channels; ++k) {
      const unsigned v = samples[static_cast<std::size_t>(r * w * channels + k)];
      if (depth == 16) {
        const std::uint16_t s = static_cast<std::uint16_t>(v);
        std::memcpy(&line[2 * static_cast<std::size_t>(k)], &s, 2);  // machine order, as libtiff expects
      } else {
        line[static_cast<std::size_t>(k)] = static_cast<unsigned char>(v);
      }
    }
    ASSERT_GE(TIFFWriteScanline(t, line.data(), static_cast<std::uint32_t>(r), 0), 0);
  }
  TIFFClose(t);
}

// The reference: the same grey levels through the PGM writer and reader.
fm::GreyImage pgm_of(int w, int h, int max_value, const std::vector<unsigned>& grey, const std::string& name) {
  fm::GreyImage g;
  g.width = w, g.height = h, g.max_value = max_value;
  for (unsigned v : grey) g.pixels.push_back(static_cast<std::uint16_t>(v));
  const std::string path = temp(name + ".pgm");
  fm::write_pgm(g, path);
  fm::GreyImage back = fm::read_grey_image(path);
  fs::remove(path);
  return back;
}

// Phase map of the scene's image levels: material per pixel for two grey-level ranges.
std::vector<int> phases(const fm::GreyImage& g) {
  std::vector<int> m;
  for (std::uint16_t v : g.pixels) m.push_back(2 * v > g.max_value ? 1 : 0);
  return m;
}

void expect_same(const fm::GreyImage& a, const fm::GreyImage& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.max_value, b.max_value);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_EQ(phases(a), phases(b));
}

std::vector<unsigned> rgb_of(const std::vector<unsigned>& grey, unsigned scale) {
  std::vector<unsigned> v;
  for (unsigned g : grey) v.insert(v.end(), {g, (g * 7) % scale, scale - 1 - g});  // genuinely coloured
  return v;
}
std::vector<unsigned> luma_of(const std::vector<unsigned>& rgb) {  // round(0.299 R + 0.587 G + 0.114 B)
  std::vector<unsigned> v;
  for (std::size_t k = 0; k + 2 < rgb.size(); k += 3) v.push_back((299 * rgb[k] + 587 * rgb[k + 1] + 114 * rgb[k + 2] + 500) / 1000);
  return v;
}

}  // namespace

TEST(ImagePngTiff, GreyPngAndTiffGiveThePgmsPhaseMap8And16Bit) {
  const int w = 7, h = 5;
  for (const int depth : {8, 16}) {
    SCOPED_TRACE(depth);
    const int max_value = depth == 16 ? 65535 : 255;
    const std::vector<unsigned> grey = picture(w, h, depth == 16 ? 1000 : 20, depth == 16 ? 60000 : 230);
    const fm::GreyImage ref = pgm_of(w, h, max_value, grey, "ref" + std::to_string(depth));
    const std::string png = temp("g" + std::to_string(depth) + ".png");
    write_png(png, w, h, 1, depth, grey);
    expect_same(fm::read_grey_image(png), ref);
    for (const std::uint16_t compression : {COMPRESSION_NONE, COMPRESSION_LZW, COMPRESSION_ADOBE_DEFLATE}) {
      const std::string tif = temp("g" + std::to_string(depth) + "_" + std::to_string(compression) + ".tif");
      write_tiff(tif, w, h, 1, depth, grey, compression);
      expect_same(fm::read_grey_image(tif), ref);
      fs::remove(tif);
    }
    fs::remove(png);
  }
}

TEST(ImagePngTiff, RgbBecomesGreyByTheLumaRule) {
  const int w = 7, h = 5;
  for (const int depth : {8, 16}) {
    SCOPED_TRACE(depth);
    const unsigned scale = depth == 16 ? 65536 : 256;
    const std::vector<unsigned> rgb = rgb_of(picture(w, h, scale / 10, scale - scale / 10), scale);
    const fm::GreyImage ref = pgm_of(w, h, static_cast<int>(scale - 1), luma_of(rgb), "rgb" + std::to_string(depth));
    const std::string png = temp("c" + std::to_string(depth) + ".png");
    const std::string tif = temp("c" + std::to_string(depth) + ".tif");
    write_png(png, w, h, 3, depth, rgb);
    write_tiff(tif, w, h, 3, depth, rgb, COMPRESSION_LZW);
    expect_same(fm::read_grey_image(png), ref);
    expect_same(fm::read_grey_image(tif), ref);
    fs::remove(png);
    fs::remove(tif);
  }
}

TEST(ImagePngTiff, TruncatedAndCorruptFilesAreRefusedWithTheFileNamed) {
  const int w = 64, h = 48;
  std::vector<unsigned> grey(static_cast<std::size_t>(w * h));
  for (std::size_t k = 0; k < grey.size(); ++k) grey[k] = static_cast<unsigned>((k * 2654435761u) >> 24);  // noise: incompressible
  const std::string png = temp("t.png"), tif = temp("t.tif");
  write_png(png, w, h, 1, 8, grey);
  write_tiff(tif, w, h, 1, 8, grey, COMPRESSION_NONE);
  auto cut = [](const std::string& from, const std::string& to, std::size_t keep) {
    std::ifstream in(from, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(to, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(std::min(keep, bytes.size())));
    return bytes.size();
  };
  auto refused = [](const std::string& path, const std::string& what) {
    try {
      fm::read_grey_image(path);
      ADD_FAILURE() << path << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr(path));
      EXPECT_THAT(e.what(), HasSubstr(what));
    }
  };
  // PNG cut in the pixel stream: libpng's error, the file named.
  const std::string png_cut = temp("cut.png");
  const std::size_t png_size = cut(png, png_cut, 0);
  cut(png, png_cut, png_size / 2);
  refused(png_cut, "truncated or corrupt");
  // A 2000 x 1000 PNG cut to 60 bytes, after the signature, IHDR and the first IDAT chunk's header:
  // 2 MB of rows cannot come out of 60 deflated bytes (at most 1032:1), refused before allocation.
  const std::string big = temp("big.png");
  write_png(big, 2000, 1000, 1, 8, std::vector<unsigned>(2000u * 1000u, 128u));
  cut(big, png_cut, 60);
  refused(png_cut, "header claims 2000x1000 pixels but the file holds only 60 bytes");
  fs::remove(big);
  // TIFF cut in half: libtiff writes the directory after the strips, so it is lost and libtiff refuses.
  const std::string tif_cut = temp("cut.tif");
  const std::size_t tif_size = cut(tif, tif_cut, 0);
  cut(tif, tif_cut, tif_size / 2);
  refused(tif_cut, "TIFF file");
  // TIFF whose directory claims 6400 columns (the width tag patched in place): refused by the size
  // check before any buffer is sized.
  {
    std::fstream f(tif, std::ios::in | std::ios::out | std::ios::binary);
    unsigned char head[8];
    f.read(reinterpret_cast<char*>(head), 8);
    ASSERT_EQ(head[0], 'I');  // little endian on this machine
    const std::uint32_t ifd = head[4] | (head[5] << 8) | (head[6] << 16) | (static_cast<std::uint32_t>(head[7]) << 24);
    f.seekg(ifd);
    unsigned char count[2];
    f.read(reinterpret_cast<char*>(count), 2);
    bool patched = false;
    for (int e = 0; e < (count[0] | (count[1] << 8)); ++e) {
      unsigned char entry[12];
      const std::streamoff at = static_cast<std::streamoff>(ifd) + 2 + 12 * e;
      f.seekg(at);
      f.read(reinterpret_cast<char*>(entry), 12);
      if ((entry[0] | (entry[1] << 8)) != TIFFTAG_IMAGEWIDTH) continue;
      entry[8] = 6400 & 0xff, entry[9] = 6400 >> 8;  // SHORT or LONG: the low bytes come first
      f.seekp(at);
      f.write(reinterpret_cast<char*>(entry), 12);
      patched = true;
    }
    ASSERT_TRUE(patched);
  }
  refused(tif, "header claims 6400x48 pixels but the file holds only");
  // Neither format: the four accepted ones are listed.
  const std::string other = temp("x.gif");
  std::ofstream(other) << "GIF89a....";
  refused(other, "none of PGM");
  for (const auto& p : {png, tif, png_cut, tif_cut, other}) fs::remove(p);
}
