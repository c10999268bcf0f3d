#include "cairn/thermal/conduction.hpp"

#include <limits>

#include "cairn/transfer/transfer.hpp"

namespace cairn {

template <int D>
Conduction<D>::Conduction(const ThermalConfig& config, const Grid<D>& grid,
                          std::vector<double> conductivity, std::vector<double> heat_capacity,
                          double thickness)
    : config_(config), grid_(&grid), k_(std::move(conductivity)), cp_(std::move(heat_capacity)) {
  for (int f = 0; f < 2 * D; ++f) {
    face_area_[f] = D == 3 ? 1.0 : thickness;  // 2D: per unit thickness; 1D: cross-section
    for (int b = 0; b < D; ++b)
      if (b != f / 2) face_area_[f] *= grid.cell_size()[b];
  }
  grid_changed();
}

template <int D>
void Conduction<D>::grid_changed() {
  const Grid<D>& grid = *grid_;
  const auto n = grid.n_nodes();
  capacity_.assign(n, 0.0);
  temperature_.assign(n, 0.0);
  temperature_new_.assign(n, 0.0);
  held_.assign(n, 0.0);
  heat_.assign(n, 0.0);
  flux_.assign(0, Vec<D>::Zero());
  face_nodes_.clear();
  for (std::int32_t i = 0; i < n; ++i) {
    const IVec<D> j = grid.multi_index(i);
    for (int f = 0; f < 2 * D; ++f) {
      if (config_.face[f] == ThermalFace::adiabatic) continue;
      const int a = f / 2;
      const bool on = f % 2 == 0 ? j[a] == 0 : j[a] == grid.n_cells()[a];
      const bool beyond = f % 2 == 0 ? j[a] < 0 : j[a] > grid.n_cells()[a];
      if (on || (beyond && config_.face[f] == ThermalFace::temperature)) face_nodes_.emplace_back(i, f);
    }
  }
}

template <int D>
double Conduction<D>::stable_dt(const Particles<D>& particles, const std::vector<double>& density) const {
  double kappa = 0.0;
  for (std::size_t m = 0; m < k_.size(); ++m)
    if (cp_[m] > 0.0) kappa = std::max(kappa, k_[m] / (density[m] * cp_[m]));
  (void)particles;
  if (kappa <= 0.0) return std::numeric_limits<double>::infinity();
  const double h = grid_->min_cell_size();
  return h * h / (2.0 * D * kappa);
}

template <int D>
void Conduction<D>::step(const TransferCache<D>& cache, Particles<D>& P, double dt,
                         const std::function<void(std::vector<Vec<D>>&)>& share_flux,
                         const std::function<void(std::vector<double>&, std::vector<double>*)>& sum_nodes) {
  const auto n = grid_->n_nodes();
  for_each_node(n, [&](std::int32_t i) {
    capacity_[i] = 0.0;
    temperature_[i] = 0.0;
    heat_[i] = 0.0;
  });
  scatter(cache, [&](std::int32_t p, const auto& stencil) {
    stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
      const double c = S * P.mass[p] * cp_[P.material[p]];
      capacity_[node] += c;
      temperature_[node] += c * P.temperature[p];
    });
  });
  if (sum_nodes) sum_nodes(capacity_, &temperature_);
  for_each_node(n, [&](std::int32_t i) {
    temperature_[i] = capacity_[i] > 0.0 ? temperature_[i] / capacity_[i] : 0.0;
  });
  // Held temperatures: the gradient and the update start from them, while the particle update
  // measures the change from the extrapolated value, so the jump to a held value reaches the
  // particles (the thermal analogue of seed 003 Eq. 30).
  for_each_node(n, [&](std::int32_t i) { held_[i] = temperature_[i]; });
  for (const auto& [i, f] : face_nodes_)
    if (config_.face[f] == ThermalFace::temperature) held_[i] = config_.value[f];
  // Heat flow into the nodes from the particles' temperature gradients: V k grad T_p first,
  // then Q_i = -sum_p (V k grad T_p) . G_pi.
  if (flux_.size() != P.n()) flux_.assign(P.n(), Vec<D>::Zero());
  gather(cache, [&](std::int64_t p, const auto& stencil) {
    Vec<D> grad = Vec<D>::Zero();
    stencil.for_each([&](std::int32_t node, double, const Vec<D>& G) { grad += held_[node] * G; });
    flux_[p] = P.deformation_gradient[p].determinant() * P.volume0[p] * k_[P.material[p]] * grad;
  });
  if (share_flux) share_flux(flux_);
  scatter(cache, [&](std::int32_t p, const auto& stencil) {
    stencil.for_each([&](std::int32_t node, double, const Vec<D>& G) { heat_[node] -= flux_[p].dot(G); });
  });
  if (sum_nodes) sum_nodes(heat_, nullptr);
  for (const auto& [i, f] : face_nodes_)
    if (config_.face[f] == ThermalFace::flux && capacity_[i] > 0.0) heat_[i] += config_.value[f] * face_area_[f];
  for_each_node(n, [&](std::int32_t i) {
    temperature_new_[i] = capacity_[i] > 0.0 ? held_[i] + heat_[i] * dt / capacity_[i] : 0.0;
  });
  for (const auto& [i, f] : face_nodes_)
    if (config_.face[f] == ThermalFace::temperature) temperature_new_[i] = config_.value[f];
  gather(cache, [&](std::int64_t p, const auto& stencil) {
    if (cp_[P.material[p]] <= 0.0) return;
    double dT = 0.0;
    stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
      dT += S * (temperature_new_[node] - temperature_[node]);
    });
    P.temperature[p] += dT;
  });
}

template class Conduction<1>;
template class Conduction<2>;
template class Conduction<3>;

}  // namespace cairn
