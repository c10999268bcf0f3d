#include "cairn/config/units.hpp"

#include <array>
#include <stdexcept>

namespace cairn {

namespace {

constexpr std::size_t n_quantities = 13;

struct System {
  const char* name;
  std::array<const char*, n_quantities> symbols;  ///< in the order of enum Quantity
};

// Derived units follow from the base units (length, mass, time): force = mass length / time^2,
// stress = force / length^2, energy = force length.
const std::array<System, 5>& systems() {
  static const std::array<System, 5> s{{
      {"SI", {"1", "m", "kg", "s", "K", "m/s", "m/s^2", "N", "Pa", "J", "kg/m^3", "m^3", "kg*m/s"}},
      {"mm_t_s", {"1", "mm", "t", "s", "K", "mm/s", "mm/s^2", "N", "MPa", "mJ", "t/mm^3", "mm^3", "t*mm/s"}},
      {"mm_kg_ms", {"1", "mm", "kg", "ms", "K", "m/s", "km/s^2", "kN", "GPa", "J", "kg/mm^3", "mm^3", "kg*m/s"}},
      {"cgs", {"1", "cm", "g", "s", "K", "cm/s", "cm/s^2", "dyn", "Ba", "erg", "g/cm^3", "cm^3", "g*cm/s"}},
      {"unspecified",
       {"1", "length", "mass", "time", "temperature", "length/time", "length/time^2",
        "mass*length/time^2", "mass/(length*time^2)", "mass*length^2/time^2", "mass/length^3",
        "length^3", "mass*length/time"}},
  }};
  return s;
}

}  // namespace

std::string unit_symbol(std::string_view system, Quantity q) {
  for (const auto& s : systems())
    if (system == s.name) return s.symbols[static_cast<std::size_t>(q)];
  throw std::invalid_argument("unknown unit system '" + std::string(system) + "'");
}

std::vector<std::string> unit_system_names() {
  std::vector<std::string> names;
  for (const auto& s : systems()) names.emplace_back(s.name);
  return names;
}

}  // namespace cairn
