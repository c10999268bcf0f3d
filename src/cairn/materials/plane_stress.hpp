// Plane stress for any material: the out-of-plane stretch F_zz is the unknown that makes
// tau_zz = 0. Solved per particle by Newton iterations with a finite-difference slope, starting
// from the previous F_zz, so any model (including path-dependent ones) works unchanged.
#pragma once

#include <algorithm>
#include <cmath>

#include "cairn/materials/material.hpp"

namespace cairn {

/// Updates F(2,2) in place (F must be the object point.F refers to) and returns tau.
inline Mat3 plane_stress_update(const Material& m, Mat3& F, const MaterialPoint& point) {
  Mat3 tau = m.update(point);
  const double scale = std::max(1.0, tau.norm());
  for (int it = 0; it < 25 && std::abs(tau(2, 2)) > 1e-13 * scale; ++it) {
    const double fzz = F(2, 2), delta = 1e-7 * std::max(1.0, std::abs(fzz));
    F(2, 2) = fzz + delta;
    const double t_plus = m.update(point)(2, 2);
    const double slope = (t_plus - tau(2, 2)) / delta;
    if (slope == 0.0) break;
    F(2, 2) = fzz - tau(2, 2) / slope;
    tau = m.update(point);
  }
  return tau;
}

}  // namespace cairn
