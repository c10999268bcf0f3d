// PNG reading with libpng's classic interface: png_set_* transforms turn every colour type and
// bit depth into 8-bit grey (image.hpp). Errors come back through setjmp/longjmp: the function
// that calls setjmp holds only the libpng handles, the FILE and pre-sized buffers, so the jump
// skips no C++ destructor.
#include "cairn/geometry/image.hpp"

#include <fmt/format.h>
#include <fnmatch.h>
#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>

namespace cairn {
namespace {

struct ErrorState {
  char message[512] = {0};
};

void on_error(png_structp png, png_const_charp msg) {
  auto* state = static_cast<ErrorState*>(png_get_error_ptr(png));
  if (state) std::snprintf(state->message, sizeof state->message, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // e.g. "iCCP: known incorrect sRGB profile"

/// Header pass and transforms: fills width/height; returns false after a libpng error.
bool read_header(png_structp png, png_infop info, std::FILE* fp, png_uint_32& width, png_uint_32& height) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, fp);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const int colour = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (depth == 16) {
#ifdef PNG_READ_SCALE_16_TO_8_SUPPORTED
    png_set_scale_16(png);
#else
    png_set_strip_16(png);
#endif
  }
  png_set_strip_alpha(png);
  if (colour == PNG_COLOR_TYPE_RGB || colour == PNG_COLOR_TYPE_RGB_ALPHA ||
      colour == PNG_COLOR_TYPE_PALETTE)
    png_set_rgb_to_gray_fixed(png, 1, 21268, 71514);  // Rec. 709: 0.21268, 0.71514, (0.07218)
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  width = png_get_image_width(png, info);
  height = png_get_image_height(png, info);
  return true;
}

/// Pixel pass into rows[] (height pointers into one buffer); false after a libpng error.
bool read_pixels(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

}  // namespace

GreyImage read_png_grey(const std::string& path) {
  auto fail = [&](const std::string& why) {
    return std::invalid_argument("image '" + path + "': " + why);
  };
  std::FILE* fp = std::fopen(path.c_str(), "rb");
  if (!fp) throw fail(std::string("cannot open: ") + std::strerror(errno));
  png_byte signature[8] = {0};
  const std::size_t got = std::fread(signature, 1, 8, fp);
  if (got != 8 || png_sig_cmp(signature, 0, 8) != 0) {
    std::fclose(fp);
    throw fail("not a PNG file");
  }
  ErrorState state;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    throw fail("libpng could not allocate its structures");
  }
  png_uint_32 width = 0, height = 0;
  if (!read_header(png, info, fp, width, height)) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    throw fail(state.message);
  }
  // The header's size decides the allocation: refuse a claim beyond the limit before it.
  if (static_cast<double>(width) * static_cast<double>(height) > static_cast<double>(max_image_pixels)) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    throw fail("its header claims " + std::to_string(width) + " x " + std::to_string(height) +
               " pixels, more than the " + std::to_string(max_image_pixels) + " an image may have");
  }
  const int channels = png_get_channels(png, info);
  const int depth = png_get_bit_depth(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  if (channels != 1 || depth != 8 || row_bytes != width) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    throw fail("unsupported pixel layout after conversion to grey (" + std::to_string(channels) +
               " channels, " + std::to_string(depth) + " bits)");
  }
  GreyImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.level.assign(static_cast<std::size_t>(width) * height, 0);
  std::vector<png_bytep> rows(height);
  for (png_uint_32 r = 0; r < height; ++r) rows[r] = image.level.data() + static_cast<std::size_t>(r) * width;
  const bool ok = read_pixels(png, info, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(fp);
  if (!ok) throw fail(state.message);
  return image;
}

GreyImage read_png_stack(const std::string& folder, const std::string& pattern) {
  namespace fs = std::filesystem;
  auto fail = [&](const std::string& why) {
    return std::invalid_argument("image stack '" + folder + "': " + why);
  };
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw fail("not a folder");
  // The slices by number: the last run of digits in each matching name.
  std::map<long long, std::string> by_number;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || fnmatch(pattern.c_str(), name.c_str(), 0) != 0) continue;
    const std::size_t last = name.find_last_of("0123456789");
    if (last == std::string::npos)
      throw fail(fmt::format("'{}' has no slice number (slices are ordered by the last number in their names)",
                             name));
    const std::size_t first = name.find_last_not_of("0123456789", last) + 1;  // npos + 1 = 0
    if (last - first >= 15) throw fail(fmt::format("'{}': slice number of more than 15 digits", name));
    const long long number = std::stoll(name.substr(first, last - first + 1));
    const auto [at, fresh] = by_number.emplace(number, name);
    if (!fresh) throw fail(fmt::format("'{}' and '{}' have the same slice number {}", at->second, name, number));
  }
  if (ec) throw fail("cannot list it: " + ec.message());
  if (by_number.empty()) throw fail(fmt::format("no file matches '{}' (an empty folder?)", pattern));
  for (auto it = std::next(by_number.begin()); it != by_number.end(); ++it) {
    const auto before = std::prev(it);
    if (it->first != before->first + 1)
      throw fail(fmt::format("slice {} is missing: the numbers jump from '{}' to '{}'", before->first + 1,
                             before->second, it->second));
  }
  GreyImage stack;
  stack.depth = static_cast<int>(by_number.size());
  for (const auto& [number, name] : by_number) {
    const std::string path = (fs::path(folder) / name).string();
    GreyImage slice = read_png_grey(path);
    if (stack.files.empty()) {
      stack.width = slice.width;
      stack.height = slice.height;
      const double voxels = static_cast<double>(slice.width) * slice.height * stack.depth;
      if (voxels > static_cast<double>(max_stack_voxels))
        throw fail(fmt::format("{} slices of {} x {} pixels, more than the {} voxels a stack may have", stack.depth,
                               slice.width, slice.height, max_stack_voxels));
      stack.level.reserve(static_cast<std::size_t>(voxels));
    } else if (slice.width != stack.width || slice.height != stack.height) {
      throw fail(fmt::format("slice '{}' is {} x {} pixels, the first slice '{}' {} x {}", name, slice.width,
                             slice.height, fs::path(stack.files.front()).filename().string(), stack.width,
                             stack.height));
    }
    stack.level.insert(stack.level.end(), slice.level.begin(), slice.level.end());
    stack.files.push_back(path);
  }
  return stack;
}

std::string resolve_input_relative(const std::string& file, const std::string& input_file) {
  namespace fs = std::filesystem;
  fs::path p(file);
  if (p.is_relative()) p = fs::path(input_file).parent_path() / p;
  return fs::absolute(p).lexically_normal().string();
}

}  // namespace cairn
