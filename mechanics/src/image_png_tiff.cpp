// PNG (libpng) and TIFF (libtiff) micrographs as grey images (image.hpp). Both check the header's
// pixel count against the file size before any pixel buffer is allocated: a PNG's pixels are
// deflate-compressed, which packs at most 1032 bytes into one, and a TIFF's are stored raw or
// compressed by at most 4096:1 (LZW: a 9-bit or longer code stands for at most 4096 bytes).
#include <frictherm/mechanics/image.hpp>

#include <png.h>
#include <tiffio.h>

#include <csetjmp>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::mechanics {

namespace {

// ITU-R BT.601 luma, rounded (the BMP reader's rule, image.cpp): R = G = B gives that value back.
std::uint16_t luma(unsigned r, unsigned g, unsigned b) {
  return static_cast<std::uint16_t>((299u * r + 587u * g + 114u * b + 500u) / 1000u);
}

std::uintmax_t file_size(const std::string& path, const std::string& kind) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error(kind + " file '" + path + "' is not a regular file (a folder, device or pipe)");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw std::runtime_error("cannot open image file '" + path + "': " + ec.message());
  if (size == 0) throw std::runtime_error(kind + " file '" + path + "' is empty");
  return size;
}

// Empty when the header's claim fits the file, else the refusal.
std::string claim_problem(const std::string& where, std::uint32_t width, std::uint32_t height, double bytes_needed,
                          std::uintmax_t file_bytes, double ratio) {
  if (width == 0 || height == 0 || width > 1000000 || height > 1000000)
    return where + "bad width or height " + std::to_string(width) + "x" + std::to_string(height);
  if (static_cast<double>(width) * height > kMaxImagePixels)
    return where + std::to_string(width) + "x" + std::to_string(height) +
           " pixels; expected at most 25e6 pixels (kMaxImagePixels)";
  if (bytes_needed > ratio * static_cast<double>(file_bytes))
    return where + "header claims " + std::to_string(width) + "x" + std::to_string(height) +
           " pixels but the file holds only " + std::to_string(file_bytes) + " bytes (truncated or corrupt)";
  return "";
}

// ---- PNG ----
struct PngErrors {
  char message[512] = "";
  std::jmp_buf jump;
};

void png_error_handler(png_structp png, png_const_charp text) {
  auto* e = static_cast<PngErrors*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof e->message, "%s", text);
  std::longjmp(e->jump, 1);
}
void png_warning_handler(png_structp, png_const_charp) {}  // warnings (e.g. unknown chunks) are not errors

}  // namespace

GreyImage read_png(const std::string& path) {
  const std::string where = "PNG file '" + path + "': ";
  const std::uintmax_t bytes = file_size(path, "PNG");
  // Every C++ object the reading touches exists before setjmp (a longjmp must not skip destructors).
  GreyImage img;
  std::vector<unsigned char> raw;
  std::vector<png_bytep> rows;
  std::string refusal;
  PngErrors errors;
  FILE* fp = std::fopen(path.c_str(), "rb");
  if (!fp) throw std::runtime_error("cannot open image file '" + path + "'");
  unsigned char signature[8] = {0};
  if (std::fread(signature, 1, 8, fp) != 8 || png_sig_cmp(signature, 0, 8) != 0) {
    std::fclose(fp);
    throw std::runtime_error("image file '" + path + "' is not a PNG (expected the PNG signature)");
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &errors, png_error_handler, png_warning_handler);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(png ? &png : nullptr, nullptr, nullptr);
    std::fclose(fp);
    throw std::runtime_error(where + "out of memory");
  }
  if (setjmp(errors.jump) == 0) {
    png_init_io(png, fp);
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
    const int depth = png_get_bit_depth(png, info), type = png_get_color_type(png, info);
    if (type & PNG_COLOR_MASK_PALETTE) png_set_palette_to_rgb(png);
    if (type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);  // 1 bit: 0 and 255
    if (type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);  // transparency is ignored
    if (png_get_valid(png, info, PNG_INFO_tRNS)) {
      png_set_tRNS_to_alpha(png);
      png_set_strip_alpha(png);
    }
    png_read_update_info(png, info);
    const int channels = png_get_channels(png, info), out_depth = png_get_bit_depth(png, info);
    const std::size_t row_bytes = png_get_rowbytes(png, info);
    refusal = claim_problem(where, width, height, static_cast<double>(height) * static_cast<double>(row_bytes), bytes, 1032.0);
    if (!refusal.empty()) {
      // refused before any pixel buffer is allocated
    } else if ((channels != 1 && channels != 3) || (out_depth != 8 && out_depth != 16)) {
      refusal = where + "unsupported layout (" + std::to_string(channels) + " channels of " +
                std::to_string(out_depth) + " bits)";
    } else {
      raw.resize(row_bytes * height);
      rows.resize(height);
      for (png_uint_32 r = 0; r < height; ++r) rows[r] = raw.data() + row_bytes * r;
      png_read_image(png, rows.data());  // a truncated or corrupt stream longjmps to the else branch
      png_read_end(png, nullptr);
      img.width = static_cast<int>(width);
      img.height = static_cast<int>(height);
      img.max_value = out_depth == 16 ? 65535 : 255;
      img.pixels.resize(static_cast<std::size_t>(width) * height);
      const std::size_t step = out_depth == 16 ? 2 : 1;
      for (std::size_t k = 0; k < img.pixels.size(); ++k) {
        unsigned v[3] = {0, 0, 0};
        for (int c = 0; c < channels; ++c) {
          const unsigned char* p = &raw[(k * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)) * step];
          v[c] = step == 2 ? (static_cast<unsigned>(p[0]) << 8) | p[1] : p[0];  // PNG samples are big endian
        }
        img.pixels[k] = channels == 1 ? static_cast<std::uint16_t>(v[0]) : luma(v[0], v[1], v[2]);
      }
    }
  } else {
    refusal = where + errors.message + " (truncated or corrupt)";
  }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(fp);
  if (!refusal.empty()) throw std::runtime_error(refusal);
  return img;
}

// ---- TIFF ----
namespace {

thread_local std::string tiff_last_error;
void tiff_error_handler(const char* module, const char* fmt, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, fmt, ap);
  tiff_last_error = std::string(module ? module : "libtiff") + ": " + text;
}
void tiff_warning_handler(const char*, const char*, va_list) {}

struct TiffCloser {
  TIFF* t;
  ~TiffCloser() {
    if (t) TIFFClose(t);
  }
};

}  // namespace

GreyImage read_tiff(const std::string& path) {
  const std::string where = "TIFF file '" + path + "': ";
  const std::uintmax_t bytes = file_size(path, "TIFF");
  TIFFSetErrorHandler(tiff_error_handler);
  TIFFSetWarningHandler(tiff_warning_handler);
  tiff_last_error.clear();
  const TiffCloser tif{TIFFOpen(path.c_str(), "r")};
  if (!tif.t) throw std::runtime_error(where + "cannot be read (" + tiff_last_error + ")");
  std::uint32_t width = 0, height = 0;
  std::uint16_t bits = 0, samples = 1, photometric = 0, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG,
                compression = COMPRESSION_NONE;
  if (!TIFFGetField(tif.t, TIFFTAG_IMAGEWIDTH, &width) || !TIFFGetField(tif.t, TIFFTAG_IMAGELENGTH, &height) ||
      !TIFFGetField(tif.t, TIFFTAG_PHOTOMETRIC, &photometric))
    throw std::runtime_error(where + "missing width, height or photometric interpretation");
  TIFFGetFieldDefaulted(tif.t, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif.t, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif.t, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif.t, TIFFTAG_PLANARCONFIG, &planar);
  TIFFGetFieldDefaulted(tif.t, TIFFTAG_COMPRESSION, &compression);
  const bool grey = photometric == PHOTOMETRIC_MINISBLACK || photometric == PHOTOMETRIC_MINISWHITE;
  const bool rgb = photometric == PHOTOMETRIC_RGB;
  if (!((grey && samples >= 1) || (rgb && samples >= 3)) || (bits != 8 && bits != 16) || format != SAMPLEFORMAT_UINT ||
      (planar != PLANARCONFIG_CONTIG && samples > 1) || TIFFIsTiled(tif.t))
    throw std::runtime_error(where + "unsupported layout (photometric " + std::to_string(photometric) + ", " +
                             std::to_string(samples) + " samples of " + std::to_string(bits) +
                             " bits, sample format " + std::to_string(format) +
                             "); expected 8 or 16 bit unsigned grey or RGB in strips, samples interleaved");
  const double row_bytes = static_cast<double>(width) * samples * (bits / 8);
  const std::string problem = claim_problem(where, width, height, row_bytes * height, bytes,
                                            compression == COMPRESSION_NONE ? 1.0 : 4096.0);
  if (!problem.empty()) throw std::runtime_error(problem);
  const tmsize_t scanline = TIFFScanlineSize(tif.t);
  if (scanline < static_cast<tmsize_t>(row_bytes)) throw std::runtime_error(where + "inconsistent scanline size");
  GreyImage img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  img.max_value = bits == 16 ? 65535 : 255;
  img.pixels.resize(static_cast<std::size_t>(width) * height);
  std::vector<unsigned char> line(static_cast<std::size_t>(scanline));
  for (std::uint32_t r = 0; r < height; ++r) {
    if (TIFFReadScanline(tif.t, line.data(), r, 0) < 0)
      throw std::runtime_error(where + "row " + std::to_string(r) + " cannot be read (" + tiff_last_error +
                               "; truncated or corrupt)");
    for (std::uint32_t c = 0; c < width; ++c) {
      unsigned v[3] = {0, 0, 0};
      const int used = rgb ? 3 : 1;
      for (int s = 0; s < used; ++s) {
        const std::size_t at = (static_cast<std::size_t>(c) * samples + static_cast<std::size_t>(s)) * (bits / 8);
        if (bits == 16) {
          std::uint16_t w;
          std::memcpy(&w, &line[at], 2);  // libtiff hands samples over in the machine's byte order
          v[s] = w;
        } else {
          v[s] = line[at];
        }
      }
      std::uint16_t g = rgb ? luma(v[0], v[1], v[2]) : static_cast<std::uint16_t>(v[0]);
      if (photometric == PHOTOMETRIC_MINISWHITE) g = static_cast<std::uint16_t>(img.max_value - g);  // 0 is white
      img.pixels[static_cast<std::size_t>(r) * width + c] = g;
    }
  }
  return img;
}

}  // namespace frictherm::mechanics
