// Grey-level images for bodies drawn as pictures ([[body]] shape `image`, seed 004 Sec. 4.2:
// a bitmap whose pixel shades mark different materials becomes particles).
//
// read_png_grey() reads any PNG (grey, grey+alpha, palette, RGB, RGBA; 1 to 16 bits per
// channel, interlaced or not) as 8-bit grey levels 0..255:
//   - palette entries and grey depths below 8 bits are expanded to 8 bits;
//   - colour becomes luma 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709 weights, on the stored,
//     gamma-encoded values; a pixel with R = G = B keeps that value exactly);
//   - 16-bit samples are scaled to 8 bits (round(v * 255 / 65535));
//   - alpha (and tRNS transparency) is ignored.
// Rows are stored as in the file: row 0 is the TOP row of the picture.
//
// read_png_stack() reads a stack of such pictures (the slices of a CT scan, [[body]] shape
// `image_stack`, 3D) from the files of one folder whose names match a pattern, in the order of
// the number in their names: slice 0 is the file with the lowest number. The numbers must be
// consecutive and every slice must have the first one's width and height.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace cairn {

struct GreyImage {
  int width = 0;
  int height = 0;
  int depth = 1;                    ///< slices: 1 for a picture, n for a stack
  std::vector<std::uint8_t> level;  ///< width * height * depth grey levels, row by row from the top, slice by slice
  std::vector<std::string> files;   ///< a stack's slices in order (empty for one picture)

  /// Grey level of column `col` (0 = left) in row `row` (0 = top) of slice `slice`.
  [[nodiscard]] std::uint8_t at(int col, int row, int slice = 0) const {
    return level[(static_cast<std::size_t>(slice) * static_cast<std::size_t>(height) +
                  static_cast<std::size_t>(row)) *
                     static_cast<std::size_t>(width) +
                 static_cast<std::size_t>(col)];
  }
};

/// Most pixels an image may have (2^28, 256 MiB of grey levels): a header claiming more is
/// refused before anything is allocated.
inline constexpr long long max_image_pixels = 1LL << 28;

/// The image in `path` as 8-bit grey levels. Throws std::invalid_argument naming the path and
/// the reason (cannot open, not a PNG file, too many pixels, libpng's error message) on failure.
GreyImage read_png_grey(const std::string& path);

/// Most voxels a stack may have (2^31, 2 GiB of grey levels), checked before its slices are read.
inline constexpr long long max_stack_voxels = 1LL << 31;

/// The slices of the regular files in `folder` whose names match the glob `pattern` (fnmatch(3),
/// e.g. "*.png" or "ct_*.png"), ordered by the last run of digits in each name. Throws
/// std::invalid_argument naming the folder or the file and the fault: not a folder, no file
/// matching, a name without a number or two names with one number, a missing slice (a gap in the
/// numbers, naming the neighbours), a slice whose size differs from the first's, too many voxels,
/// or a slice that read_png_grey() cannot read.
GreyImage read_png_stack(const std::string& folder, const std::string& pattern);

/// Where an image named in an input file lies: `file` itself when absolute, else `file` relative
/// to the directory of `input_file` (the current directory when input_file has none), made
/// absolute and lexically normal so that it stays valid wherever the resolved input is read.
std::string resolve_input_relative(const std::string& file, const std::string& input_file);

}  // namespace cairn
