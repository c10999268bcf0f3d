// The stretch that carries an initial stress (initial_stress.hpp).
#include "cairn/materials/initial_stress.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace cairn {

bool takes_initial_stress(const Material& m) { return m.n_state() == 0 && !m.uses_increment(); }

std::optional<Mat3> initial_stretch(const Material& m, const Mat3& sigma0, bool planar, bool plane_stress) {
  // The unknown components of V (symmetric) and the residual components, as (row, col).
  std::vector<std::pair<int, int>> comps;
  if (planar) {
    comps = {{0, 0}, {1, 1}, {0, 1}};
    if (plane_stress) comps.push_back({2, 2});
  } else {
    comps = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  }
  const int n = static_cast<int>(comps.size());
  Mat3 target = sigma0;  // (planar: only xx, yy, xy of it are matched)
  auto residual = [&](const Mat3& V) {
    const Mat3 tau = m.kirchhoff(V);
    const double J = V.determinant();
    Eigen::VectorXd r(n);
    for (int i = 0; i < n; ++i) {
      const auto [a, b] = comps[static_cast<std::size_t>(i)];
      r[i] = tau(a, b) - (planar && a == 2 ? 0.0 : J * target(a, b));
    }
    return r;
  };
  auto set = [&](Mat3& V, int i, double value) {
    const auto [a, b] = comps[static_cast<std::size_t>(i)];
    V(a, b) = V(b, a) = value;
  };
  // Converged when the residual is round-off: of the stress, or of the stiffness times |V| ~ 1.
  Mat3 V = Mat3::Identity();
  const double scale = target.norm();
  double stiffness = 0.0;
  Eigen::VectorXd r = residual(V);
  for (int it = 0; it < 50; ++it) {
    Eigen::MatrixXd Jac(n, n);
    for (int j = 0; j < n; ++j) {  // central differences
      const auto [a, b] = comps[static_cast<std::size_t>(j)];
      const double v = V(a, b), h = 1e-6;
      Mat3 Vp = V, Vm = V;
      set(Vp, j, v + h);
      set(Vm, j, v - h);
      Jac.col(j) = (residual(Vp) - residual(Vm)) / (2.0 * h);
    }
    stiffness = std::max(stiffness, Jac.norm());
    if (r.norm() <= 1e-13 * (scale + stiffness)) break;
    const Eigen::VectorXd du = Jac.fullPivLu().solve(-r);
    if (!du.allFinite()) return std::nullopt;
    for (int j = 0; j < n; ++j) {
      const auto [a, b] = comps[static_cast<std::size_t>(j)];
      set(V, j, V(a, b) + du[j]);
    }
    if (!(V.determinant() > 0.0)) return std::nullopt;
    r = residual(V);
  }
  if (!(r.norm() <= 1e-10 * (scale + stiffness))) return std::nullopt;
  return V;
}

}  // namespace cairn
