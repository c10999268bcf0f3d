// Particle (material point) state stored as structure-of-arrays.
//
// Owns every per-particle quantity of a simulation. Units are whatever consistent set the
// input uses (SI in the examples). All arrays have the same length n(); index p is a particle.
#pragma once

#include <cstdint>
#include <vector>

#include "cairn/math/types.hpp"

namespace cairn {

template <int D>
struct Particles {
  std::vector<Vec<D>> position;         ///< current position x_p
  std::vector<Vec<D>> reference_position;  ///< initial (reference) position X_p, for MMS and output
  std::vector<Vec<D>> velocity;         ///< V_p
  std::vector<double> mass;             ///< M_p (constant)
  std::vector<double> volume0;          ///< initial volume V_p^(0) (x thickness in 2D)
  std::vector<Vec<D>> size0;            ///< initial particle edge lengths l_p0 (domain size)
  std::vector<Mat3> deformation_gradient;  ///< F (3x3 always)
  std::vector<Mat3> kirchhoff_stress;   ///< tau = J sigma (3x3 always)
  std::vector<Mat3> velocity_gradient;  ///< last grad V_p extrapolated from the grid (diagnostic)
  std::vector<Mat3> affine_velocity;    ///< APIC affine matrix C_p (top-left DxD used; else zero)
  std::vector<double> temperature;      ///< temperature (thermal models; 0 where unused)
  std::vector<std::int32_t> material;   ///< index into the simulation's material list
  std::vector<std::int32_t> body;       ///< index of the [[body]] the particle came from
  /// Material state variables, n_state_per_particle doubles per particle (0 for elastic laws).
  std::vector<double> state;
  int n_state_per_particle = 0;

  [[nodiscard]] std::size_t n() const { return position.size(); }

  void resize(std::size_t n) {
    position.resize(n);
    reference_position.resize(n);
    velocity.resize(n);
    mass.resize(n);
    volume0.resize(n);
    size0.resize(n);
    deformation_gradient.resize(n, Mat3::Identity());
    kirchhoff_stress.resize(n, Mat3::Zero());
    velocity_gradient.resize(n, Mat3::Zero());
    affine_velocity.resize(n, Mat3::Zero());
    temperature.resize(n, 0.0);
    material.resize(n);
    body.resize(n);
    state.resize(n * static_cast<std::size_t>(n_state_per_particle));
  }

  /// Append one particle; F = I, zero stress.
  void add(const Vec<D>& x, const Vec<D>& v, double m, double vol0, const Vec<D>& lp0,
           std::int32_t mat, std::int32_t bod) {
    position.push_back(x);
    reference_position.push_back(x);
    velocity.push_back(v);
    mass.push_back(m);
    volume0.push_back(vol0);
    size0.push_back(lp0);
    deformation_gradient.push_back(Mat3::Identity());
    kirchhoff_stress.push_back(Mat3::Zero());
    velocity_gradient.push_back(Mat3::Zero());
    affine_velocity.push_back(Mat3::Zero());
    temperature.push_back(0.0);
    material.push_back(mat);
    body.push_back(bod);
    state.resize(state.size() + static_cast<std::size_t>(n_state_per_particle), 0.0);
  }
};

}  // namespace cairn
