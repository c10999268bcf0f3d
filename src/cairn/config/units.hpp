// Declared unit systems ([simulation] units): Cairn computes in any consistent set of units; the
// declaration only labels the output files (HDF5 attributes) and documents the input.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace cairn {

/// Physical quantities that output arrays carry.
enum class Quantity {
  dimensionless, length, mass, time, temperature, velocity, acceleration, force, stress,
  energy, density, volume, momentum
};

/// The unit symbol of a quantity in a declared system, e.g. unit_symbol("SI", stress) = "Pa".
/// In the "unspecified" system the symbol is the dimension, e.g. "mass/(length*time^2)".
/// Throws std::invalid_argument for an unknown system name.
[[nodiscard]] std::string unit_symbol(std::string_view system, Quantity q);

/// The declared systems, in the order `cairn keys` lists them.
[[nodiscard]] std::vector<std::string> unit_system_names();

}  // namespace cairn
