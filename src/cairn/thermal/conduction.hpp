// Explicit heat conduction on the grid, coupled both ways with particle temperatures
// (the thermal task of a coupled MPM step; seed 000 Sec. 3.5 ran nickel with it):
//
//   C_i = sum_p S_pi M_p c_p                         thermal mass of node i
//   T_i = sum_p S_pi M_p c_p T_p / C_i               grid temperature
//   grad T_p = sum_i T_i G_pi
//   Q_i = - sum_p J_p V0_p k_p grad T_p . G_pi  (+ face fluxes)
//   T_i+ = T_i + Q_i dt / C_i,   T_p <- T_p + sum_i S_pi (T_i+ - T_i)
//
// Faces: adiabatic (nothing), fixed temperature (T_i and T_i+ held on the face nodes and the
// ghost nodes beyond), or a prescribed heat flux into the body (added to Q_i of the face nodes
// with the face area of one node). Stable for dt <= h^2 / (2 D kappa_max), kappa = k / (rho c_p);
// Simulation::next_dt takes cfl times that limit into account.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"

namespace cairn {

template <int D>
class Conduction {
 public:
  Conduction(const ThermalConfig& config, const Grid<D>& grid, std::vector<double> conductivity,
             std::vector<double> heat_capacity, double thickness);

  /// The grid passed to the constructor now stores another window (a distributed run).
  void grid_changed();
  /// One explicit conduction step over the transfer cache of the current mechanical step.
  /// `share_flux` (a distributed run) gives the ghost particles their owners' heat fluxes
  /// between the gather that computes them and the scatter that reads them; `sum_nodes` (a
  /// node-halo run) completes the node sums after each scatter: (capacity, temperature), then
  /// (heat, null).
  void step(const TransferCache<D>& cache, Particles<D>& particles, double dt,
            const std::function<void(std::vector<Vec<D>>&)>& share_flux = {},
            const std::function<void(std::vector<double>&, std::vector<double>*)>& sum_nodes = {});
  /// Largest stable time step for the particles' materials (infinity when nothing conducts).
  [[nodiscard]] double stable_dt(const Particles<D>& particles, const std::vector<double>& density) const;

 private:
  ThermalConfig config_;
  const Grid<D>* grid_;
  std::vector<double> k_, cp_;  ///< per material
  std::array<double, 6> face_area_{};  ///< area one node of each face stands for
  std::vector<double> capacity_, temperature_, temperature_new_, held_, heat_;
  std::vector<Vec<D>> flux_;  ///< per particle: V k grad T
  std::vector<std::pair<std::int32_t, int>> face_nodes_;  ///< (node, face) with a condition
};

}  // namespace cairn
