// The input layer's positive paths: defaults, overrides, the resolved TOML reading back to the
// same Config, 1D and 3D inputs, and the schema's own defaults and key listing (the errors are in
// test_input_errors.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cairn/input/input.hpp"
#include "cairn/input/schema.hpp"
#include "input_case.hpp"

namespace cairn {
namespace {

using test::base;
using test::with;

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
