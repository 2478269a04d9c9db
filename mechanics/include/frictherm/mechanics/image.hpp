#pragma once
// Grey-scale images (PGM, P2 and P5) for image-defined microstructures.
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

/// Pixels whose grey level lies in [min_level, max_level] become `material`.
struct GreyLevelMaterial {
  int min_level = 0;
  int max_level = 255;
  int material = 0;
};

}  // namespace frictherm::mechanics
