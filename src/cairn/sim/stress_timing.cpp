#include "cairn/sim/stress_timing.hpp"

namespace cairn {

std::vector<std::pair<std::string, StressTiming>>& stress_timings() {
  static std::vector<std::pair<std::string, StressTiming>> timings;
  return timings;
}

const StressTiming& stress_timing(const std::string& name) {
  std::vector<std::string> names;
  for (const auto& [n, timing] : stress_timings()) {
    if (n == name) return timing;
    names.push_back(n);
  }
  throw UnknownName("stress update", name, names);
}

// seed 003 Sec. 3.3
CAIRN_REGISTER_STRESS_TIMING(usl, "usl", {0.0, 1.0, 0.0, "update stress last: from the updated grid velocities"});
CAIRN_REGISTER_STRESS_TIMING(usf, "usf", {1.0, 0.0, 0.0, "update stress first: from the momenta before the forces"});
CAIRN_REGISTER_STRESS_TIMING(usavg, "usavg", {0.5, 0.5, 0.0, "half a step first, half last"});
// seed 002: the last update from the re-extrapolated updated particle momenta
CAIRN_REGISTER_STRESS_TIMING(usl_plus, "usl+", {0.0, 0.0, 1.0, "update stress last, from re-extrapolated momenta"});
CAIRN_REGISTER_STRESS_TIMING(usavg_plus, "usavg+", {0.5, 0.0, 0.5, "half first, half from re-extrapolated momenta"});

}  // namespace cairn
