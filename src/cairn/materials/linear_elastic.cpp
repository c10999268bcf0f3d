// Isotropic linear elasticity (Hooke's law, lambda and G) in two forms, chosen by `form`:
//
//  "corotational" (default) the strain is measured in the body's own frame: with the polar
//              decomposition F = R U = V R, the Biot strain E = U - I and the strain energy
//                  W = G |U - I|^2 + lambda/2 (tr U - 3)^2,
//              so that P = dW/dF = 2G (F - R) + lambda (tr U - 3) R (the "corotated linear"
//              energy, McAdams et al. 2011) and the Kirchhoff stress tau = P F^T is
//                  tau = 2G (B - V) + lambda (tr V - 3) V,   B = F F^T = V^2,
//              which needs only the left stretch V = sqrt(B), never R. W depends on F only
//              through U, so a rigid rotation adds no stress (objective) and the model is
//              hyperelastic (the history's strain energy balances the stress power exactly).
//              For small strains tau = lambda tr(eps) I + 2G eps + O(eps^2) in the rotated
//              frame: Hooke's law for small strains and any rotation.
//  "small_strain" eps = sym(F) - I, sigma = lambda tr(eps) I + 2 G eps, W = eps : sigma / 2
//              (seed 003 Sec. 6's linear elasticity). Not objective: a rotation by theta alone
//              gives a strain of (cos theta - 1) across the rotation plane. Each material of
//              this form warns once when a particle's rotation passes kWarnAngleDeg.
//
// In 1D (uniaxial strain, F = diag(f, 1, 1), f > 0) the two forms are the same function:
// tau_xx = f (f - 1)(lambda + 2G).
//
// damping_time = beta > 0 adds a Kelvin-Voigt viscous stress proportional to the stiffness,
//     sigma_v = beta (lambda tr(D) I + 2G D),   D = sym(L),   tau_v = J sigma_v,
// so that for small strains sigma = C : (eps + beta d eps/dt) and every elastic mode of angular
// frequency omega decays at the damping ratio zeta = beta omega / 2 (Rayleigh's
// stiffness-proportional damping). Not in the seeds: Cairn's option against the friction flutter
// of verification/incline_friction_bounce (docs/materials.md, "Kelvin-Voigt damping"). Its work
// tau_v : D dt per unit reference volume is kept in the particle's one state variable and counted
// in the history's dissipated_energy; the time step shrinks with it (Simulation::next_dt).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "cairn/materials/elastic_constants.hpp"
#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

constexpr double kWarnAngleDeg = 5.0;  ///< small_strain: the rotation that triggers the warning

enum class Form { corotational, small_strain };

Form parse_form(const MaterialConfig& cfg) {
  const auto it = cfg.strings.find("form");
  return it != cfg.strings.end() && it->second == "small_strain" ? Form::small_strain : Form::corotational;
}

/// Coefficients c_k of sqrt(1 + x) - 1 = sum_(k>=1) c_k x^k and, per degree m, the largest
/// |D| for which the truncation after c_m is below round-off of E ~ D / 2:
/// |c_(m+1)| |D|^m <= 5e-18 (the terms decrease geometrically for |D| < 1).
struct SqrtSeries {
  static constexpr int max_degree = 14;
  std::array<double, max_degree + 2> c{};
  std::array<double, max_degree + 1> limit{};
  SqrtSeries() {
    c[1] = 0.5;
    for (int k = 1; k <= max_degree; ++k) c[k + 1] = c[k] * (0.5 - k) / (k + 1);
    limit[0] = 0.0;
    for (int m = 1; m <= max_degree; ++m) limit[m] = std::pow(5e-18 / std::abs(c[m + 1]), 1.0 / m);
  }
};
const SqrtSeries sqrt_series;

/// The Biot-type strain E = V - I of the left stretch V = sqrt(F F^T) (symmetric; det F > 0),
/// computed from the displacement gradient H = F - I (exact: F near I) so that it keeps the
/// precision of H however small the strain: with D = B - I = H + H^T + H H^T,
///  - planar F (block diagonal, 2x2 block): for a 2x2 SPD matrix M, sqrt(M) = (M + s I) / t with
///    s = sqrt(det M), t = sqrt(tr M + 2 s) (Cayley-Hamilton for X = sqrt M: X^2 = tr(X) X -
///    det(X) I, tr X = t, det X = s). With s = 1 + ds and t = 2 + dt, E = (D + (ds - dt) I) / t,
///    dt = 2x / (1 + sqrt(1 + x)), x = (tr D + 2 ds) / 4; E_zz = |F_zz| - 1.
///  - full F: for |D| up to 0.06 the binomial series of sqrt(I + D) - I in D; beyond, the
///    eigen-decomposition D = Q diag(d) Q^T (Eigen's closed form for symmetric 3x3 matrices) and
///    E = Q diag(d / (1 + sqrt(1 + d))) Q^T.
Mat3 stretch_strain(const Mat3& F, bool planar) {
  const Mat3 H = F - Mat3::Identity();
  if (planar) {
    const Eigen::Matrix2d h = H.topLeftCorner<2, 2>();
    const Eigen::Matrix2d D = h + h.transpose() + h * h.transpose();
    const double det_h = h(0, 0) * h(1, 1) - h(0, 1) * h(1, 0);
    const double det_f = 1.0 + h.trace() + det_h;
    const double ds = det_f > 0.0 ? h.trace() + det_h : -det_f - 1.0;  // s - 1, s = |det F_2|
    const double x = 0.25 * (D.trace() + 2.0 * ds);
    const double dt = 2.0 * x / (1.0 + std::sqrt(1.0 + x));  // t - 2
    Mat3 E = Mat3::Zero();
    E.topLeftCorner<2, 2>() = (D + (ds - dt) * Eigen::Matrix2d::Identity()) / (2.0 + dt);
    E(2, 2) = std::abs(F(2, 2)) - 1.0;
    return E;
  }
  const Mat3 D = H + H.transpose() + H * H.transpose();
  // Small D (elastic strains): the binomial series sqrt(I + D) - I = sum_k c_k D^k, c_1 = 1/2,
  // c_(k+1) = c_k (1/2 - k) / (k + 1), by Horner in D, to the degree at which the tail is below
  // round-off of E (|D|_inf bounds the spectral radius; sqrt_series below). Eight times cheaper
  // than the eigen-decomposition in problem (c) (docs/performance.md).
  const double b = D.cwiseAbs().rowwise().sum().maxCoeff();
  if (b <= sqrt_series.limit[sqrt_series.max_degree]) {
    int m = 1;
    while (b > sqrt_series.limit[m]) ++m;
    Mat3 E = sqrt_series.c[m] * D;
    for (int k = m - 1; k >= 1; --k) {
      E.diagonal().array() += sqrt_series.c[k];
      E = D * E;
    }
    return 0.5 * (E + E.transpose());  // symmetric to round-off; make it exactly so
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
  eigen.computeDirect(D);
  Eigen::Vector3d e;
  for (int i = 0; i < 3; ++i) {
    const double d = std::max(eigen.eigenvalues()[i], -1.0);
    e[i] = d / (1.0 + std::sqrt(1.0 + d));
  }
  return eigen.eigenvectors() * e.asDiagonal() * eigen.eigenvectors().transpose();
}

bool is_planar(const Mat3& F) {
  return F(0, 2) == 0.0 && F(1, 2) == 0.0 && F(2, 0) == 0.0 && F(2, 1) == 0.0;
}

class LinearElastic final : public Material {
 public:
  explicit LinearElastic(const MaterialConfig& cfg)
      : Material(cfg),
        c_(elastic_constants(cfg)),
        form_(parse_form(cfg)),
        beta_(cfg.has("damping_time") ? cfg.number("damping_time") : 0.0) {}

  int n_state() const override { return beta_ > 0.0 ? 1 : 0; }
  bool uses_increment() const override { return beta_ > 0.0; }
  double damping_time() const override { return beta_; }
  // bench/material_cost.py (docs/parallel.md, "Load balance"): small_strain skips the polar
  // decomposition.
  double relative_cost() const override { return form_ == Form::corotational ? 1.0 : 0.77; }
  double dissipated_energy_density(const double* state) const override {
    return beta_ > 0.0 && state != nullptr ? state[0] : 0.0;
  }
  std::vector<StateVariable> state_variables() const override {
    if (!(beta_ > 0.0)) return {};
    return {{"viscous_dissipation", 0, Quantity::energy, Quantity::volume,
             "work of the Kelvin-Voigt stress (damping_time) per unit reference volume"}};
  }

  /// The general update (plane stress, the FEM): the elastic stress plus the viscous stress of
  /// point.L; the dissipated work is counted only by update_stress.
  Mat3 update(const MaterialPoint& point) const override {
    Mat3 tau = kirchhoff(point.F);
    if (beta_ > 0.0) tau += viscous_kirchhoff(point);
    return tau;
  }

  Mat3 kirchhoff(const Mat3& F) const override {
    if (form_ == Form::corotational) return corotational(stretch_strain(F, is_planar(F)));
    return F.determinant() * small_strain_cauchy(F);
  }

  void update_stress(const MaterialPoint& point, SymMat3& tau) const override {
    elastic_stress(point, tau);
    if (beta_ > 0.0) {
      const Mat3 tau_v = viscous_kirchhoff(point);
      auto& v = tau.voigt();  // xx, yy, zz, yz, xz, xy
      v[0] += tau_v(0, 0);
      v[1] += tau_v(1, 1);
      v[2] += tau_v(2, 2);
      v[3] += tau_v(1, 2);
      v[4] += tau_v(0, 2);
      v[5] += tau_v(0, 1);
      // Stress power per unit reference volume tau_v : D >= 0 (K tr(D)^2 + 2G |dev D|^2).
      const Mat3 D = 0.5 * (point.L + point.L.transpose());
      point.state[0] += tau_v.cwiseProduct(D).sum() * point.dt;
    }
  }

  /// The elastic part of update_stress: the stored-energy stress of F, six components.
  void elastic_stress(const MaterialPoint& point, SymMat3& tau) const {
    const Mat3& F = point.F;
    if (form_ == Form::corotational) {
      tau = corotational(stretch_strain(F, point.planar));
      return;
    }
    watch_rotation(F);
    // Six components directly (eps is symmetric); planar F: J from the 2x2 block.
    const double J = point.planar ? (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F(2, 2) : F.determinant();
    const double exx = F(0, 0) - 1.0, eyy = F(1, 1) - 1.0, ezz = F(2, 2) - 1.0;
    const double pressure_part = c_.lambda * (exx + eyy + ezz), G2 = 2.0 * c_.shear;
    auto& v = tau.voigt();  // xx, yy, zz, yz, xz, xy
    v = {J * (pressure_part + G2 * exx), J * (pressure_part + G2 * eyy), J * (pressure_part + G2 * ezz),
         J * (c_.shear * (F(1, 2) + F(2, 1))), J * (c_.shear * (F(0, 2) + F(2, 0))),
         J * (c_.shear * (F(0, 1) + F(1, 0)))};
  }

  double energy_density(const Mat3& F) const override {
    if (form_ == Form::corotational) {
      const Mat3 E = stretch_strain(F, is_planar(F));  // V - I: the invariants of U - I
      return c_.shear * E.squaredNorm() + 0.5 * c_.lambda * E.trace() * E.trace();
    }
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    return 0.5 * eps.cwiseProduct(small_strain_cauchy(F)).sum();
  }
  double wave_speed(const Mat3&) const override {
    return std::sqrt((c_.lambda + 2.0 * c_.shear) / density());
  }
  bool wave_speed_varies() const override { return false; }

  std::vector<std::string> take_notes() const override {
    int seen = 1;
    if (!warned_.compare_exchange_strong(seen, 2)) return {};
    return {"warning: material '" + name() + "' (linear_elastic, form = \"small_strain\"): a particle turned by more than " +
            std::to_string(static_cast<int>(kWarnAngleDeg)) +
            " degrees; the small-strain form reads a rotation as strain (a turn by theta gives a strain of "
            "cos(theta) - 1 and the matching stress). Use form = \"corotational\" (the default) for bodies "
            "that turn (docs/materials.md)."};
  }

 private:
  /// tau_v = J beta (lambda tr(D) I + 2G D) with D = sym(point.L).
  Mat3 viscous_kirchhoff(const MaterialPoint& point) const {
    const Mat3 D = 0.5 * (point.L + point.L.transpose());
    const Mat3& F = point.F;
    const double J = point.planar ? (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F(2, 2) : F.determinant();
    Mat3 tau_v = (J * beta_ * 2.0 * c_.shear) * D;
    tau_v.diagonal().array() += J * beta_ * c_.lambda * D.trace();
    return tau_v;
  }
  /// tau = 2G (B - V) + lambda (tr V - 3) V = 2G (E + E^2) + lambda tr(E) (I + E), E = V - I.
  Mat3 corotational(const Mat3& E) const {
    const double trE = E.trace();
    Mat3 tau = 2.0 * c_.shear * (E + E * E) + c_.lambda * trE * E;
    tau.diagonal().array() += c_.lambda * trE;
    return tau;
  }
  Mat3 small_strain_cauchy(const Mat3& F) const {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    return c_.lambda * eps.trace() * Mat3::Identity() + 2.0 * c_.shear * eps;
  }
  /// Flags (once) a rotation beyond kWarnAngleDeg, estimated from the skew part of F: for
  /// F = R U with U near I, |axial(F - F^T)| / 2 = sin(theta).
  void watch_rotation(const Mat3& F) const {
    if (warned_.load(std::memory_order_relaxed) != 0) return;
    const double wx = F(2, 1) - F(1, 2), wy = F(0, 2) - F(2, 0), wz = F(1, 0) - F(0, 1);
    static const double limit = 2.0 * std::sin(kWarnAngleDeg * std::numbers::pi / 180.0);
    if (wx * wx + wy * wy + wz * wz > limit * limit) {
      int none = 0;
      warned_.compare_exchange_strong(none, 1);
    }
  }

  ElasticConstants c_;
  Form form_;
  double beta_;  ///< damping_time: Kelvin-Voigt retardation time (0: elastic)
  mutable std::atomic<int> warned_{0};  ///< 0: no, 1: seen, not yet said, 2: said
};

MaterialModelInfo info() {
  auto keys = elastic_constant_keys();
  keys.push_back(material_choice_key(
      "form", "corotational", {"corotational", "small_strain"},
      "corotational: Hooke's law on the Biot strain U - I of F = R U (objective, any rotation); "
      "small_strain: eps = sym(F) - I (seed 003 Sec. 6; not objective, warns past 5 degrees of rotation)"));
  KeyDecl damping;
  damping.section = "material";
  damping.name = "damping_time";
  damping.type = KeyType::real;
  damping.default_value = "0.0";
  damping.min = 0.0;
  damping.doc =
      "Kelvin-Voigt retardation time beta (s): adds the viscous stress beta (lambda tr(D) I + 2G D), "
      "which damps every elastic mode at zeta = beta omega / 2; its work goes to dissipated_energy and "
      "the time step shrinks by sqrt(1 + zeta^2) - zeta, zeta = beta c / h. 0 = elastic (seed behaviour). "
      "Not in plane stress (docs/materials.md, \"Kelvin-Voigt damping\")";
  keys.push_back(damping);
  return {"isotropic linear elasticity (corotational or small-strain), optional Kelvin-Voigt damping", keys,
          &check_elastic_constants};
}

}  // namespace
CAIRN_REGISTER_MATERIAL(LinearElastic, "linear_elastic", info());
}  // namespace cairn
