// Plane stress for any material: the out-of-plane stretch F_zz is the unknown that makes
// tau_zz = 0. Solved per particle by Newton iterations with a finite-difference slope, starting
// from the previous F_zz, so any model works unchanged:
//  - a path-dependent model (state variables, temperature) starts every trial from the state the
//    particle had before the step: a trial's update must not feed the next one;
//  - a model that reads the step's increment (MaterialPoint::L, dF) gets the increment the trial
//    F_zz implies, dF_zz = F_zz / F_zz(before the step), L_zz = ln(dF_zz) / dt, so that its
//    deviatoric and volumetric parts see the same out-of-plane stretch as F.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "cairn/materials/material.hpp"

namespace cairn {

/// Updates F(2,2) in place (F must be the object point.F refers to) and returns tau.
inline Mat3 plane_stress_update(const Material& m, Mat3& F, const MaterialPoint& point) {
  const double fzz_before = F(2, 2);  // the in-plane update leaves F_zz as it was
  const int n_state = point.state ? m.n_state() : 0;
  // The state before the step, restored before every trial (few models keep more than 16).
  std::array<double, 16> small{};
  std::vector<double> large;
  double* saved = small.data();
  if (n_state > static_cast<int>(small.size())) {
    large.assign(point.state, point.state + n_state);
    saved = large.data();
  } else {
    std::copy(point.state, point.state + n_state, saved);
  }
  const double temperature_before = point.temperature ? *point.temperature : 0.0;
  const bool increments = m.uses_increment();
  Mat3 L = point.L;
  Mat3 dF = point.dF ? *point.dF : Mat3::Identity();
  MaterialPoint at{F, L, point.state, point.dt, increments ? &dF : point.dF, point.tau_old, point.cell_size,
                   point.temperature, point.planar};  // refers to F and the trial increments
  auto evaluate = [&]() -> Mat3 {
    std::copy(saved, saved + n_state, point.state);
    if (point.temperature) *point.temperature = temperature_before;
    if (increments) {
      dF(2, 2) = F(2, 2) / fzz_before;
      L(2, 2) = point.dt > 0.0 && dF(2, 2) > 0.0 ? std::log(dF(2, 2)) / point.dt : 0.0;
    }
    return m.update(at);
  };
  Mat3 tau = evaluate();
  const double scale = std::max(1.0, tau.norm());
  for (int it = 0; it < 25 && std::abs(tau(2, 2)) > 1e-13 * scale; ++it) {
    const double fzz = F(2, 2), delta = 1e-7 * std::max(1.0, std::abs(fzz));
    F(2, 2) = fzz + delta;
    const double t_plus = evaluate()(2, 2);
    const double slope = (t_plus - tau(2, 2)) / delta;
    if (slope == 0.0) {
      F(2, 2) = fzz;
      tau = evaluate();
      break;
    }
    // A step may at most halve or double the stretch (a Newton step from a kink of the law, e.g.
    // the Mie-Grueneisen EOS at J = 1, must not reach F_zz <= 0).
    F(2, 2) = std::clamp(fzz - tau(2, 2) / slope, 0.5 * fzz, 2.0 * fzz);
    tau = evaluate();
  }
  return tau;
}

}  // namespace cairn
