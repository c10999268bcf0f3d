// [[velocity]] node-set conditions and [[wall]] moving walls (seed 000 Sec. 2.4-2.5): node
// selection, start/end values and reactions, precedence between conditions and its note, the
// wall's controlled nodes, its motion and the gradient estimate of Eq. 4, the velocity / lumped /
// combined full-mass methods (Eq. 3) and Cairn's constrained method (stable against fixed faces
// for any order, where combined grows), history columns and restart, and the input errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "cairn/io/checkpoint.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

/// A 1D or 2D bar x in [-1, 1] (y in [0, 0.5]) on 0.125 cells, neo-Hookean, initial velocity
/// rate X, plus the caller's tables.
std::string bar(const std::string& extra, int dimension = 2, const std::string& method = "") {
  const std::string grid = dimension == 1 ? "origin = [-2.0]\nextent = [4.0]\n"
                                          : "origin = [-2.0, -0.5]\nextent = [4.0, 1.5]\n";
  const std::string box = dimension == 1 ? "{ min = [-1.0], max = [1.0] }"
                                         : "{ min = [-1.0, 0.0], max = [1.0, 0.5] }";
  const std::string velocity = dimension == 1 ? "[\"rate*X\"]" : "[\"rate*X\", 0.0]";
  return "[simulation]\ndimension = " + std::to_string(dimension) +
         "\nend_time = 1.0\ncfl = 0.2\n[grid]\n" + grid + "cell_size = 0.125\n[method]\n" + method +
         "\n[constants]\nrate = 0.01\n[[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\n"
         "form = \"j_squared\"\ndensity = 1.0\nlambda = 0.0\nshear_modulus = 1.0\n"
         "[[body]]\nname = \"bar\"\nmaterial = \"m\"\nshape = { box = " + box +
         " }\nparticles_per_cell = 2\nvelocity = " + velocity + "\n" + extra;
}

TEST(VelocityConditions, NodeSetsByFaceBoxAndPlane) {
  auto nodes = [](const std::string& sel) {
    Simulation<2> sim(load_config_string(bar("[[velocity]]\n" + sel + "direction = [1.0, 0.0]\n"), "b.toml"));
    std::vector<IVec<2>> out;
    for (auto i : sim.velocity_conditions().set_nodes(0)) out.push_back(sim.grid().multi_index(i));
    return out;
  };
  // Face x_max of a 32 x 12 grid with bspline2 (2 ghost layers): the face and two ghost columns.
  const auto face = nodes("face = \"x_max\"\n");
  EXPECT_EQ(face.size(), 3u * (13u + 4u));
  for (const auto& j : face) EXPECT_GE(j[0], 32);
  // A flat box is a line of nodes: x = 1, y in [0, 0.5].
  const auto line = nodes("box_min = [1.0, 0.0]\nbox_max = [1.0, 0.5]\n");
  EXPECT_EQ(line.size(), 5u);
  for (const auto& j : line) EXPECT_EQ(j[0], 24);
  // A plane (2D: line) x = -1 intersected with a box.
  const auto plane = nodes("plane_axis = \"x\"\nplane_at = -1.0\nbox_min = [-5.0, 0.25]\nbox_max = [5.0, 5.0]\n");
  EXPECT_EQ(plane.size(), 7u + 2u);  // y = 0.25 ... 1.0 and the two ghost rows beyond
  EXPECT_THROW(nodes("box_min = [0.01, 0.01]\nbox_max = [0.02, 0.02]\n"), InputError);  // selects no node: file, line, key, expected, found
}

TEST(VelocityConditions, StepImposesStartAndEndValuesAndRecordsTheReaction) {
  // v_x = 2 t on the line x = 1; after one step from t = 0 every node of the line has v = 0 and
  // v+ = 2 dt, and the reaction is m (v_end - v_start) / dt - f.
  Simulation<2> sim(load_config_string(
      bar("[[velocity]]\nname = \"pull\"\nplane_axis = \"x\"\nplane_at = 1.0\ndirection = [2.0, 0.0]\n"
          "velocity = \"2*t\"\n"),
      "b.toml"));
  const double dt = 1e-3;
  sim.step(dt);
  const auto& n = sim.nodes();
  Vec<2> reaction = Vec<2>::Zero();
  for (auto i : sim.velocity_conditions().set_nodes(0)) {
    EXPECT_EQ(n.velocity[i][0], 0.0);
    EXPECT_NEAR(n.velocity_new[i][0], 2.0 * dt, 1e-15);
    reaction[0] += n.mass[i] * (2.0 * dt - 0.0) / dt - n.force[i][0];
  }
  EXPECT_EQ(sim.velocity_conditions().names(), std::vector<std::string>{"pull"});
  EXPECT_NEAR(sim.velocity_conditions().reactions()[0][0], reaction[0], 1e-12 * std::abs(reaction[0]));
  EXPECT_EQ(sim.velocity_conditions().reactions()[0][1], 0.0);
}

TEST(VelocityConditions, LaterConditionWinsAndTheRunSaysSoOnce) {
  Simulation<2> sim(load_config_string(
      bar("[boundary]\nx_max = \"fixed\"\n"
          "[[velocity]]\nname = \"a\"\nface = \"x_max\"\ndirection = [1.0, 0.0]\nvelocity = 1.0\n"
          "[[velocity]]\nname = \"b\"\nface = \"x_max\"\ndirection = [1.0, 1.0]\nvelocity = 3.0\n"
          "[[velocity]]\nname = \"c\"\nface = \"x_max\"\ndirection = [0.0, 1.0]\nvelocity = 0.0\n"),
      "b.toml"));
  sim.step(1e-4);
  const auto notes = sim.take_notes();
  // [boundary] vs a, a vs b, [boundary] vs b, b vs c, [boundary] vs c; a and c are orthogonal.
  ASSERT_EQ(notes.size(), 5u);
  bool a_then_b = false;
  for (const auto& s : notes) a_then_b |= s.find("'b' and velocity condition 'a'") != std::string::npos;
  EXPECT_TRUE(a_then_b);
  sim.step(1e-4);
  EXPECT_TRUE(sim.take_notes().empty());  // once per pair
  // In order: fixed (0, 0); a: v_x = 1; b: v . (1, 1)/sqrt2 = 3 gives (1/2 + 3/sqrt2, 3/sqrt2 - 1/2);
  // c, the last, holds v_y = 0 and leaves v_x.
  const auto i = sim.velocity_conditions().set_nodes(0)[0];
  EXPECT_NEAR(sim.nodes().velocity_new[i][1], 0.0, 1e-15);
  EXPECT_NEAR(sim.nodes().velocity_new[i][0], 0.5 + 3.0 / std::sqrt(2.0), 1e-12);
}

TEST(VelocityConditions, HeldComponentsAreReadFromTheConditions) {
  // What the WLS particle update asks of the conditions (docs/wls.md, departure 12): per node,
  // the components a condition sets. A symmetry floor sets v_y on its nodes (and, through the
  // mirror, on the ghost row below); a fixed face sets both components; a node set along an
  // oblique direction sets both components it has; an axis-aligned one only its own.
  Simulation<2> sim(load_config_string(
      bar("[boundary]\ny_min = \"symmetry\"\nx_max = \"fixed\"\n"
          "[[velocity]]\nplane_axis = \"x\"\nplane_at = 1.0\ndirection = [1.0, 1.0]\nvelocity = 0.5\n"
          "[[velocity]]\nplane_axis = \"x\"\nplane_at = -1.0\ndirection = [1.0, 0.0]\nvelocity = \"t\"\n"),
      "b.toml"));
  sim.step(1e-4);  // the node sets' entries of the step
  const auto& grid = sim.grid();
  std::vector<std::uint8_t> held;
  held_components(sim.grid_conditions(), sim.velocity_conditions(), grid.n_nodes(), held);
  ASSERT_EQ(held.size(), static_cast<std::size_t>(grid.n_nodes()));
  const auto at = [&](double x, double y) {
    for (std::int32_t i = 0; i < grid.n_nodes(); ++i)
      if ((grid.node_position(i) - Vec<2>(x, y)).norm() < 1e-12) return static_cast<int>(held[i]);
    return -1;
  };
  EXPECT_EQ(at(0.0, -0.5), 0b10);   // on the symmetry floor: v_y
  EXPECT_EQ(at(0.0, 0.0), 0b00);    // inside
  EXPECT_EQ(at(2.0, 0.25), 0b11);   // on the fixed face
  EXPECT_EQ(at(1.0, 0.25), 0b11);   // the oblique node set
  EXPECT_EQ(at(-1.0, 0.25), 0b01);  // the node set along x
  EXPECT_EQ(at(-1.0, -0.5), 0b11);  // the floor and the node set along x
  // Every node agrees with what imposing the conditions on a probe field changes (a probe whose
  // components differ, so that no projection on a direction vanishes).
  const Vec<2> probe(1234.5, 2345.6);
  std::vector<Vec<2>> field(grid.n_nodes(), probe);
  sim.grid_conditions().apply(field, {}, nullptr, 1.0);
  sim.velocity_conditions().apply(field, VelocityConditions<2>::When::end);
  int n_held = 0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    int changed = 0;
    for (int a = 0; a < 2; ++a) changed |= (field[i][a] != probe[a]) << a;
    EXPECT_EQ(held[i], changed) << "node " << i << " at " << grid.node_position(i).transpose();
    n_held += changed != 0;
  }
  EXPECT_GT(n_held, 20);
  // Without any condition there is nothing to read.
  Simulation<2> free(load_config_string(bar(""), "b.toml"));
  held_components(free.grid_conditions(), free.velocity_conditions(), free.grid().n_nodes(), held);
  EXPECT_TRUE(held.empty());
}

TEST(MovingWall, ControlsInsideNodesWithinDepthAndOutsideNodesWithMass) {
  for (const double depth : {0.5, 1.0, 1.5, 2.0}) {
    Simulation<1> sim(load_config_string(
        bar("[[wall]]\naxis = \"x\"\ninside = \"below\"\nposition = 1.0\ndepth = " + std::to_string(depth) +
                "\nvelocity = \"rate\"\n",
            1),
        "b.toml"));
    sim.step(1e-3);
    const auto& entries = sim.velocity_conditions().entries();
    const double h = 0.125;
    int inside = 0, outside = 0;
    for (const auto& e : entries) {
      const double x = sim.grid().node_position(e.node)[0];
      if (x <= 1.0) {
        EXPECT_LE(1.0 - x, depth * h + 1e-12);
        ++inside;
      } else {
        EXPECT_GT(sim.nodes().mass[e.node], 0.0);
        ++outside;
      }
    }
    EXPECT_EQ(inside, static_cast<int>(std::floor(depth + 1e-9)) + 1) << depth;
    EXPECT_EQ(outside, 1) << depth;  // bspline2 with 2 particles per cell reaches one node beyond
  }
}

TEST(MovingWall, MovesWithItsVelocityAndEstimatesTheGradient) {
  // A 1D bar with V = rate X: with depth 2, nodes 1 and 2 of Eq. 4 (3 and 2 cells deep) see a full
  // stencil of particles, so m^-1 p there is the exact linear field and Eq. 4 returns its slope.
  const std::string walls =
      "[[wall]]\nname = \"right\"\naxis = \"x\"\ninside = \"below\"\nposition = 1.0\nvelocity = \"rate*(1 + t)\"\n"
      "gradient = \"estimate\"\ndepth = 2.0\n"
      "[[wall]]\nname = \"left\"\naxis = \"x\"\ninside = \"above\"\nposition = -1.0\nvelocity = \"-rate\"\n"
      "gradient = \"estimate\"\ndepth = 2.0\n";
  Simulation<1> sim(load_config_string(bar(walls, 1, "shape = \"bspline2\"\nupdate = \"fmpm\"\norder = 2"), "b.toml"));
  const double dt = 1e-3;
  sim.step(dt);
  const auto& w = sim.velocity_conditions().walls();
  EXPECT_NEAR(w[1].gradient(), 0.01, 1e-14);  // the exact field at t = 0: V = rate X
  EXPECT_NEAR(w[0].gradient(), 0.01, 1e-14);  // v_b = rate at t = 0
  // Eq. 4 evaluated here, from the extrapolated velocities m^-1 p of the step's own P2G, at
  // nodes 2 (deepest controlled inside node, within d = 2 cells of the wall) and 1 (the next one
  // in). The estimate changes by about 6e-5 over 200 steps, so a gradient frozen at its first
  // value, or estimated from the wrong nodes or times, fails the 1e-12 comparison.
  const double h = 0.125;
  double first_estimate = w[1].gradient(), largest_change = 0.0;
  for (int s = 1; s <= 200; ++s) {
    if (s % 50 == 0) {
      const double x_w = w[1].position(), v_b = -0.01;  // left wall, moving at -rate
      sim.build_stencils();
      sim.particles_to_grid(true, false);
      std::vector<std::pair<double, double>> inside;  // (x_i - x_wall, m^-1 p) for nodes with mass
      for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
        const double dx = sim.grid().node_position(i)[0] - x_w;
        if (dx >= -1e-9 * h && sim.nodes().mass[i] > 0.0) inside.emplace_back(dx, sim.nodes().momentum[i][0] / sim.nodes().mass[i]);
      }
      std::sort(inside.begin(), inside.end());
      std::size_t n2 = 0;
      while (n2 + 1 < inside.size() && inside[n2 + 1].first <= 2.0 * h + 1e-9 * h) ++n2;
      const auto [dx2, v2] = inside[n2];
      const auto [dx1, v1] = inside[n2 + 1];
      const double expected = ((v1 - v_b) * dx1 + (v2 - v_b) * dx2) / (dx1 * dx1 + dx2 * dx2);
      sim.step(dt);
      EXPECT_NEAR(w[1].gradient(), expected, 1e-12 * expected) << "step " << s;
      largest_change = std::max(largest_change, std::abs(w[1].gradient() - first_estimate));
    } else {
      sim.step(dt);
    }
  }
  EXPECT_GT(largest_change, 1e-5);
  const double T = 201 * dt;
  EXPECT_NEAR(w[0].position(), 1.0 + 0.01 * (T + 0.5 * T * T), 1e-12);  // trapezoid is exact here
  EXPECT_NEAR(w[1].position(), -1.0 - 0.01 * T, 1e-12);
  // The estimate stays close to the bar's free stretch rate / (1 + rate t) near this wall (the
  // right wall's acceleration has not reached it): within 1 % (its particle-lattice error).
  EXPECT_NEAR(w[1].gradient(), 0.01 / (1.0 + 0.01 * T), 1e-4);
}

TEST(MovingWall, FullMassMethodsImposeTheConditionsAsSeed000Eq3Says) {
  // FMPM(2) and FMPM(4): `velocity`, `combined` and `constrained` hold the wall values exactly
  // on v+ = m~^-1 p+, `lumped` only approximately.
  const std::string walls =
      "[[wall]]\naxis = \"x\"\ninside = \"below\"\nposition = 1.0\nvelocity = \"rate\"\ngradient = \"rate\"\n"
      "depth = 1.5\n";
  for (const std::string method : {"velocity", "lumped", "combined", "constrained"})
  for (const int order : {2, 4}) {
    Simulation<2> sim(load_config_string(
        bar(walls, 2, "shape = \"cpdi\"\nupdate = \"fmpm\"\norder = " + std::to_string(order) +
                          "\nvelocity_bc_method = \"" + method + "\""),
        "b.toml"));
    for (auto& v : sim.particles().velocity) v[1] = 0.001;  // something for the walls to correct
    const double dt = 1e-3;
    sim.step(dt);
    double worst = 0.0;
    for (const auto& e : sim.velocity_conditions().entries())
      worst = std::max(worst, std::abs(sim.nodes().velocity_full[e.node][0] - e.end));
    if (method == "lumped") EXPECT_GT(worst, 1e-9) << method << " " << order;
    else EXPECT_LT(worst, 1e-15) << method << " " << order;
  }
}

/// A 1D bar (E = 2.5 GPa, rho = 1000, 5 mm cells, GIMP, 2 ppc) moving at -1 m/s onto a fixed
/// x_min face; returns the largest kinetic + strain energy over `steps` steps of dt, relative to
/// the initial 20 J/m^2 (1.0 = no growth).
double fixed_face_energy_growth(const std::string& update, int order, const std::string& bc_method, int steps,
                                double dt) {
  const std::string input =
      "[simulation]\ndimension = 1\nend_time = 1.0\ndt = " + std::to_string(dt) +
      "\n[grid]\norigin = [0.0]\nextent = [0.06]\ncell_size = 0.005\n[method]\nshape = \"gimp\"\n"
      "update = \"" + update + "\"\norder = " + std::to_string(order) + "\nvelocity_bc_method = \"" + bc_method +
      "\"\n[boundary]\nx_min = \"fixed\"\n[[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\n"
      "density = 1000.0\nyoungs_modulus = 2.5e9\npoissons_ratio = 0.0\n[[body]]\nmaterial = \"m\"\n"
      "shape = { box = { min = [0.0], max = [0.04] } }\nparticles_per_cell = 2\nvelocity = [\"-1\"]\n";
  Simulation<1> sim(load_config_string(input, "bar.toml"));
  const double e0 = 0.5 * 1000.0 * 0.04;
  double worst = 1.0;
  for (int s = 0; s < steps; ++s) {
    try {
      sim.step(dt);
    } catch (const SimulationFailure&) {
      return std::numeric_limits<double>::infinity();  // it left the grid: unbounded growth
    }
    const Totals t = sim.totals();
    worst = std::max(worst, (t.kinetic_energy + t.strain_energy) / e0);
  }
  return worst;
}

TEST(FullMassConditions, ConstrainedStaysBoundedAgainstAFixedFaceWhereCombinedGrows) {
  // The bar of docs/boundary-conditions.md ("Why constrained"): 1000 steps of 0.25 us, the first
  // rebound. Constrained never gains energy for XPIC(k)/FMPM(k) up to k = 8; the paper's combined
  // method grows without bound from k = 3 (the finding that made constrained the default).
  for (const std::string update : {"xpic", "fmpm"})
    for (const int order : {3, 5, 8}) {
      EXPECT_LT(fixed_face_energy_growth(update, order, "constrained", 1000, 2.5e-7), 1.0 + 1e-6)
          << update << "(" << order << ") constrained";
      EXPECT_GT(fixed_face_energy_growth(update, order, "combined", 1000, 2.5e-7), 10.0)
          << update << "(" << order << ") combined";
    }
}

TEST(FullMassConditions, ConstrainedIsTheSameExpansionWhenNothingIsHeld) {
  // Without conditions the Richardson form of `constrained` is the polynomial
  // (I + A + ... + A^(k-1)) of the other methods: equal to round-off.
  auto run_bar = [](const std::string& method) {
    Simulation<2> sim(load_config_string(
        bar("", 2, "shape = \"cpdi\"\nupdate = \"fmpm\"\norder = 6\nvelocity_bc_method = \"" + method + "\""),
        "b.toml"));
    for (int s = 0; s < 20; ++s) sim.step(1e-3);
    return sim.particles().velocity;
  };
  const auto a = run_bar("combined"), b = run_bar("constrained");
  ASSERT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t p = 0; p < a.size(); ++p) worst = std::max(worst, (a[p] - b[p]).norm());
  EXPECT_LT(worst, 1e-15);  // velocities are about 0.01
  EXPECT_GT(a.front().norm(), 1e-3);
}

TEST(MovingWall, HistoryColumnsAndBitIdenticalRestart) {
  const fs::path a = fs::temp_directory_path() / ("cairn_wall_full_" + std::to_string(::getpid()));
  const fs::path b = fs::temp_directory_path() / ("cairn_wall_rest_" + std::to_string(::getpid()));
  fs::remove_all(a);
  fs::remove_all(b);
  const std::string input = bar(
      "[[wall]]\nname = \"r\"\naxis = \"x\"\ninside = \"below\"\nposition = 1.0\nvelocity = \"rate\"\n"
      "gradient = \"estimate\"\n[[velocity]]\nname = \"floor\"\nplane_axis = \"y\"\nplane_at = 0.0\n"
      "direction = [0.0, 1.0]\n[output]\nevery = 0.25\ncheckpoint_every = 0.5\n",
      2, "shape = \"cpdi\"\nupdate = \"fmpm\"\norder = 2");
  RunOptions quiet{true};
  const RunSummary full = run(load_config_string(input, "w.toml", {"output.directory=\"" + a.string() + "\""}), quiet);
  std::ifstream ha(a / "history.csv");
  std::string header;
  std::getline(ha, header);
  EXPECT_NE(header.find("reaction_floor_x,reaction_floor_y,reaction_r_x,reaction_r_y,wall_r_position"),
            std::string::npos)
      << header;
  const RunSummary rest = restart(a / "checkpoint-0000.h5", {"output.directory=\"" + b.string() + "\""}, quiet);
  EXPECT_LT(rest.steps, full.steps);
  const auto end_a = read_checkpoint<2>(full.last_checkpoint);
  const auto end_b = read_checkpoint<2>(rest.last_checkpoint);
  ASSERT_EQ(end_a.particles.n(), end_b.particles.n());
  for (std::size_t p = 0; p < end_a.particles.n(); ++p) {
    ASSERT_EQ(end_a.particles.position[p], end_b.particles.position[p]) << p;
    ASSERT_EQ(end_a.particles.velocity[p], end_b.particles.velocity[p]) << p;
  }
  EXPECT_EQ(end_a.history_rows, end_b.history_rows);
  EXPECT_EQ(end_a.scalars.at("wall_position_0"), end_b.scalars.at("wall_position_0"));
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(LoadInput, ErrorsNameTheKey) {
  auto error_of = [](const std::string& extra) -> std::string {
    try {
      load_config_string(bar(extra), "b.toml");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of("[[wall]]\naxis = \"x\"\ninside = \"below\"\nposition = 3.0\n").find("wall[0].position"),
            std::string::npos);
  EXPECT_NE(error_of("[[wall]]\naxis = \"z\"\ninside = \"below\"\nposition = 0.0\n").find("wall[0].axis"),
            std::string::npos);
  EXPECT_NE(error_of("[[velocity]]\ndirection = [1.0, 0.0]\n").find("velocity[0]"), std::string::npos);
  EXPECT_NE(error_of("[[velocity]]\nface = \"x_min\"\ndirection = [0.0, 0.0]\n").find("velocity[0].direction"),
            std::string::npos);
  EXPECT_NE(error_of("[[velocity]]\nface = \"x_min\"\nbox_min = [0.0, 0.0]\ndirection = [1.0, 0.0]\n")
                .find("box_max"),
            std::string::npos);
  EXPECT_NE(error_of("[[traction]]\nbody = \"bra\"\nside = \"x_min\"\ntraction = [1.0, 0.0]\n").find("did you mean"),
            std::string::npos);
  EXPECT_NE(error_of("[[traction]]\ntraction = [1.0, 0.0]\n").find("traction[0]"), std::string::npos);
  EXPECT_NE(error_of("[[traction]]\nside = \"x_min\"\ntraction = [1.0, 0.0]\ntable = [[1.0, 0.0], [0.5, 1.0]]\n")
                .find("traction[0].table"),
            std::string::npos);
  EXPECT_NE(error_of("[[wall]]\nname = \"w\"\naxis = \"x\"\ninside = \"below\"\nposition = 0.0\n"
                     "[[velocity]]\nname = \"w\"\nface = \"x_min\"\ndirection = [1.0, 0.0]\n")
                .find("wall[0].name"),
            std::string::npos);
}

TEST(LoadInput, ResolvedInputReadsBackToTheSameConditions) {
  const std::string input = bar(
      "[[traction]]\nbody = \"bar\"\nside = \"x_min\"\nbox_min = [-1.0, 0.0]\nbox_max = [0.0, 0.25]\n"
      "traction = [-1.0, 0.5]\nscale = \"tri(t, 1e-3)\"\ntable = [[0.0, 1.0], [1.0, 2.0]]\n"
      "[[velocity]]\nname = \"v\"\nface = \"y_min\"\nplane_axis = \"x\"\nplane_at = 0.5\ndirection = [0.0, 2.0]\n"
      "velocity = \"0.1*ramp(t, 0.5)\"\n"
      "[[wall]]\naxis = \"x\"\ninside = \"above\"\nposition = -1.0\nvelocity = -0.5\ngradient = \"estimate\"\n"
      "depth = 1.5\n");
  const Config a = load_config_string(input, "b.toml");
  const Config b = load_config_string(a.resolved_toml, "resolved.toml");
  EXPECT_EQ(a.resolved_toml, b.resolved_toml);
  ASSERT_EQ(b.tractions.size(), 1u);
  EXPECT_EQ(b.tractions[0].side, 0);
  EXPECT_EQ(b.tractions[0].scale, "tri(t, 1e-3)");
  EXPECT_EQ(b.tractions[0].table.size(), 2u);
  ASSERT_EQ(b.velocity_conditions.size(), 1u);
  EXPECT_EQ(b.velocity_conditions[0].face, 2);
  EXPECT_EQ(b.velocity_conditions[0].plane_axis, 0);
  EXPECT_EQ(b.velocity_conditions[0].direction, (std::vector<double>{0.0, 1.0}));
  ASSERT_EQ(b.walls.size(), 1u);
  EXPECT_EQ(b.walls[0].name, "wall0");
  EXPECT_FALSE(b.walls[0].inside_below);
  EXPECT_EQ(b.walls[0].gradient, WallGradient::estimate);
  EXPECT_EQ(b.walls[0].depth, 1.5);
  // --set reaches entries of the new arrays of tables.
  const Config c = load_config_string(input, "b.toml", {"wall[0].depth=2.5", "velocity.0.velocity=3"});
  EXPECT_EQ(c.walls[0].depth, 2.5);
  EXPECT_EQ(c.velocity_conditions[0].velocity, "3");
}

}  // namespace
}  // namespace cairn
