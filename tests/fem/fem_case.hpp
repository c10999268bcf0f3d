// TOML inputs for the FEM tests (small, generated meshes).
#pragma once

#include <fmt/format.h>

#include <string>

#include "cairn/input/input.hpp"

namespace cairn::test {

/// A neo-Hookean (seed 001 Eq. 31-32) [fem] input; `fem` holds the [fem] keys besides material,
/// `extra` any further sections.
inline Config fem_config(const std::string& fem, const std::string& extra = "", double E = 1.0e4,
                         double nu = 0.3, const std::string& mode = "plane_strain") {
  const std::string text = fmt::format(R"(
[simulation]
dimension = 2
mode = "{}"
end_time = 1.0
cfl = 0.3

[[material]]
name = "m"
model = "neo_hookean"
density = 1.0
youngs_modulus = {}
poissons_ratio = {}

[fem]
material = "m"
{}

[output]
snapshots = false
checkpoints = false
{}
)",
                                       mode, E, nu, fem, extra);
  return load_config_string(text, "fem_test.toml", {});
}

}  // namespace cairn::test
