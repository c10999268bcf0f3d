// Initial stresses for hyperelastic models (a point file's stress columns, docs/geometry.md).
//
// A hyperelastic model's stress is a function of the deformation gradient alone, tau = tau(F),
// so a particle can only start with a stress sigma0 if it starts deformed: initial_stretch()
// finds the symmetric stretch F0 = V (no rotation) with
//     tau(V) = det(V) sigma0          (Kirchhoff stress tau = J sigma, seed 000 Tasks 1-2)
// by Newton iterations with a finite-difference Jacobian (as materials/plane_stress.hpp does for
// F_zz), from V = I. The reference (stress-free) configuration is the one the particle would
// relax to; its volume there is V0 and it starts at J V0. Path-dependent models (state
// variables or increments: mie_gruneisen) keep their stress in their state and are refused.
//
// In 2D (planar F) sigma0 gives xx, yy, xy; V_zz = 1 in plane strain (sigma_zz follows from
// the model) and V_zz solves tau_zz = 0 in plane stress.
#pragma once

#include <optional>
#include <string>

#include "cairn/materials/material.hpp"

namespace cairn {

/// Whether `m`'s stress is tau(F) alone (no state variables, no increments).
[[nodiscard]] bool takes_initial_stress(const Material& m);

/// The stretch V with tau(V) = det(V) sigma0 (sigma0 symmetric, Cauchy); `planar`: 2D, only
/// xx, yy, xy of sigma0 are matched and V is block diagonal, with V_zz = 1 or, when
/// `plane_stress`, tau_zz = 0. std::nullopt when the iterations do not converge (a stress the
/// model cannot carry, e.g. beyond the neo-Hookean's range).
[[nodiscard]] std::optional<Mat3> initial_stretch(const Material& m, const Mat3& sigma0, bool planar,
                                                  bool plane_stress);

}  // namespace cairn
