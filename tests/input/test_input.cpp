// The input layer: one test per class of input error, each checking that the message names the
// place (file:line or the --set text), the key, what was expected and what was found; then the
// positive paths: defaults, overrides, and the resolved TOML reading back to the same Config.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "cairn/input/input.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

// A valid 2D input; tests edit one line of it, so the line numbers in the comments hold.
const std::string base = R"toml([simulation]
title = "two blocks"
dimension = 2
end_time = 2.0e-3
cfl = 0.4

[grid]
origin = [0.0, 0.0]
extent = [0.12, 0.04]
cell_size = 1.0e-3

[method]
shape = "bspline2"
update = "flip"

[[material]]
name = "rubber"
model = "linear_elastic"
density = 1500.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "left"
material = "rubber"
shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }
velocity = [8.165, 0.0]

[boundary]
x_min = "fixed"
)toml";
// Lines: 1 [simulation], 3 dimension, 5 cfl, 8 origin, 10 cell_size, 13 shape, 16 [[material]],
// 18 model, 23 [[body]], 25 material, 26 shape, 29 [boundary], 30 x_min.

/// `base` with the first occurrence of `from` replaced by `to`.
std::string with(const std::string& from, const std::string& to, std::string text = base) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the input";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The InputError that loading `text` raises (a test failure when none is raised).
std::optional<InputError> error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load_config_string(text, "case.toml", overrides);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError";
  return std::nullopt;
}

std::string message(const std::optional<InputError>& e) { return e ? e->what() : ""; }

// ---- one test per error class -------------------------------------------------------------

TEST(InputErrors, UnknownKeySuggestsTheClosestDeclaredKey) {
  const auto e = error_of(with("cfl = 0.4", "cfll = 0.4"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "case.toml");
  EXPECT_EQ(e->line(), 5);
  EXPECT_EQ(e->key(), "simulation.cfll");
  EXPECT_EQ(message(e),
            "case.toml:5: key 'simulation.cfll': expected a key declared for [simulation] "
            "(did you mean 'cfl'?); found an undeclared key");
}

TEST(InputErrors, UnknownKeyWithoutCloseMatchListsTheKeys) {
  const auto m = message(error_of(with("update = \"flip\"", "frobnicate = 1")));
  EXPECT_NE(m.find("case.toml:14: key 'method.frobnicate': expected one of the keys of [method]: "
                   "shape, update, order, stress_update, smoothing_length"),
            std::string::npos)
      << m;
}

TEST(InputErrors, MisspelledSection) {
  const auto e = error_of(with("[simulation]", "[simulaton]"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 1);
  EXPECT_EQ(e->key(), "simulaton");
  EXPECT_NE(message(e).find("case.toml:1: key 'simulaton': expected a section, one of simulation, "),
            std::string::npos)
      << message(e);
  EXPECT_NE(message(e).find("(did you mean 'simulation'?); found an unknown table"), std::string::npos)
      << message(e);
}

TEST(InputErrors, KeyAboveItsSectionHeader) {
  const auto m = message(error_of("dimension = 2\n" + base));
  EXPECT_NE(m.find("case.toml:1: key 'dimension': expected a section"), std::string::npos) << m;
  EXPECT_NE(m.find("'dimension' belongs in [simulation]"), std::string::npos) << m;
}

TEST(InputErrors, WrongType) {
  EXPECT_EQ(message(error_of(with("dimension = 2", "dimension = \"two\""))),
            "case.toml:3: key 'simulation.dimension': expected an integer in 1..3; "
            "found \"two\" (a string)");
  EXPECT_EQ(message(error_of(with("cfl = 0.4", "cfl = [0.4]"))),
            "case.toml:5: key 'simulation.cfl': expected a number in (0, 2]; found [0.4] (an array)");
  // Integers are accepted where reals are expected, but not the other way round.
  EXPECT_EQ(message(error_of(with("dimension = 2", "dimension = 2.0"))),
            "case.toml:3: key 'simulation.dimension': expected an integer in 1..3; found 2.0 (a real)");
}

TEST(InputErrors, OutOfRange) {
  const auto e = error_of(with("cfl = 0.4", "cfl = 3.0"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->expected(), "a number in (0, 2]");
  EXPECT_EQ(e->found(), "3.0");
  EXPECT_EQ(message(e), "case.toml:5: key 'simulation.cfl': expected a number in (0, 2]; found 3.0");
  EXPECT_EQ(message(error_of(with("end_time = 2.0e-3", "end_time = 0"))),
            "case.toml:4: key 'simulation.end_time': expected a number > 0; found 0");
  EXPECT_EQ(message(error_of(with("extent = [0.12, 0.04]", "extent = [0.12, -0.04]"))),
            "case.toml:9: key 'grid.extent[1]': expected a number > 0; found -0.04");
}

TEST(InputErrors, NotInChoices) {
  const auto e = error_of(with("shape = \"bspline2\"", "shape = \"cpdii\""));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 13);
  EXPECT_EQ(e->key(), "method.shape");
  EXPECT_EQ(e->found(), "\"cpdii\"");
  EXPECT_EQ(e->expected().rfind("one of ", 0), 0u) << e->expected();
  EXPECT_NE(e->expected().find("bspline2"), std::string::npos) << e->expected();
  EXPECT_EQ(message(e).rfind("case.toml:13: key 'method.shape': expected one of ", 0), 0u) << message(e);
}

TEST(InputErrors, MissingRequiredKey) {
  EXPECT_EQ(message(error_of(with("end_time = 2.0e-3", "# no end time"))),
            "case.toml:1: key 'simulation.end_time': expected a number > 0 (required key); found nothing");
  // A whole required section missing: no line to point at.
  const std::string no_grid = with("[grid]\norigin = [0.0, 0.0]\nextent = [0.12, 0.04]\ncell_size = 1.0e-3\n", "");
  EXPECT_EQ(message(error_of(no_grid)),
            "case.toml: key 'grid.origin': expected an array of 2 numbers (one per axis, dimension 2) "
            "(required key); found nothing");
  const std::string no_body = base.substr(0, base.find("[[body]]")) + "[boundary]\n";
  EXPECT_EQ(message(error_of(no_body)), "case.toml: key 'body': expected at least one [[body]] table; found none");
}

TEST(InputErrors, MalformedToml) {
  const auto e = error_of(with("cfl = 0.4", "cfl = = 0.4"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 5);
  EXPECT_EQ(e->expected(), "valid TOML");
  EXPECT_FALSE(e->found().empty());
  EXPECT_EQ(message(e).rfind("case.toml:5: expected valid TOML; found ", 0), 0u) << message(e);
  // Duplicate keys are a TOML error too.
  EXPECT_EQ(error_of(with("cfl = 0.4", "cfl = 0.4\ncfl = 0.5"))->line(), 6);
}

TEST(InputErrors, BadSetSyntax) {
  EXPECT_EQ(message(error_of(base, {"method.order"})),
            "--set method.order: expected section.key=value, e.g. method.order=4 or "
            "material[0].density=1100; found \"method.order\" (no '=')");
  EXPECT_EQ(message(error_of(base, {"order=4"})),
            "--set order=4: expected section.key=value, e.g. method.order=4 or "
            "material[0].density=1100; found key \"order\"");
  EXPECT_EQ(message(error_of(base, {"material[x].density=1"})).rfind("--set material[x].density=1: expected section.key=value", 0),
            0u);
  EXPECT_EQ(message(error_of(base, {"material.name=x"})),
            "--set material.name=x: key 'material.name': expected an entry index, as in "
            "material.0.name or material[0].name; found \"name\"");
  EXPECT_EQ(message(error_of(base, {"body.3.name=x"})),
            "--set body.3.name=x: key 'body[3]': expected the index of an existing [[body]] (0..0); found 3");
}

TEST(InputErrors, NodeHaloIsAcceptedWithContactAndAnUnknownHaloRefused) {
  // Contact runs under the node halo too (its point clouds travel with it; docs/parallel.md).
  const std::string contact = base + "[contact]\nmode = \"body\"\n";
  EXPECT_EQ(load_config_string(contact, "case.toml", {"parallel.halo=\"nodes\""}).parallel.halo, "nodes");
  EXPECT_EQ(load_config_string(contact, "case.toml", {}).parallel.halo, "auto");
  EXPECT_EQ(load_config_string(base, "case.toml", {"parallel.halo=\"nodes\""}).parallel.halo, "nodes");
  const auto e = error_of(contact, {"parallel.halo=\"ghosts\""});
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "parallel.halo");
  EXPECT_EQ(e->found(), "\"ghosts\"");
  EXPECT_NE(e->expected().find("nodes"), std::string::npos) << e->expected();
}

TEST(InputErrors, SetOfUnknownKey) {
  EXPECT_EQ(message(error_of(base, {"method.ordr=4"})),
            "--set method.ordr=4: key 'method.ordr': expected a key declared for [method] "
            "(did you mean 'order'?); found an undeclared key");
  EXPECT_EQ(message(error_of(base, {"materail[0].density=1"})),
            "--set materail[0].density=1: key 'materail': expected a section, one of simulation, parallel, grid, "
            "method, constants, material, body, boundary, thermal, body_force, traction, velocity, wall, "
            "contact, contact_pair, fem, output (did you mean "
            "'material'?); found an undeclared key");
  // The model decides the keys of a [[material]].
  EXPECT_EQ(message(error_of(base, {"material.0.gamma0=2"})).rfind(
                "--set material.0.gamma0=2: key 'material[0].gamma0': expected a key declared for [[material]]",
                0),
            0u);
  EXPECT_EQ(message(error_of(base, {"body.0.shape.cube.min=[0,0]"})).rfind(
                "--set body.0.shape.cube.min=[0,0]: key 'body[0].shape.cube': expected a shape kind", 0),
            0u);
}

TEST(InputErrors, ValueSetByOverrideIsBlamedOnTheOverride) {
  const auto e = error_of(base, {"method.order=100"});
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), "--set method.order=100");
  EXPECT_EQ(e->line(), 0);
  EXPECT_EQ(message(e), "--set method.order=100: key 'method.order': expected an integer in 1..64; found 100");
}

TEST(InputErrors, ArrayOfWrongLength) {
  EXPECT_EQ(message(error_of(with("origin = [0.0, 0.0]", "origin = [0.0, 0.0, 0.0]"))),
            "case.toml:8: key 'grid.origin': expected an array of 2 numbers (one per axis, "
            "dimension 2); found [0.0, 0.0, 0.0] (3 entries)");
  EXPECT_EQ(message(error_of(with("velocity = [8.165, 0.0]", "velocity = [8.165]"))),
            "case.toml:27: key 'body[0].velocity': expected an array of 2 entries (one per axis, "
            "dimension 2), each a number or an expression string; found [8.165] (1 entry)");
}

TEST(InputErrors, BodyReferencesUnknownMaterial) {
  const auto e = error_of(with("material = \"rubber\"", "material = \"rubbr\""));
  ASSERT_TRUE(e);
  EXPECT_EQ(message(e),
            "case.toml:25: key 'body[0].material': expected the name of a [[material]], one of "
            "rubber (did you mean 'rubber'?); found \"rubbr\"");
}

TEST(InputErrors, MaterialWithWrongCombinationOfElasticConstants) {
  const auto& info = material_model_info().at("linear_elastic");
  ASSERT_NE(info.check, nullptr);
  MaterialConfig given;
  given.name = "rubber";
  given.model = "linear_elastic";
  given.numbers = {{"density", 1500.0}, {"youngs_modulus", 1.0e6}, {"poissons_ratio", 0.3}, {"shear_modulus", 4.0e5}};
  const std::string problem = info.check(given);
  ASSERT_FALSE(problem.empty());

  const auto e = error_of(with("poissons_ratio = 0.3", "poissons_ratio = 0.3\nshear_modulus = 4.0e5"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 16);  // the [[material]] header
  EXPECT_EQ(e->key(), "material[0]");
  EXPECT_EQ(e->expected(), problem);
  EXPECT_EQ(message(e), "case.toml:16: key 'material[0]': expected " + problem +
                            "; found model 'linear_elastic' with youngs_modulus = 1000000.0, "
                            "poissons_ratio = 0.3, shear_modulus = 400000.0");
}

TEST(InputErrors, UnknownMaterialModel) {
  const auto e = error_of(with("model = \"linear_elastic\"", "model = \"neo_hooke\""));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line(), 18);
  EXPECT_EQ(e->key(), "material[0].model");
  EXPECT_EQ(e->found(), "\"neo_hooke\"");
  EXPECT_NE(e->expected().find("linear_elastic"), std::string::npos);
  EXPECT_NE(e->expected().find("(did you mean 'neo_hookean'?)"), std::string::npos) << e->expected();
}

TEST(InputErrors, BodyShapeOfUnknownKind) {
  EXPECT_EQ(message(error_of(with("{ box = { min", "{ cube = { min"))),
            "case.toml:26: key 'body[0].shape.cube': expected a shape kind, one of box, circle, "
            "ellipse, annulus, polygon, sphere, cylinder, image, mesh, volume_mesh, outline, points, "
            "image_stack; found \"cube\"");
  EXPECT_EQ(message(error_of(with("shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }",
                                  "shape = { sphere = { center = [0.03, 0.02], radius = 0.01 } }"))),
            "case.toml:26: key 'body[0].shape.sphere': expected a shape kind valid in 2D, one of box, "
            "circle, ellipse, annulus, polygon, image, volume_mesh, outline, points; found \"sphere\"");
  EXPECT_EQ(message(error_of(with("shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }",
                                  "shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] }, "
                                  "circle = { center = [0.1, 0.02], radius = 0.01 } }"))),
            "case.toml:26: key 'body[0].shape': expected exactly one shape kind, one of box, circle, "
            "ellipse, annulus, polygon, sphere, cylinder, image, mesh, volume_mesh, outline, points, "
            "image_stack; found 2 kinds: box, circle");
}

TEST(InputErrors, BodyShapeMissingItsParameters) {
  EXPECT_EQ(message(error_of(with("shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }",
                                  "shape = { circle = { center = [0.03, 0.02] } }"))),
            "case.toml:26: key 'body[0].shape.circle.radius': expected a number > 0 (required key); "
            "found nothing");
  EXPECT_EQ(message(error_of(with("shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }",
                                  "shape = { polygon = { vertices = [[0.0, 0.0], [0.01, 0.0]] } }"))),
            "case.toml:26: key 'body[0].shape.polygon.vertices': expected an array of at least 3 "
            "points, each an array of 2 numbers; found [[0.0, 0.0], [0.01, 0.0]] (2 points)");
  EXPECT_EQ(message(error_of(with("max = [0.06, 0.03]", "max = [0.06, 0.005]"))),
            "case.toml:26: key 'body[0].shape.box.max': expected max > min on every axis; found max "
            "0.005 <= min 0.01 on axis y");
}

TEST(InputErrors, PeriodicOnOneFaceOfAnAxis) {
  const auto e = error_of(with("x_min = \"fixed\"", "x_min = \"periodic\""));
  ASSERT_TRUE(e);
  EXPECT_EQ(message(e),
            "case.toml:30: key 'boundary.x_min': expected periodic on both x faces (x_min and x_max); "
            "found x_min = \"periodic\", x_max = \"free\"");
}

TEST(InputErrors, FaceOfAnAxisTheGridDoesNotHave) {
  EXPECT_EQ(message(error_of(with("x_min = \"fixed\"", "z_min = \"fixed\""))),
            "case.toml:30: key 'boundary.z_min': expected a face of the 2D grid, one of x_min, x_max, "
            "y_min, y_max; found z_min (a 2D grid has no z axis)");
}

TEST(InputErrors, ModeInconsistentWithDimension) {
  EXPECT_EQ(message(error_of(with("dimension = 2", "dimension = 2\nmode = \"3d\""))),
            "case.toml:4: key 'simulation.mode': expected plane_strain or plane_stress for dimension 2; "
            "found \"3d\"");
}

TEST(InputErrors, CellSizeNotDividingTheExtent) {
  EXPECT_EQ(message(error_of(with("cell_size = 1.0e-3", "cell_size = [1.0e-3, 3.0e-3]"))),
            "case.toml:10: key 'grid.cell_size': expected grid.extent / grid.cell_size to be a whole "
            "number of cells on axis y (within 1e-9 relative); found 0.04 / 0.003 = 13.3333333333");
}

TEST(InputErrors, BadConstantsAndExpressions) {
  EXPECT_EQ(message(error_of(base + "\n[constants]\nx = 1.0\n")),
            "case.toml:33: key 'constants.x': expected a constant name other than x, y, z, X, Y, Z, t, "
            "_pi, _e (built into expressions); found \"x\"");
  EXPECT_EQ(message(error_of(base + "\n[constants]\nA = \"big\"\n")),
            "case.toml:33: key 'constants.A': expected a number; found \"big\" (a string)");
  EXPECT_EQ(message(error_of(with("velocity = [8.165, 0.0]", "velocity = [\"\", 0.0]"))),
            "case.toml:27: key 'body[0].velocity[0]': expected a number or a non-empty expression "
            "string; found an empty string");
}

TEST(InputErrors, DuplicateMaterialName) {
  const std::string second =
      "[[material]]\nname = \"rubber\"\nmodel = \"neo_hookean\"\ndensity = 1.0\n"
      "bulk_modulus = 1.0\nshear_modulus = 1.0\n\n[[body]]";
  EXPECT_EQ(message(error_of(with("[[body]]", second))),
            "case.toml:24: key 'material[1].name': expected a name not used by another [[material]] "
            "(used at case.toml:16); found \"rubber\"");
}

TEST(InputErrors, SectionOfTheWrongKind) {
  EXPECT_EQ(message(error_of(with("[[material]]", "[material]"))),
            "case.toml:16: key 'material': expected an array of tables, written [[material]]; found "
            "a single table [material]");
}

TEST(InputErrors, UnreadableFile) {
  try {
    load_config("/nonexistent/cairn/case.toml", {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/cairn/case.toml: expected a readable input file; found ", 0), 0u)
        << e.what();
  }
}

// ---- every independent error in one reading ---------------------------------------------

/// The errors of the InputErrors that loading `text` raises (a test failure when fewer than two).
std::vector<InputError> errors_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load_config_string(text, "case.toml", overrides);
  } catch (const InputErrors& e) {
    EXPECT_EQ(std::string(e.what()).find(e.errors().front().what()), 0u) << "what() starts with the first";
    return e.errors();
  } catch (const InputError& e) {
    ADD_FAILURE() << "expected several errors, got one: " << e.what();
    return {e};
  }
  ADD_FAILURE() << "expected InputErrors";
  return {};
}

TEST(InputErrors, EveryIndependentErrorOfAFileInOneReading) {
  // A key in the wrong section, a bad choice, a value out of range and a stray key in a body:
  // none stops the reading, so all four come back, in file order, each with line and key.
  std::string text = with("cell_size = 1.0e-3", "cell_size = 1.0e-3\ncfl = 0.3");  // line 11
  text = with("shape = \"bspline2\"", "shape = \"cpdii\"", text);                  // line 14
  text = with("velocity = [8.165, 0.0]", "velocity = [8.165, 0.0]\nvelocty = 1", text);  // line 29
  text += "\n[output]\nevery = -1.0\n";                                               // line 35
  const auto errors = errors_of(text);
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_EQ(errors[0].line(), 11);
  EXPECT_EQ(errors[0].key(), "grid.cfl");
  EXPECT_EQ(std::string(errors[0].what()),
            "case.toml:11: key 'grid.cfl': expected a key declared for [grid] ('cfl' is a key of [simulation]: "
            "did you mean simulation.cfl?); found an undeclared key");
  EXPECT_EQ(errors[1].line(), 14);
  EXPECT_EQ(errors[1].key(), "method.shape");
  EXPECT_EQ(errors[1].found(), "\"cpdii\"");
  EXPECT_EQ(errors[2].line(), 29);
  EXPECT_EQ(errors[2].key(), "body[0].velocty");
  EXPECT_NE(errors[2].expected().find("did you mean 'velocity'?"), std::string::npos) << errors[2].expected();
  EXPECT_EQ(errors[3].line(), 35);
  EXPECT_EQ(errors[3].key(), "output.every");
}

TEST(InputErrors, AStrayKeyAndTheMissingRequiredKeyBothReported) {
  // end_time moved from [simulation] to [output]: the missing key stops the reading, the stray
  // one is still found, and says where it belongs.
  std::string text = with("end_time = 2.0e-3\n", "");
  text += "\n[output]\nend_time = 2.0e-3\n";
  const auto errors = errors_of(text);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].key(), "simulation.end_time");
  EXPECT_NE(errors[0].expected().find("required key"), std::string::npos) << errors[0].what();
  EXPECT_EQ(errors[1].key(), "output.end_time");
  EXPECT_NE(std::string(errors[1].what()).find("did you mean simulation.end_time?"), std::string::npos)
      << errors[1].what();
}

TEST(InputErrors, AMaterialKeyInAnotherSectionSaysWhereItBelongs) {
  const auto e = error_of(with("cfl = 0.4", "youngs_modulus = 1.0e6"));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "simulation.youngs_modulus");
  EXPECT_NE(e->expected().find("'youngs_modulus' is a key of [[material]] (model "), std::string::npos)
      << e->expected();
}

TEST(InputErrors, BadOverridesAndFileErrorsTogether) {
  const auto errors = errors_of(with("cfl = 0.4", "cfl = 3.0"), {"method.nope=1", "output.every=-2"});
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0].file(), "--set method.nope=1");  // overrides (line 0) first
  EXPECT_EQ(errors[1].file(), "--set output.every=-2");
  EXPECT_EQ(errors[2].line(), 5);
  EXPECT_EQ(errors[2].key(), "simulation.cfl");
}

TEST(InputErrors, ReadingStopsAtTheCap) {
  std::string text = base + "\n[output]\n";
  for (int i = 0; i < 30; ++i) text += "stray_" + std::to_string(i) + " = 1\n";
  try {
    load_config_string(text, "case.toml");
    FAIL() << "expected InputErrors";
  } catch (const InputErrors& e) {
    EXPECT_EQ(e.errors().size(), InputErrors::max_reported);
    EXPECT_TRUE(e.truncated());
    EXPECT_EQ(e.errors().front().key(), "output.stray_0");
  }
}

TEST(InputErrors, AnErrorThatLeavesTheRestUnreadableStopsTheReading) {
  // A bad dimension would make every array's length wrong: nothing after it is reported.
  try {
    load_config_string(with("dimension = 2", "dimension = 5") + "\n[output]\nevery = -1.0\n", "case.toml");
    FAIL() << "expected an InputError";
  } catch (const InputErrors& e) {
    FAIL() << "expected one error, got " << e.what();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "simulation.dimension");
  }
}

// ---- positive paths -----------------------------------------------------------------------

void expect_same(const Config& a, const Config& b) {
  EXPECT_EQ(a.simulation.title, b.simulation.title);
  EXPECT_EQ(a.simulation.dimension, b.simulation.dimension);
  EXPECT_EQ(a.simulation.mode, b.simulation.mode);
  EXPECT_EQ(a.simulation.end_time, b.simulation.end_time);
  EXPECT_EQ(a.simulation.cfl, b.simulation.cfl);
  EXPECT_EQ(a.simulation.fixed_dt, b.simulation.fixed_dt);
  EXPECT_EQ(a.simulation.max_steps, b.simulation.max_steps);
  EXPECT_EQ(a.simulation.thickness, b.simulation.thickness);
  EXPECT_EQ(a.simulation.threads, b.simulation.threads);
  EXPECT_EQ(a.grid.origin, b.grid.origin);
  EXPECT_EQ(a.grid.extent, b.grid.extent);
  EXPECT_EQ(a.grid.cell_size, b.grid.cell_size);
  EXPECT_EQ(a.method.shape, b.method.shape);
  EXPECT_EQ(a.method.update, b.method.update);
  EXPECT_EQ(a.method.order, b.method.order);
  EXPECT_EQ(a.method.stress_update, b.method.stress_update);
  EXPECT_EQ(a.method.plugin.real("smoothing_length"), b.method.plugin.real("smoothing_length"));
  EXPECT_EQ(a.constants, b.constants);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_EQ(a.materials[i].model, b.materials[i].model);
    EXPECT_EQ(a.materials[i].numbers, b.materials[i].numbers);
    EXPECT_EQ(a.materials[i].strings, b.materials[i].strings);
  }
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    const auto &x = a.bodies[i], &y = b.bodies[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.material, y.material);
    EXPECT_EQ(x.shape.kind, y.shape.kind);
    EXPECT_EQ(x.shape.min, y.shape.min);
    EXPECT_EQ(x.shape.max, y.shape.max);
    EXPECT_EQ(x.shape.center, y.shape.center);
    EXPECT_EQ(x.shape.radius, y.shape.radius);
    EXPECT_EQ(x.shape.semi_axes, y.shape.semi_axes);
    EXPECT_EQ(x.shape.inner_radius, y.shape.inner_radius);
    EXPECT_EQ(x.shape.outer_radius, y.shape.outer_radius);
    EXPECT_EQ(x.shape.vertices, y.shape.vertices);
    EXPECT_EQ(x.particles_per_cell, y.particles_per_cell);
    EXPECT_EQ(x.velocity, y.velocity);
    EXPECT_EQ(x.displacement, y.displacement);
  }
  EXPECT_EQ(a.boundary.face, b.boundary.face);
  EXPECT_EQ(a.body_force.expression, b.body_force.expression);
  EXPECT_EQ(a.output.directory, b.output.directory);
  EXPECT_EQ(a.output.every, b.output.every);
  EXPECT_EQ(a.output.history_every, b.output.history_every);
  EXPECT_EQ(a.output.checkpoint_every, b.output.checkpoint_every);
  EXPECT_EQ(a.output.snapshots, b.output.snapshots);
  EXPECT_EQ(a.output.grid_snapshots, b.output.grid_snapshots);
  EXPECT_EQ(a.output.checkpoints, b.output.checkpoints);
}

TEST(Input, DefaultsAreFilled) {
  const Config c = load_config_string(base, "examples/case.toml", {});
  EXPECT_EQ(c.source_file, "examples/case.toml");
  EXPECT_EQ(c.simulation.title, "two blocks");
  EXPECT_EQ(c.simulation.dimension, 2);
  EXPECT_EQ(c.simulation.mode, Mode::plane_strain);
  EXPECT_EQ(c.simulation.end_time, 2.0e-3);
  EXPECT_EQ(c.simulation.cfl, 0.4);
  EXPECT_EQ(c.simulation.fixed_dt, 0.0);
  EXPECT_EQ(c.simulation.max_steps, 0);
  EXPECT_EQ(c.simulation.thickness, 1.0);
  EXPECT_EQ(c.simulation.threads, 0);
  EXPECT_EQ(c.grid.origin, (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(c.grid.cell_size, (std::vector<double>{1.0e-3, 1.0e-3}));
  EXPECT_EQ(c.method.order, 1);
  EXPECT_EQ(c.method.stress_update, "usl");
  EXPECT_EQ(c.parallel.halo, "auto");
  EXPECT_EQ(c.parallel.balance, "count");
  EXPECT_EQ(c.method.plugin.real("smoothing_length"), 0.0);
  EXPECT_TRUE(c.constants.empty());
  ASSERT_EQ(c.materials.size(), 1u);
  EXPECT_EQ(c.materials[0].numbers,
            (std::map<std::string, double>{{"density", 1500.0}, {"youngs_modulus", 1.0e6}, {"poissons_ratio", 0.3},
                                          {"conductivity", 0.0}, {"heat_capacity", 0.0}, {"balance_cost", 0.0},
                                          {"damping_time", 0.0}}));
  EXPECT_EQ(c.materials[0].where.str(), "examples/case.toml:16");
  ASSERT_EQ(c.bodies.size(), 1u);
  const BodyConfig& b = c.bodies[0];
  EXPECT_EQ(b.name, "left");
  EXPECT_EQ(b.shape.kind, "box");
  EXPECT_EQ(b.shape.min, (std::vector<double>{0.01, 0.01}));
  EXPECT_EQ(b.particles_per_cell, (std::vector<int>{2, 2}));
  // Numbers in expressions are kept as full-precision text.
  EXPECT_EQ(b.velocity, (std::vector<std::string>{"8.1649999999999991", "0"}));
  EXPECT_TRUE(b.displacement.empty());
  EXPECT_EQ(b.where.str(), "examples/case.toml:23");
  EXPECT_EQ(c.boundary.face[0], FaceCondition::fixed);
  for (int f = 1; f < 6; ++f) EXPECT_EQ(c.boundary.face[f], FaceCondition::free);
  EXPECT_TRUE(c.body_force.expression.empty());
  EXPECT_EQ(c.output.directory, "out/case");
  EXPECT_EQ(c.output.every, 0.0);
  EXPECT_TRUE(c.output.snapshots);
  EXPECT_FALSE(c.output.grid_snapshots);
  EXPECT_TRUE(c.output.checkpoints);

  // A second body without a name gets body<N>; neo_hookean's `form` takes its default.
  const Config d = load_config_string(
      base +
          "\n[[material]]\nname = \"soft\"\nmodel = \"neo_hookean\"\ndensity = 1000\n"
          "bulk_modulus = 2e6\nshear_modulus = 1e6\n"
          "\n[[body]]\nmaterial = \"soft\"\nshape = { circle = { center = [0.09, 0.02], radius = 0.01 } }\n"
          "particles_per_cell = [3, 1]\n",
      "case.toml", {});
  ASSERT_EQ(d.bodies.size(), 2u);
  EXPECT_EQ(d.bodies[1].name, "body1");
  EXPECT_EQ(d.bodies[1].velocity, (std::vector<std::string>{"0", "0"}));
  EXPECT_EQ(d.bodies[1].particles_per_cell, (std::vector<int>{3, 1}));
  EXPECT_EQ(d.materials[1].strings.at("form"), "ln_j");
  EXPECT_EQ(d.materials[1].numbers.at("density"), 1000.0);
}

TEST(Input, OverridesAreApplied) {
  const Config c = load_config_string(
      base, "case.toml",
      {"method.order=4", "method.update=flip", "grid.origin=[0.01, 0]", "material.0.density=1100",
       "material[0].poissons_ratio=0.25", "constants.A=2", "body[0].velocity=[1, \"A*X\"]",
       "body.0.shape.box.max=[0.07, 0.03]", "simulation.title=hello world", "simulation.mode=plane_stress",
       "output.every=1e-4", "boundary.y_max=symmetry", "body_force.expression=[0, -9.81]"});
  EXPECT_EQ(c.method.order, 4);
  EXPECT_EQ(c.method.update, "flip");
  EXPECT_EQ(c.grid.origin, (std::vector<double>{0.01, 0.0}));
  EXPECT_EQ(c.materials[0].number("density"), 1100.0);
  EXPECT_EQ(c.materials[0].number("poissons_ratio"), 0.25);
  EXPECT_EQ(c.constants, (std::vector<std::pair<std::string, double>>{{"A", 2.0}}));
  EXPECT_EQ(c.bodies[0].velocity, (std::vector<std::string>{"1", "A*X"}));
  EXPECT_EQ(c.bodies[0].shape.max, (std::vector<double>{0.07, 0.03}));
  EXPECT_EQ(c.simulation.title, "hello world");
  EXPECT_EQ(c.simulation.mode, Mode::plane_stress);
  EXPECT_EQ(c.output.every, 1e-4);
  EXPECT_EQ(c.boundary.face[3], FaceCondition::symmetry);
  EXPECT_EQ(c.body_force.expression, (std::vector<std::string>{"0", "-9.8100000000000005"}));
  // Later overrides win.
  EXPECT_EQ(load_config_string(base, "case.toml", {"method.order=2", "method.order=3"}).method.order, 3);
}

const std::string rich = R"toml([simulation]
title = "rich \"quoted\" title"
dimension = 2
mode = "plane_stress"
end_time = 1
dt = 1.0e-6
max_steps = 1000
thickness = 0.1
threads = 2

[grid]
origin = [-0.5, 0]
extent = [1, 0.5]
cell_size = [0.1, 0.05]

[method]
shape = "linear"
order = 3
smoothing_length = 0.01

[constants]
omega = 12.5
A = 0.05

[[material]]
name = "gel"
model = "neo_hookean"
density = 1000
lambda = 1e6
shear_modulus = 5e5
form = "isochoric"

[[material]]
name = "steel"
model = "linear_elastic"
density = 7800
youngs_modulus = 2.1e11
poissons_ratio = 0.3

[[body]]
material = "gel"
shape = { annulus = { center = [0, 0.25], inner_radius = 0.05, outer_radius = 0.1 } }
particles_per_cell = 3
velocity = ["A*sin(omega*X)", 1e-3]
displacement = [0.1, "-A*Y"]

[[body]]
name = "wedge"
material = "steel"
shape.polygon.vertices = [[0.2, 0.1], [0.4, 0.1], [0.3, 0.3]]

[[body]]
material = "gel"
shape = { ellipse = { center = [-0.3, 0.2], semi_axes = [0.1, 0.05] } }

[boundary]
x_min = "periodic"
x_max = "periodic"
y_min = "fixed"

[body_force]
expression = [0, "-9.81*t"]

[output]
directory = "results/rich"
every = 0.1
history_every = 0.01
checkpoint_every = 0.5
snapshots = false
grid_snapshots = true
checkpoints = false
)toml";

TEST(Input, ResolvedTomlReadsBackToTheSameConfig) {
  for (const std::string& text : {base, rich}) {
    const Config a = load_config_string(text, "case.toml", {"method.order=5"});
    const Config b = load_config_string(a.resolved_toml, "resolved.toml", {});
    expect_same(a, b);
    EXPECT_EQ(a.resolved_toml, b.resolved_toml);
    EXPECT_EQ(b.output.directory, a.output.directory);  // not re-derived from the new name
  }
  const Config r = load_config_string(rich, "case.toml", {});
  EXPECT_EQ(r.constants, (std::vector<std::pair<std::string, double>>{{"omega", 12.5}, {"A", 0.05}}));
  EXPECT_EQ(r.bodies[1].shape.vertices.size(), 3u);
  EXPECT_EQ(r.bodies[0].particles_per_cell, (std::vector<int>{3, 3}));
  EXPECT_EQ(r.bodies[0].displacement, (std::vector<std::string>{"0.10000000000000001", "-A*Y"}));
  EXPECT_EQ(r.boundary.face[0], FaceCondition::periodic);
  // Every default is written out.
  EXPECT_NE(r.resolved_toml.find("stress_update = \"usl\""), std::string::npos) << r.resolved_toml;
  EXPECT_NE(r.resolved_toml.find("name = \"body2\""), std::string::npos) << r.resolved_toml;
}

TEST(Input, OneAndThreeDimensionalInputs) {
  const std::string one_d = R"toml([simulation]
dimension = 1
end_time = 1.0
[grid]
origin = [0.0]
extent = [1.0]
cell_size = 0.01
[[material]]
name = "bar"
model = "linear_elastic"
density = 1.0
youngs_modulus = 100.0
poissons_ratio = 0.0
[[body]]
material = "bar"
shape = { box = { min = [0.0], max = [1.0] } }
velocity = ["0.1*sin(_pi*X)"]
[boundary]
x_min = "fixed"
x_max = "fixed"
)toml";
  const Config c1 = load_config_string(one_d, "bar.toml", {});
  EXPECT_EQ(c1.simulation.mode, Mode::uniaxial_strain_1d);
  EXPECT_EQ(c1.bodies[0].particles_per_cell, (std::vector<int>{2}));
  expect_same(c1, load_config_string(c1.resolved_toml, "r.toml", {}));

  std::string three_d = with("dimension = 1", "dimension = 3", one_d);
  three_d = with("origin = [0.0]", "origin = [0.0, 0.0, 0.0]", three_d);
  three_d = with("extent = [1.0]", "extent = [1.0, 1.0, 1.0]", three_d);
  three_d = with("{ box = { min = [0.0], max = [1.0] } }",
                 "{ sphere = { center = [0.5, 0.5, 0.5], radius = 0.25 } }", three_d);
  three_d = with("velocity = [\"0.1*sin(_pi*X)\"]", "velocity = [0, 0, \"-Z\"]", three_d);
  three_d += "z_max = \"symmetry\"\n";
  const Config c3 = load_config_string(three_d, "ball.toml", {});
  EXPECT_EQ(c3.simulation.mode, Mode::three_d);
  EXPECT_EQ(c3.boundary.face[5], FaceCondition::symmetry);
  EXPECT_EQ(c3.bodies[0].shape.radius, 0.25);
  expect_same(c3, load_config_string(c3.resolved_toml, "r.toml", {}));
}

TEST(Input, LoadsFromAFile) {
  const auto dir = std::filesystem::temp_directory_path() / "cairn_test_input";
  std::filesystem::create_directories(dir);
  const auto path = (dir / "two_blocks.toml").string();
  std::ofstream(path) << base;
  const Config c = load_config(path, {"method.order=2"});
  EXPECT_EQ(c.source_file, path);
  EXPECT_EQ(c.method.order, 2);
  // A relative output folder lies next to the input file; one given with --set is taken as typed.
  EXPECT_EQ(c.output.directory, (dir / "out/two_blocks").string());
  EXPECT_EQ(load_config(path, {"output.directory=\"x/y\""}).output.directory, "x/y");
  EXPECT_EQ(load_config(path, {" output.directory = rel"}).output.directory, "rel");
  EXPECT_NE(c.resolved_toml.find("directory = \"" + (dir / "out/two_blocks").string() + "\""), std::string::npos);
  try {
    load_config(path, {"method.shape=\"cpdii\""});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "--set method.shape=\"cpdii\"");
  }
  std::ofstream(path) << with("cfl = 0.4", "cfl = -1");
  try {
    load_config(path, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":5: key 'simulation.cfl': expected a number in (0, 2]; found -1");
  }
  std::filesystem::remove_all(dir);
}

TEST(InputSchema, EveryDeclaredDefaultIsValid) {
  // Each section's defaults are validated when a key is absent, so a minimal input exercises them.
  const Config c = load_config_string(
      "[simulation]\ndimension = 2\nend_time = 1.0\n[grid]\norigin = [0, 0]\nextent = [1, 1]\n"
      "cell_size = 0.5\n[[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\ndensity = 1.0\n"
      "lambda = 1.0\nshear_modulus = 1.0\n[[body]]\nmaterial = \"m\"\n"
      "shape = { box = { min = [0, 0], max = [1, 1] } }\n",
      "minimal.toml", {});
  EXPECT_EQ(c.method.shape, "bspline2");
  EXPECT_EQ(c.method.update, "flip");
  EXPECT_EQ(c.output.directory, "out/minimal");
  for (const auto& d : declared_keys()) {
    EXPECT_FALSE(d.doc.empty()) << d.section << "." << d.name;
    EXPECT_FALSE(d.required && !d.default_value.empty()) << d.section << "." << d.name;
  }
}

TEST(InputSchema, KeysTextListsEverySection) {
  const std::string plain = keys_text(false);
  const std::string markdown = keys_text(true);
  for (const auto& s : section_names()) {
    EXPECT_NE(plain.find("[" + s + "]"), std::string::npos) << s;
    EXPECT_NE(markdown.find("[" + s + "]"), std::string::npos) << s;
  }
  for (const auto& d : declared_keys()) {
    // Shape parameters are listed as `kind.parameter`.
    const std::string shape = "body.shape.";
    const std::string name =
        d.section.rfind(shape, 0) == 0 ? d.section.substr(shape.size()) + "." + d.name : d.name;
    EXPECT_NE(markdown.find("`" + name + "`"), std::string::npos) << name;
  }
  EXPECT_NE(markdown.find("### model `linear_elastic`"), std::string::npos);
  EXPECT_NE(markdown.find("`youngs_modulus`"), std::string::npos);
  EXPECT_NE(plain.find("cfl"), std::string::npos);
}

}  // namespace
}  // namespace cairn
