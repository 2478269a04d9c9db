#pragma once
// Grey-scale images for image-defined microstructures: PGM (P2, P5) and uncompressed BMP (8-bit
// palettised, 24-bit) readers, a PGM writer. Labelling of grains: microstructure.hpp.
#include <cstdint>
#include <string>
#include <vector>

namespace frictherm::mechanics {

struct GreyImage {
  int width = 0, height = 0;
  int max_value = 255;
  std::vector<std::uint16_t> pixels;  // row-major, row 0 is the TOP row of the picture
  int at(int column, int row) const { return pixels[static_cast<std::size_t>(row) * width + column]; }
};

/// Reads a PGM file (ASCII P2 or binary P5, 8 or 16 bit). Throws std::runtime_error naming the
/// file and the problem.
GreyImage read_pgm(const std::string& path);

/// Reads an uncompressed Windows bitmap (BI_RGB): 8-bit palettised (grey = the palette entry's
/// luma) or 24-bit (grey = luma of each pixel), luma = round(0.299 R + 0.587 G + 0.114 B) (ITU-R
/// BT.601; exact for grey pictures, R = G = B). Bottom-up and top-down files. Other bit depths and
/// compressed files are refused with std::runtime_error naming the file and what was found.
GreyImage read_bmp(const std::string& path);

/// Reads a PGM or BMP file, chosen by its first two bytes ("P2"/"P5" or "BM").
GreyImage read_grey_image(const std::string& path);

/// Writes `image` as binary PGM (P5; one byte per pixel when max_value <= 255, else two, big
/// endian). `comment` (one line, optional) goes into the header. Throws std::runtime_error.
void write_pgm(const GreyImage& image, const std::string& path, const std::string& comment = "");

/// Pixels whose grey level lies in [min_level, max_level] become `material`.
struct GreyLevelMaterial {
  int min_level = 0;
  int max_level = 255;
  int material = 0;
};

}  // namespace frictherm::mechanics
