// One prescribed grid velocity component, the unit of every velocity condition of
// bc/velocity_conditions (node sets and moving walls): the component of node `node` along the
// unit vector `direction` is set to `start` at the start of the step (v = m^-1 p) and to `end`
// at its end (v+ = m^-1 p+), seed 000 Sec. 2.4.
#pragma once

#include <cstdint>

#include "cairn/math/types.hpp"

namespace cairn {

template <int D>
struct PrescribedVelocity {
  std::int32_t node;
  std::int32_t owner;  ///< index of the condition or wall (VelocityConditions::names())
  Vec<D> direction;
  double start;
  double end;
};

}  // namespace cairn
