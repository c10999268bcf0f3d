// The input layer's errors: one test per class of input error, each checking that the message
// names the place (file:line or the --set text), the key, what was expected and what was found;
// then every independent error of a file reported in one reading.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "cairn/input/input.hpp"
#include "cairn/materials/material.hpp"
#include "input_case.hpp"

namespace cairn {
namespace {

using test::base;
using test::error_of;
using test::message;
using test::with;

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

}  // namespace
}  // namespace cairn
