// Small fixed-size vector and tensor types used throughout Cairn.
//
// Positions, velocities and gradients live in the simulation dimension D (1, 2 or 3).
// Deformation gradients and stresses are always 3x3: plane strain keeps F_zz = 1, plane stress
// solves for F_zz, and 1D is uniaxial strain along x.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

namespace cairn {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;
template <int D>
using IVec = Eigen::Matrix<int, D, 1>;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Embed a D-vector in 3D (missing components zero).
template <int D>
inline Vec3 to3(const Vec<D>& v) {
  Vec3 out = Vec3::Zero();
  out.template head<D>() = v;
  return out;
}

/// Kinematic assumption for the out-of-plane directions.
enum class Mode : std::uint8_t { uniaxial_strain_1d, plane_strain, plane_stress, three_d };

}  // namespace cairn
