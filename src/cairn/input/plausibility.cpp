#include "cairn/input/plausibility.hpp"

#include <fmt/format.h>

#include <array>

#include "cairn/config/units.hpp"
#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

/// One SI unit of density, stress and velocity expressed in each declared system (units.cpp):
/// 1 kg/m^3 = 1e-12 t/mm^3, 1 Pa = 1e-6 MPa, 1 m/s = 1000 mm/s, ...
struct Scale {
  const char* system;
  double density, stress, velocity;
};
constexpr std::array<Scale, 4> scales{{{"SI", 1.0, 1.0, 1.0},
                                       {"mm_t_s", 1e-12, 1e-6, 1e3},
                                       {"mm_kg_ms", 1e-9, 1e-9, 1.0},
                                       {"cgs", 1e-3, 10.0, 1e2}}};

const Scale* scale_of(const std::string& system) {
  for (const auto& s : scales)
    if (system == s.system) return &s;
  return nullptr;
}

/// " (as <unit> (units = "<system>") it would be a real solid's: a unit slip?)" for the systems
/// other than `own` in which the number `x` lies in range; "" when none.
std::string likely_slip(double x, const Scale& own, double Scale::*factor, Quantity q, PlausibleRange si) {
  std::string systems;
  for (const auto& s : scales) {
    if (&s == &own) continue;
    const double in_si = x / (s.*factor);
    if (in_si >= si.low && in_si <= si.high)
      systems += fmt::format("{}{} (units = \"{}\")", systems.empty() ? "" : " or ", unit_symbol(s.system, q), s.system);
  }
  return systems.empty() ? "" : fmt::format("; as {} it would be a real solid's: a unit slip?", systems);
}

}  // namespace

std::vector<std::string> implausible_material_values(const Config& config) {
  std::vector<std::string> out;
  const std::string& system = config.simulation.units;
  const Scale* own = scale_of(system);
  if (!own) return out;  // "unspecified": no ranges to compare with
  auto check = [&](const std::string& key, double x, double Scale::*factor, Quantity q, PlausibleRange si,
                   const char* what, const char* example) {
    const double low = si.low * (own->*factor), high = si.high * (own->*factor);
    if (!(x > 0.0) || (x >= low && x <= high)) return;
    const std::string unit = unit_symbol(system, q);
    out.push_back(fmt::format("key '{}': {} {} {} (units = \"{}\") is {} that of any real solid ({:.3g} to {:.3g} {}; "
                              "{}){}",
                              key, what, x, unit, system, x < low ? "below" : "above", low, high, unit, example,
                              likely_slip(x, *own, factor, q, si)));
  };
  for (std::size_t m = 0; m < config.materials.size(); ++m) {
    const MaterialConfig& mc = config.materials[m];
    const std::string prefix = fmt::format("material[{}]", m);
    if (mc.has("density"))
      check(prefix + ".density", mc.number("density"), &Scale::density, Quantity::density, plausible_density,
            "density", fmt::format("steel {:.4g} {}", 7850.0 * own->density, unit_symbol(system, Quantity::density)).c_str());
    for (const char* modulus : {"youngs_modulus", "shear_modulus", "bulk_modulus", "lambda"})
      if (mc.has(modulus))
        check(prefix + "." + modulus, mc.number(modulus), &Scale::stress, Quantity::stress, plausible_modulus,
              "modulus", fmt::format("steel's Young's modulus {:.4g} {}", 200e9 * own->stress,
                                     unit_symbol(system, Quantity::stress)).c_str());
    double c = 0.0;
    try {
      c = make_material(mc)->wave_speed(Mat3::Identity());
    } catch (const std::exception&) {
      continue;  // the reading has refused such a material already
    }
    const double c_max = plausible_wave_speed_max * own->velocity;
    if (c > c_max)
      out.push_back(fmt::format("material '{}' ({}): its wave speed {:.4g} {} is faster than any real solid's (at most "
                                "{:.3g} {}, diamond's): check its density and moduli against units = \"{}\"; the time "
                                "step shrinks in proportion",
                                mc.name, prefix, c, unit_symbol(system, Quantity::velocity), c_max,
                                unit_symbol(system, Quantity::velocity), system));
  }
  return out;
}

}  // namespace cairn
