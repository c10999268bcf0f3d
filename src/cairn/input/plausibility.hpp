// Material values that are valid input but no real solid has, in the declared unit system
// ([simulation] units): densities and elastic moduli outside the ranges of real materials, and
// the wave speed they give. `cairn check` warns about them (it never fails on them): most are a
// unit slip, such as a steel density of 1.0 (7850 kg/m^3 in SI, 7.85 g/cm^3 in cgs), which
// checks fine and then makes the time step hundreds of times smaller.
#pragma once

#include <string>
#include <vector>

#include "cairn/config/config.hpp"

namespace cairn {

/// The plausible range of one quantity, in SI.
struct PlausibleRange {
  double low, high;
};

/// Densities of real solids in kg/m^3: from light foams to osmium (22 600).
inline constexpr PlausibleRange plausible_density{5.0, 2.5e4};
/// Elastic moduli (Young's, shear, bulk, Lame's lambda) in Pa: from soft gels to diamond.
inline constexpr PlausibleRange plausible_modulus{1.0e3, 2.0e12};
/// Elastic wave speeds in m/s: none is faster than diamond's (about 18 km/s).
inline constexpr double plausible_wave_speed_max = 2.0e4;

/// One line per implausible value: the key (material[i].density), its value with its unit, the
/// range of real solids in the declared system, and the likely slip (the unit systems in which
/// the same number would be plausible). Empty for units = "unspecified".
std::vector<std::string> implausible_material_values(const Config& config);

}  // namespace cairn
