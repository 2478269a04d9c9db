// Grey-scale images: BMP reader (8-bit palettised, 24-bit), magic-byte dispatch, PGM writer,
// connected-component labelling of grains and the per-pixel material region.
#include <frictherm/mechanics/microstructure.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace frictherm::mechanics;

namespace {

std::string temp(const std::string& name) { return ::testing::TempDir() + "frictherm_img_" + name; }

void put32(std::vector<unsigned char>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<unsigned char>(v >> (8 * i));
}
void put16(std::vector<unsigned char>& b, std::size_t at, std::uint16_t v) {
  b[at] = static_cast<unsigned char>(v & 0xff);
  b[at + 1] = static_cast<unsigned char>(v >> 8);
}

/// A BMP with a BITMAPINFOHEADER; `rows` are the file's rows in file order, each already padded.
std::vector<unsigned char> bmp(int width, int height, int bits, std::uint32_t compression,
                               const std::vector<std::array<unsigned char, 3>>& palette_rgb,
                               const std::vector<std::vector<unsigned char>>& rows) {
  const std::size_t palette_bytes = 4 * palette_rgb.size();
  const std::size_t offset = 14 + 40 + palette_bytes;
  std::vector<unsigned char> b(offset, 0);
  b[0] = 'B';
  b[1] = 'M';
  put32(b, 10, static_cast<std::uint32_t>(offset));
  put32(b, 14, 40);
  put32(b, 18, static_cast<std::uint32_t>(width));
  put32(b, 22, static_cast<std::uint32_t>(height));
  put16(b, 26, 1);
  put16(b, 28, static_cast<std::uint16_t>(bits));
  put32(b, 30, compression);
  put32(b, 46, static_cast<std::uint32_t>(palette_rgb.size()));
  for (std::size_t i = 0; i < palette_rgb.size(); ++i) {
    b[54 + 4 * i] = palette_rgb[i][2];  // B, G, R, 0
    b[54 + 4 * i + 1] = palette_rgb[i][1];
    b[54 + 4 * i + 2] = palette_rgb[i][0];
  }
  for (const auto& r : rows) b.insert(b.end(), r.begin(), r.end());
  put32(b, 2, static_cast<std::uint32_t>(b.size()));
  return b;
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& b) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::string error_of(const std::string& path) {
  try {
    read_grey_image(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ImageIO, Bmp8BitPalettisedBottomUp) {
  // 3 x 2 pixels, rows padded from 3 to 4 bytes. Palette: 0 black, 1 grey 200, 2 pure red.
  // File rows are bottom-up: the first stored row is the picture's bottom row.
  const std::string path = temp("p8.bmp");
  write_bytes(path, bmp(3, 2, 8, 0, {{0, 0, 0}, {200, 200, 200}, {255, 0, 0}},
                        {{1, 0, 2, 0xAA},     // bottom row
                         {0, 1, 1, 0xAA}}));  // top row
  const GreyImage img = read_grey_image(path);
  ASSERT_EQ(img.width, 3);
  ASSERT_EQ(img.height, 2);
  EXPECT_EQ(img.max_value, 255);
  EXPECT_EQ(img.at(0, 0), 0);    // top row
  EXPECT_EQ(img.at(1, 0), 200);  // a grey palette entry gives its level exactly
  EXPECT_EQ(img.at(0, 1), 200);  // bottom row
  EXPECT_EQ(img.at(2, 1), 76);   // red: round(0.299 * 255) = 76 (BT.601 luma)
  std::remove(path.c_str());
}

TEST(ImageIO, Bmp24BitTopDown) {
  // 3 x 2 pixels, 9 bytes per row padded to 12; negative height: rows stored top first.
  const std::string path = temp("p24.bmp");
  std::vector<unsigned char> top{10, 10, 10, 0, 255, 0, 100, 100, 100, 0, 0, 0};  // B, G, R per pixel
  std::vector<unsigned char> bottom{255, 255, 255, 0, 0, 255, 30, 30, 30, 0, 0, 0};
  write_bytes(path, bmp(3, -2, 24, 0, {}, {top, bottom}));
  const GreyImage img = read_bmp(path);
  EXPECT_EQ(img.at(0, 0), 10);
  EXPECT_EQ(img.at(1, 0), 150);  // green: round(0.587 * 255) = 150
  EXPECT_EQ(img.at(2, 0), 100);
  EXPECT_EQ(img.at(0, 1), 255);
  EXPECT_EQ(img.at(1, 1), 76);  // red
  EXPECT_EQ(img.at(2, 1), 30);
  std::remove(path.c_str());
}

TEST(ImageIO, BmpRefusesOtherFormatsWithAClearMessage) {
  const std::string path = temp("bad.bmp");
  write_bytes(path, bmp(4, 1, 32, 0, {}, {std::vector<unsigned char>(16, 0)}));
  EXPECT_NE(error_of(path).find("32 bits per pixel is not supported"), std::string::npos) << error_of(path);
  write_bytes(path, bmp(4, 1, 8, 1, {{0, 0, 0}}, {std::vector<unsigned char>(4, 0)}));  // BI_RLE8
  EXPECT_NE(error_of(path).find("compression type 1 is not supported"), std::string::npos) << error_of(path);
  write_bytes(path, bmp(4, 1, 4, 0, {{0, 0, 0}}, {std::vector<unsigned char>(4, 0)}));
  EXPECT_NE(error_of(path).find("4 bits per pixel"), std::string::npos) << error_of(path);
  write_bytes(path, bmp(4, 2, 24, 0, {}, {std::vector<unsigned char>(12, 0)}));  // one row missing
  EXPECT_NE(error_of(path).find("fewer pixels"), std::string::npos) << error_of(path);
  write_bytes(path, bmp(2, 1, 8, 0, {{0, 0, 0}}, {{0, 5, 0, 0}}));  // index 5, palette of 1
  EXPECT_NE(error_of(path).find("outside the palette"), std::string::npos) << error_of(path);
  write_bytes(path, {'G', 'I', 'F', '8', '9', 'a'});
  EXPECT_NE(error_of(path).find("is none of PGM (magic P2 or P5), BMP (BM), PNG"), std::string::npos) << error_of(path);
  EXPECT_NE(error_of(path + ".missing").find("cannot open"), std::string::npos);
  std::remove(path.c_str());
}

TEST(ImageIO, PgmWriterRoundTrips8And16Bit) {
  const std::string path = temp("rt.pgm");
  GreyImage img;
  img.width = 3;
  img.height = 2;
  img.pixels = {0, 7, 255, 128, 1, 254};
  write_pgm(img, path, "a comment\nwith a newline");
  GreyImage back = read_grey_image(path);  // dispatches on "P5"
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.max_value, 255);
  EXPECT_EQ(back.pixels, img.pixels);
  img.max_value = 65535;
  img.pixels = {0, 300, 65535, 256, 1, 4096};
  write_pgm(img, path);
  back = read_pgm(path);
  EXPECT_EQ(back.max_value, 65535);
  EXPECT_EQ(back.pixels, img.pixels);
  img.pixels.pop_back();
  EXPECT_THROW(write_pgm(img, path), std::runtime_error);
  std::remove(path.c_str());
}

TEST(Labelling, FourAndEightConnectivity) {
  // 255 = grain. Pixels (3,1) and (2,2) touch only at a corner.
  GreyImage img;
  img.width = 5;
  img.height = 3;
  img.pixels = {255, 255, 0, 0,   0,  //
                255, 0,   0, 255, 0,  //
                0,   0, 255, 0,   0};
  const GrainLabels four = label_grains(img, 128, 255, Connectivity::four);
  ASSERT_EQ(four.count(), 3);
  EXPECT_EQ(four.at(0, 0), 1);
  EXPECT_EQ(four.at(1, 0), 1);
  EXPECT_EQ(four.at(0, 1), 1);
  EXPECT_EQ(four.at(3, 1), 2);  // numbered in scan order from the top-left
  EXPECT_EQ(four.at(2, 2), 3);
  EXPECT_EQ(four.pixel_count, (std::vector<std::size_t>{10, 3, 1, 1}));
  const GrainLabels eight = label_grains(img, 128, 255, Connectivity::eight);
  ASSERT_EQ(eight.count(), 2);
  EXPECT_EQ(eight.at(3, 1), 2);
  EXPECT_EQ(eight.at(2, 2), 2);
  EXPECT_EQ(eight.pixel_count, (std::vector<std::size_t>{10, 3, 2}));
  // The complementary range labels the binder: one connected piece (4-connected through the middle).
  EXPECT_EQ(label_grains(img, 0, 127, Connectivity::four).count(), 1);
}

TEST(Labelling, PixelRegionGivesEachPixelItsMaterial) {
  // 2 x 2 pixels of 1 m: top-left a, top-right b, bottom-left empty, bottom-right a.
  PixelMaterials map;
  map.width = 2;
  map.height = 2;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.5, 0.5), IVec<2>{4, 4}));
  Material m;
  m.density = 1000.0;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  const int a = sim.add_material(m), b = sim.add_material(m);
  map.material = {a, b, -1, a};
  const auto region = make_pixel_region<2>(map, Vec<2>(0, 0), 1.0, 0, 0);
  EXPECT_EQ(region->material_at(Vec<2>(0.5, 1.5)), a);
  EXPECT_EQ(region->material_at(Vec<2>(1.5, 1.5)), b);
  EXPECT_EQ(region->material_at(Vec<2>(0.5, 0.5)), -1);
  EXPECT_EQ(region->material_at(Vec<2>(1.5, 0.5)), a);
  EXPECT_EQ(region->material_at(Vec<2>(2.5, 0.5)), -1);  // outside the image
  sim.add_body("pixels", *region, 2, Vec<2>::Zero());
  int na = 0, nb = 0;
  for (int mat : sim.particles().material) (mat == a ? na : nb)++;
  EXPECT_EQ(na, 32);  // two 1 m pixels = 2 x (2 x 2 cells of 0.5 m) x 4 particles
  EXPECT_EQ(nb, 16);
  const auto prism = make_pixel_region<3>(map, Vec<2>(0, 0), 1.0, 0.0, 0.5);
  EXPECT_EQ(prism->material_at(Vec<3>(1.5, 1.5, 0.25)), b);
  EXPECT_EQ(prism->material_at(Vec<3>(1.5, 1.5, 0.75)), -1);
}

// Issue 15: a header larger than the file is refused before the pixel buffer is sized (a 1e10-pixel
// claim would allocate 10 GB), and a P2 value outside [0, maxval] is refused instead of wrapping.
TEST(ImageIO, PgmHeaderCheckedAgainstFileSizeAndPixelRange) {
  const std::string path = temp("bomb.pgm");
  { std::ofstream f(path, std::ios::binary); f << "P5\n4000 4000\n255\n12345678"; }
  EXPECT_NE(error_of(path).find("header claims 4000x4000 pixels"), std::string::npos) << error_of(path);
  // Beyond kMaxImagePixels (25e6) the header alone is refused, whatever the file holds.
  { std::ofstream f(path, std::ios::binary); f << "P5\n100000 100000\n255\n12345678"; }
  EXPECT_NE(error_of(path).find("100000x100000 pixels; expected at most 25e6 pixels"), std::string::npos) << error_of(path);
  { std::ofstream f(path, std::ios::binary); f << "P2\n2 1\n255\n10 300\n"; }
  EXPECT_NE(error_of(path).find("value 300, outside [0, 255]"), std::string::npos) << error_of(path);
  { std::ofstream f(path, std::ios::binary); f << "P2\n2 1\n255\n10 -1\n"; }
  EXPECT_NE(error_of(path).find("value -1, outside [0, 255]"), std::string::npos) << error_of(path);
  std::remove(path.c_str());
}
