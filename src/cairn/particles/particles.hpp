// Particle (material point) state stored as structure-of-arrays.
//
// Owns every per-particle quantity of a simulation. Units are whatever consistent set the
// input uses (SI in the examples). All arrays have the same length n(); index p is a particle.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "cairn/math/sym_mat3.hpp"
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
  std::vector<SymMat3> kirchhoff_stress;  ///< tau = J sigma (symmetric, six components)
  /// APIC affine matrix C_p (top-left DxD used); stored only when has_affine, else empty.
  std::vector<Mat3> affine_velocity;
  std::vector<double> temperature;      ///< temperature; stored only when has_temperature
  std::vector<std::int32_t> material;   ///< index into the simulation's material list
  std::vector<std::int32_t> body;       ///< index of the [[body]] the particle came from
  /// Particle number in creation order, kept for the particle's life: it names the particle in
  /// messages and outputs of every rank count, and a distributed run adds each node's
  /// contributions in increasing id, as a serial run does (docs/parallel.md).
  std::vector<std::int64_t> id;
  /// Material state variables, n_state_per_particle doubles per particle (0 for elastic laws).
  std::vector<double> state;
  int n_state_per_particle = 0;
  /// Whether affine_velocity is stored (the simulation sets it from its scheme before adding
  /// particles; schemes without an affine part leave the 72 bytes per particle unallocated).
  bool has_affine = true;
  /// Whether temperature is stored (thermal models, conduction); the simulation sets it like
  /// has_affine. Without it the array stays empty and temperatures read as 0.
  bool has_temperature = true;

  [[nodiscard]] std::size_t n() const { return position.size(); }

  /// fn(array, width) for every per-particle array: `width` entries per particle (0 for an
  /// array that is not stored). Migration between ranks, ghost copies, reordering and restarts
  /// go through this one list, so an array added to the struct must be added here (a unit test
  /// compares the list with the struct's size).
  template <class Fn>
  void for_each_array(Fn&& fn) {
    fn(position, 1);
    fn(reference_position, 1);
    fn(velocity, 1);
    fn(mass, 1);
    fn(volume0, 1);
    fn(size0, 1);
    fn(deformation_gradient, 1);
    fn(kirchhoff_stress, 1);
    fn(affine_velocity, has_affine ? 1 : 0);
    fn(temperature, has_temperature ? 1 : 0);
    fn(material, 1);
    fn(body, 1);
    fn(id, 1);
    fn(state, n_state_per_particle);
  }
  template <class Fn>
  void for_each_array(Fn&& fn) const {
    const_cast<Particles*>(this)->for_each_array([&](auto& array, int width) { fn(std::as_const(array), width); });
  }
  /// Number of per-particle arrays for_each_array visits.
  static constexpr int n_arrays = 14;

  void resize(std::size_t n) {
    position.resize(n);
    reference_position.resize(n);
    velocity.resize(n);
    mass.resize(n);
    volume0.resize(n);
    size0.resize(n);
    deformation_gradient.resize(n, Mat3::Identity());
    kirchhoff_stress.resize(n);
    affine_velocity.resize(has_affine ? n : 0, Mat3::Zero());
    temperature.resize(has_temperature ? n : 0, 0.0);
    material.resize(n);
    body.resize(n);
    const std::size_t numbered = id.size();
    id.resize(n);
    for (std::size_t p = numbered; p < n; ++p) id[p] = static_cast<std::int64_t>(p);
    state.resize(n * static_cast<std::size_t>(n_state_per_particle));
  }

  /// Room for n particles in every array (particles made in a loop whose count is known).
  void reserve(std::size_t n) {
    for_each_array([n](auto& array, int width) { array.reserve(n * static_cast<std::size_t>(width)); });
  }

  /// Release the spare capacity that adding particles one by one leaves (up to half the arrays).
  void shrink_to_fit() {
    for_each_array([](auto& array, int) { array.shrink_to_fit(); });
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
    kirchhoff_stress.emplace_back();
    if (has_affine) affine_velocity.push_back(Mat3::Zero());
    if (has_temperature) temperature.push_back(0.0);
    material.push_back(mat);
    body.push_back(bod);
    id.push_back(static_cast<std::int64_t>(id.size()));
    state.resize(state.size() + static_cast<std::size_t>(n_state_per_particle), 0.0);
  }
};

}  // namespace cairn
