#pragma once
// Grey-scale images for image-defined microstructures: PGM (P2, P5), uncompressed BMP (8-bit
// palettised, 24-bit), PNG (libpng) and TIFF (libtiff) readers, a PGM writer. Labelling of grains:
// microstructure.hpp.
#include <cstdint>
#include <string>
#include <vector>

namespace frictherm::mechanics {

/// The most pixels an image may have (25 megapixels, e.g. 5000 x 5000): refused from the header,
/// before any pixel buffer exists, so a compressed image cannot decode into gigabytes (a PNG packs
/// zeros about 1000:1). A microstructure finer than the particles gains nothing; downsample larger ones.
constexpr double kMaxImagePixels = 25e6;

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

/// Reads a PNG (libpng): grey, grey + alpha, RGB, RGBA or palette, 1 to 16 bits. Grey of 8 or fewer
/// bits gives max_value 255 (1, 2 and 4 bit scaled up: 1 bit is 0 or 255), 16 bits max_value 65535;
/// colour becomes grey by the BMP rule, round(0.299 R + 0.587 G + 0.114 B), per 8- or 16-bit sample;
/// alpha and transparency are ignored. The header's size is checked against the file's before any
/// allocation (deflate packs at most 1032:1). Throws std::runtime_error naming the file and the problem.
GreyImage read_png(const std::string& path);

/// Reads the first image of a TIFF (libtiff): 8 or 16 bit unsigned grey (min-is-black, or
/// min-is-white, inverted) or RGB (grey by the BMP rule; extra samples such as alpha ignored), in
/// strips with interleaved samples, any compression libtiff decodes. The header's size is checked
/// against the file's before allocation (raw: 1:1, compressed: at most 4096:1). Throws
/// std::runtime_error naming the file and the problem.
GreyImage read_tiff(const std::string& path);

/// Reads a PGM, BMP, PNG or TIFF file, chosen by its first two bytes ("P2"/"P5", "BM", "\x89P", "II"/"MM").
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
