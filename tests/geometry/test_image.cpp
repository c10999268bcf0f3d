// Grey-level PNG reading (geometry/image.hpp) for bodies drawn as pictures, and the [[body]] shape
// `image` in the input: paths relative to the input file, validation messages, round trip.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "../support/png_writer.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/geometry/image.hpp"
#include "cairn/input/input.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string read_error(const std::string& path) {
  try {
    read_png_grey(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected std::invalid_argument for " << path;
  return "";
}

TEST(ImageReader, EightBitGreyKeepsLevelsAndRowZeroIsTheTop) {
  const auto dir = test::temp_dir("image_grey");
  const std::string path = (dir / "g.png").string();
  test::write_grey_png(path, 3, 2, {0, 10, 20,  //
                                    200, 254, 255});
  const GreyImage im = read_png_grey(path);
  ASSERT_EQ(im.width, 3);
  ASSERT_EQ(im.height, 2);
  ASSERT_EQ(im.level.size(), 6u);
  EXPECT_EQ(im.at(0, 0), 0);  // first row written = top row
  EXPECT_EQ(im.at(1, 0), 10);
  EXPECT_EQ(im.at(2, 0), 20);
  EXPECT_EQ(im.at(0, 1), 200);
  EXPECT_EQ(im.at(1, 1), 254);
  EXPECT_EQ(im.at(2, 1), 255);
}

TEST(ImageReader, RgbBecomesRec709LumaAndGreyPixelsStayExact) {
  const auto dir = test::temp_dir("image_rgb");
  const std::string path = (dir / "c.png").string();
  test::write_png(path, 4, 1, PNG_COLOR_TYPE_RGB, 8,
                  {77, 77, 77, 255, 0, 0, 0, 255, 0, 0, 0, 255});
  const GreyImage im = read_png_grey(path);
  ASSERT_EQ(im.width, 4);
  ASSERT_EQ(im.height, 1);
  EXPECT_EQ(im.at(0, 0), 77);
  EXPECT_NEAR(im.at(1, 0), 0.2126 * 255, 1.0);
  EXPECT_NEAR(im.at(2, 0), 0.7152 * 255, 1.0);
  EXPECT_NEAR(im.at(3, 0), 0.0722 * 255, 1.0);
}

TEST(ImageReader, RgbaAsWrittenByMatplotlibIgnoresAlpha) {
  const auto dir = test::temp_dir("image_rgba");
  const std::string path = (dir / "a.png").string();
  test::write_png(path, 2, 2, PNG_COLOR_TYPE_RGB_ALPHA, 8,
                  {10, 10, 10, 255, 20, 20, 20, 0,  //
                   30, 30, 30, 128, 255, 255, 255, 255});
  const GreyImage im = read_png_grey(path);
  EXPECT_EQ(im.at(0, 0), 10);
  EXPECT_EQ(im.at(1, 0), 20);
  EXPECT_EQ(im.at(0, 1), 30);
  EXPECT_EQ(im.at(1, 1), 255);
}

TEST(ImageReader, GreyAlphaPaletteSixteenAndLowBitDepths) {
  const auto dir = test::temp_dir("image_kinds");
  {
    const std::string path = (dir / "ga.png").string();
    test::write_png(path, 2, 1, PNG_COLOR_TYPE_GRAY_ALPHA, 8, {40, 0, 250, 255});
    const GreyImage im = read_png_grey(path);
    EXPECT_EQ(im.at(0, 0), 40);
    EXPECT_EQ(im.at(1, 0), 250);
  }
  {
    const std::string path = (dir / "p.png").string();
    test::write_png(path, 3, 1, PNG_COLOR_TYPE_PALETTE, 8, {2, 0, 1},
                    {png_color{0, 0, 0}, png_color{90, 90, 90}, png_color{200, 200, 200}});
    const GreyImage im = read_png_grey(path);
    EXPECT_EQ(im.at(0, 0), 200);
    EXPECT_EQ(im.at(1, 0), 0);
    EXPECT_EQ(im.at(2, 0), 90);
  }
  {
    const std::string path = (dir / "g16.png").string();
    test::write_png(path, 3, 1, PNG_COLOR_TYPE_GRAY, 16, {0, 128 * 257, 65535});
    const GreyImage im = read_png_grey(path);
    EXPECT_EQ(im.at(0, 0), 0);
    EXPECT_EQ(im.at(1, 0), 128);
    EXPECT_EQ(im.at(2, 0), 255);
  }
  {
    const std::string path = (dir / "rgb16.png").string();
    test::write_png(path, 1, 1, PNG_COLOR_TYPE_RGB, 16, {60 * 257, 60 * 257, 60 * 257});
    EXPECT_EQ(read_png_grey(path).at(0, 0), 60);
  }
  {
    const std::string path = (dir / "g1.png").string();
    test::write_png(path, 3, 2, PNG_COLOR_TYPE_GRAY, 1, {1, 0, 1, 0, 0, 1});
    const GreyImage im = read_png_grey(path);
    ASSERT_EQ(im.width, 3);
    EXPECT_EQ(im.at(0, 0), 255);
    EXPECT_EQ(im.at(1, 0), 0);
    EXPECT_EQ(im.at(2, 1), 255);
  }
  {
    const std::string path = (dir / "g4.png").string();
    test::write_png(path, 3, 1, PNG_COLOR_TYPE_GRAY, 4, {0, 1, 15});
    const GreyImage im = read_png_grey(path);
    EXPECT_EQ(im.at(0, 0), 0);
    EXPECT_EQ(im.at(1, 0), 17);
    EXPECT_EQ(im.at(2, 0), 255);
  }
}

TEST(ImageReader, FailuresNameThePathAndTheReason) {
  const auto dir = test::temp_dir("image_errors");
  const std::string missing = (dir / "missing.png").string();
  const std::string m = read_error(missing);
  EXPECT_NE(m.find(missing), std::string::npos) << m;
  EXPECT_NE(m.find("cannot open"), std::string::npos) << m;

  const std::string text = (dir / "text.png").string();
  std::ofstream(text) << "this is not a picture\n";
  EXPECT_NE(read_error(text).find("not a PNG file"), std::string::npos);

  // A valid PNG cut short: libpng's own message comes through.
  const std::string good = (dir / "good.png").string();
  std::vector<unsigned> levels(64 * 64);
  for (std::size_t i = 0; i < levels.size(); ++i) levels[i] = (i * 37) % 256;
  test::write_grey_png(good, 64, 64, levels);
  const std::string cut = (dir / "cut.png").string();
  fs::copy_file(good, cut);
  fs::resize_file(cut, fs::file_size(good) / 2);
  const std::string c = read_error(cut);
  EXPECT_NE(c.find(cut), std::string::npos) << c;
  EXPECT_GT(c.size(), cut.size() + 12) << c;  // a reason follows the path
}

// ---- the image shape in the input ---------------------------------------------------------

const std::string image_input = R"toml([simulation]
dimension = 2
end_time = 1.0e-3

[grid]
origin = [0.0, 0.0]
extent = [1.0, 1.0]
cell_size = 0.1

[[material]]
name = "dark"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "a"
material = "dark"
shape = { image = { file = "pic.png", pixel_size = 0.1, origin = [0.2, 0.3], levels = [0, 50] } }

[[body]]
name = "b"
material = "dark"
shape = { image = { file = "pic.png", pixel_size = 0.1, levels = [90, 110] } }
)toml";
// Lines: 20 first shape, 25 second shape.

std::string with(const std::string& from, const std::string& to, std::string text = image_input) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the input";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// Writes pic.png and `text` as case.toml into a fresh directory; returns the input path.
std::string write_case(const std::string& name, const std::string& text) {
  const auto dir = test::temp_dir(name);
  test::write_grey_png((dir / "pic.png").string(), 2, 1, {10, 100});
  const auto path = dir / "case.toml";
  std::ofstream(path) << text;
  return path.string();
}

std::optional<InputError> error_of(const std::string& name, const std::string& text) {
  try {
    load_config(write_case(name, text));
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError";
  return std::nullopt;
}

TEST(ImageShape, ReadsKeysResolvesTheFileNextToTheInputAndSharesThePicture) {
  const std::string path = write_case("image_shape", image_input);
  const Config c = load_config(path);
  ASSERT_EQ(c.bodies.size(), 2u);
  const auto& a = c.bodies[0].shape;
  EXPECT_EQ(a.kind, "image");
  EXPECT_EQ(fs::path(a.file), fs::absolute(fs::path(path).parent_path() / "pic.png").lexically_normal());
  EXPECT_EQ(a.pixel_size, 0.1);
  EXPECT_EQ(a.origin, (std::vector<double>{0.2, 0.3}));
  EXPECT_EQ(a.level_min, 0);
  EXPECT_EQ(a.level_max, 50);
  ASSERT_TRUE(a.image);
  EXPECT_EQ(a.image->width, 2);
  EXPECT_EQ(a.image->at(1, 0), 100);
  const auto& b = c.bodies[1].shape;
  EXPECT_EQ(b.origin, (std::vector<double>{0.0, 0.0}));  // the default
  EXPECT_EQ(b.image.get(), a.image.get());                // read once

  // The resolved input names the absolute file, so it reads back from anywhere.
  const Config r = load_config_string(c.resolved_toml, "elsewhere/resolved.toml");
  EXPECT_EQ(r.resolved_toml, c.resolved_toml);
  EXPECT_EQ(r.bodies[0].shape.file, a.file);
  EXPECT_EQ(r.bodies[0].shape.origin, a.origin);
  EXPECT_EQ(r.bodies[0].shape.pixel_size, a.pixel_size);
  EXPECT_EQ(r.bodies[1].shape.level_min, 90);
  EXPECT_EQ(r.bodies[1].shape.level_max, 110);
  EXPECT_NE(c.resolved_toml.find("levels = [0, 50]"), std::string::npos) << c.resolved_toml;
}

TEST(ImageShape, InvalidKeysAreReportedWithFileLineKeyExpectedAndFound) {
  auto e = error_of("image_bad_levels", with("levels = [0, 50]", "levels = [60, 50]"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 20);
  EXPECT_EQ(e->key(), "body[0].shape.image.levels");
  EXPECT_NE(e->expected().find("lo <= hi"), std::string::npos) << e->what();

  e = error_of("image_level_range", with("levels = [0, 50]", "levels = [0, 300]"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "body[0].shape.image.levels[1]");
  EXPECT_NE(e->expected().find("0..255"), std::string::npos) << e->what();

  e = error_of("image_level_count", with("levels = [0, 50]", "levels = [0, 50, 60]"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "body[0].shape.image.levels");
  EXPECT_EQ(std::string(e->what()).find("dimension"), std::string::npos) << e->what();
  EXPECT_NE(e->found().find("3 entries"), std::string::npos) << e->what();

  e = error_of("image_pixel", with("pixel_size = 0.1, origin", "pixel_size = 0.0, origin"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "body[0].shape.image.pixel_size");

  e = error_of("image_missing", with("file = \"pic.png\"", "file = \"nope.png\""));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 20);
  EXPECT_EQ(e->key(), "body[0].shape.image.file");
  EXPECT_NE(e->found().find("nope.png"), std::string::npos) << e->what();
  EXPECT_NE(e->found().find("cannot open"), std::string::npos) << e->what();

  e = error_of("image_unknown_key", with("levels = [0, 50]", "levels = [0, 50], level = 3"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "body[0].shape.image.level");

  e = error_of("image_no_levels", with(", levels = [90, 110]", ""));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 25);
  EXPECT_NE(e->expected().find("required"), std::string::npos) << e->what();
}

TEST(ImageShape, OnlyTwoDimensional) {
  std::string three = with("dimension = 2", "dimension = 3");
  three = with("origin = [0.0, 0.0]\nextent = [1.0, 1.0]", "origin = [0.0, 0.0, 0.0]\nextent = [1.0, 1.0, 1.0]",
               three);
  const auto e = error_of("image_3d", three);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->location(), (fs::temp_directory_path() / "cairn_test_image_3d" / "case.toml").string() + ":20");
  EXPECT_EQ(e->key(), "body[0].shape.image");
  EXPECT_NE(e->expected().find("valid in 3D"), std::string::npos) << e->what();
}

}  // namespace
}  // namespace cairn
