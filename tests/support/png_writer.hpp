// Writes small PNG files with libpng for tests of the image reader and image bodies.
#pragma once

#include <png.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace cairn::test {

/// A fresh, empty temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cairn_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Writes `samples` (height rows from the top, each width * channels samples of bit_depth bits,
/// 16-bit samples given as values 0..65535) as a PNG of the given libpng colour type. For
/// PNG_COLOR_TYPE_PALETTE, `palette` holds the RGB entries and samples are indices.
inline void write_png(const std::string& path, int width, int height, int colour_type, int bit_depth,
                      const std::vector<unsigned>& samples,
                      const std::vector<png_color>& palette = {}) {
  const int channels = colour_type == PNG_COLOR_TYPE_GRAY_ALPHA ? 2
                       : colour_type == PNG_COLOR_TYPE_RGB       ? 3
                       : colour_type == PNG_COLOR_TYPE_RGB_ALPHA ? 4
                                                                 : 1;  // const: not clobbered by setjmp
  if (samples.size() != static_cast<std::size_t>(width * height * channels))
    throw std::logic_error("write_png: wrong number of samples");
  std::FILE* fp = std::fopen(path.c_str(), "wb");
  if (!fp) throw std::runtime_error("write_png: cannot open " + path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(fp);
    throw std::runtime_error("write_png: libpng failed on " + path);
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bit_depth,
               colour_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (colour_type == PNG_COLOR_TYPE_PALETTE)
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  png_write_info(png, info);
  // Pack each row by hand: 1/2/4 bits per sample (MSB first), 8 bits, or 16 bits big-endian.
  const std::size_t row_bytes = (static_cast<std::size_t>(width) * channels * bit_depth + 7) / 8;
  std::vector<png_byte> row(row_bytes);
  for (int r = 0; r < height; ++r) {
    std::fill(row.begin(), row.end(), png_byte{0});
    for (int i = 0; i < width * channels; ++i) {
      const unsigned v = samples[static_cast<std::size_t>(r * width * channels + i)];
      if (bit_depth == 16) {
        row[2 * i] = static_cast<png_byte>(v >> 8);
        row[2 * i + 1] = static_cast<png_byte>(v & 0xff);
      } else if (bit_depth == 8) {
        row[i] = static_cast<png_byte>(v);
      } else {
        const int bit = i * bit_depth;
        row[bit / 8] |= static_cast<png_byte>(v << (8 - bit_depth - bit % 8));
      }
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(fp);
}

/// An 8-bit grey PNG of `levels` (height rows from the top, width levels each).
inline void write_grey_png(const std::string& path, int width, int height,
                           const std::vector<unsigned>& levels) {
  write_png(path, width, height, PNG_COLOR_TYPE_GRAY, 8, levels);
}

}  // namespace cairn::test
