// A run that cannot go on: a particle left the grid, a value became NaN/Inf, a particle
// inverted. Carries which particle and what quantity; the run loop adds step and time.
#pragma once

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace cairn {

/// A number for a failure message, with 6 significant digits: "-1.23457e-07", not the
/// "-0.000000" of std::to_string.
inline std::string failure_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

class SimulationFailure : public std::runtime_error {
 public:
  SimulationFailure(std::int64_t particle, std::string quantity, const std::string& detail)
      : std::runtime_error(detail), particle_(particle), quantity_(std::move(quantity)) {}
  [[nodiscard]] std::int64_t particle() const { return particle_; }
  [[nodiscard]] const std::string& quantity() const { return quantity_; }

 private:
  std::int64_t particle_;
  std::string quantity_;
};

}  // namespace cairn
