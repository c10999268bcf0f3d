// When a step updates the stresses (Task 5 of seed 000 Table 1): the stress-update timings of
// seed 003 Sec. 3.3 (USF, USL, USAVG) and seed 002 (USL+, USAVG+, which re-extrapolate the
// updated particle momenta first). A timing is the fraction of dt that each of the three places
// where a step can update the stresses takes; one registration line each.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cairn/util/registry.hpp"

namespace cairn {

struct StressTiming {
  /// From v = m^-1 p (m~_k^-1 p under FMPM), before the internal forces are extrapolated.
  double before_forces = 0.0;
  /// From the updated grid velocity v+ (or FMPM's), in the particle update's own loop.
  double with_particle_update = 0.0;
  /// From the re-extrapolated updated particle momenta q = S^T M V^(n+1), after the update.
  double after_update = 0.0;
  std::string doc;
};

/// The registered timings (method.stress_update) by name, in registration order.
std::vector<std::pair<std::string, StressTiming>>& stress_timings();

/// The timing `name` (throws UnknownName listing the valid names).
const StressTiming& stress_timing(const std::string& name);

inline bool register_stress_timing(const std::string& name, StressTiming timing) {
  stress_timings().emplace_back(name, std::move(timing));
  return true;
}

#define CAIRN_REGISTER_STRESS_TIMING(id, name, ...) \
  static const bool cairn_stress_timing_##id = ::cairn::register_stress_timing(name, ::cairn::StressTiming __VA_ARGS__)

}  // namespace cairn
