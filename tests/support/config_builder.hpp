// Builds small Configs in code for unit tests (no TOML involved).
#pragma once

#include <string>

#include "cairn/config/config.hpp"

namespace cairn::test {

/// A unit-cube-ish domain [0, 1]^D with 10 cells per axis and one block body in the middle.
inline Config box_config(int D, const std::string& shape, const std::string& material = "linear_elastic") {
  Config c;
  c.simulation.dimension = D;
  c.simulation.mode = D == 1 ? Mode::uniaxial_strain_1d : D == 2 ? Mode::plane_strain : Mode::three_d;
  c.simulation.end_time = 1.0;
  c.simulation.cfl = 0.4;
  c.grid.origin.assign(D, 0.0);
  c.grid.extent.assign(D, 1.0);
  c.grid.cell_size.assign(D, 0.1);
  c.method.shape = shape;
  MaterialConfig m;
  m.name = "mat";
  m.model = material;
  m.numbers = {{"density", 1000.0}, {"youngs_modulus", 1.0e6}, {"poissons_ratio", 0.3}};
  if (material == "neo_hookean") m.strings["form"] = "ln_j";
  c.materials.push_back(m);
  BodyConfig b;
  b.name = "block";
  b.material = "mat";
  b.shape.kind = "box";
  b.shape.min.assign(D, 0.3);
  b.shape.max.assign(D, 0.7);
  b.particles_per_cell.assign(D, 2);
  c.bodies.push_back(b);
  return c;
}

}  // namespace cairn::test
