// Hyperelastic-plastic material with a Mie-Grueneisen equation of state, artificial viscosity
// and adiabatic heating (seed 004 Eq. 18, 51, 52; seed 000 Sec. 3.5).
//
// Kirchhoff stress  tau = s - J (p + q) I  with
//  * deviatoric part s = G dev(b_e) from the neo-Hookean shear term of seed 004 Eq. 18, where
//    b_e is the isochoric elastic left Cauchy-Green tensor. J2 plasticity by radial return in the
//    hyperelastic setting (Simo's multiplicative algorithm): trial b_e = f b_e f^T with the
//    isochoric increment f = det(dF)^(-1/3) dF; if |s_trial| > sqrt(2/3) sigma_y(alpha), return
//    to the yield surface with the shear modulus scaled by tr(b_e)/3. Hardening: linear
//    sigma_y = sigma_y0 + H alpha, or power law sigma_y = sigma_y0 (1 + alpha / eps0)^n.
//  * pressure from seed 004 Eq. 51 with eta = 1 - J (positive in compression). Sign convention:
//    the printed Eq. 51 puts the Hugoniot branch at eta < 0; with eta = 1 - J that is tension,
//    which contradicts the reference Hugoniot it comes from, so Cairn uses the Hugoniot branch in
//    compression, where it gives positive pressure (tested):
//        p = K eta (1 - gamma0 eta / 2) / (1 - S1 eta)^2 + rho0 gamma0 U      eta > 0
//        p = K eta                                                             eta <= 0
//    With the Rankine-Hugoniot energy jump U = p eta / (2 rho0) this reduces to the reference
//    Hugoniot p_H = K eta / (1 - S1 eta)^2, U_s = C0 + S1 u_p, C0 = sqrt(K / rho0).
//  * artificial viscosity seed 004 Eq. 52 in compression only (D_kk < 0):
//        q = rho dx |D_kk| (A1 C + A2 dx |D_kk|),  rho = rho0 / J, C = current bulk wave speed,
//        C^2 = dp/drho = J dp/deta / rho along the reference Hugoniot (tested).
// Internal energy per unit mass U is integrated with the trapezoidal rule from the stress power,
// dU = (tau_old + tau_new) : D dt / (2 rho0), so it includes plastic and viscous work; the EOS uses
// the predictor U + tau_old : D dt / rho0. Temperature: dT = -gamma0 J T tr(D) dt (Grueneisen
// heating, Gamma rho = gamma0 rho0) + (plastic + viscous work) / (rho0 c_v).
//
// State per particle: U, alpha (equivalent plastic strain), b_e (6 components), d alpha / dt of
// the last step (output only).
#include <cmath>

#include "cairn/materials/elastic_constants.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/math/tensor.hpp"

namespace cairn {
namespace {

enum State { U_ = 0, ALPHA = 1, BE = 2, ALPHA_RATE = 8, N_STATE = 9 };

Mat3 load_be(const double* s) {
  Mat3 b;
  b << s[BE + 0], s[BE + 3], s[BE + 4], s[BE + 3], s[BE + 1], s[BE + 5], s[BE + 4], s[BE + 5], s[BE + 2];
  return b;
}
void store_be(double* s, const Mat3& b) {
  s[BE + 0] = b(0, 0);
  s[BE + 1] = b(1, 1);
  s[BE + 2] = b(2, 2);
  s[BE + 3] = b(0, 1);
  s[BE + 4] = b(0, 2);
  s[BE + 5] = b(1, 2);
}

class MieGruneisen final : public Material {
 public:
  explicit MieGruneisen(const MaterialConfig& c)
      : Material(c),
        K_(c.number("bulk_modulus")),
        G_(c.number("shear_modulus")),
        gamma0_(c.number("gamma0")),
        S1_(c.number("s1")),
        yield_(c.number("yield_stress")),
        H_(c.number("hardening_modulus")),
        power_(c.strings.count("hardening") && c.strings.at("hardening") == "power"),
        n_(c.number("hardening_exponent")),
        eps0_(c.number("hardening_strain")),
        A1_(c.number("av_a1")),
        A2_(c.number("av_a2")),
        cv_(c.number("heat_capacity")),
        T0_(c.number("initial_temperature")) {}

  int n_state() const override { return N_STATE; }
  void initialize_state(double* s) const override {
    for (int k = 0; k < N_STATE; ++k) s[k] = 0.0;
    store_be(s, Mat3::Identity());
  }
  std::vector<StateVariable> state_variables() const override {
    return {{"equivalent_plastic_strain", ALPHA, Quantity::dimensionless, Quantity::dimensionless,
             "equivalent plastic strain alpha (J2 radial return)"},
            {"plastic_strain_rate", ALPHA_RATE, Quantity::dimensionless, Quantity::time,
             "d alpha / dt over the last step"},
            {"internal_energy", U_, Quantity::energy, Quantity::mass,
             "internal energy per unit mass U (Mie-Grueneisen equation of state)"}};
  }
  double initial_temperature() const override { return T0_; }
  bool uses_temperature() const override { return true; }
  // bench/material_cost.py (docs/parallel.md, "Load balance"): with plasticity, the yielding
  // particles' radial return.
  double relative_cost() const override { return yield_ > 0.0 ? 1.31 : 1.16; }

  /// Pressure from the EOS (Eq. 51, compression branch for eta > 0).
  double pressure(double J, double U) const {
    const double eta = 1.0 - J;
    if (eta <= 0.0) return K_ * eta;
    const double d = 1.0 - S1_ * eta;
    return K_ * eta * (1.0 - 0.5 * gamma0_ * eta) / (d * d) + density() * gamma0_ * U;
  }
  /// Current bulk modulus rho dp/drho = J dp/deta along the reference Hugoniot (p = K eta in
  /// tension): the "current bulk wave speed" of seed 004 Eq. 52 is sqrt(of this / rho).
  double bulk_tangent(double J) const {
    const double eta = 1.0 - J;
    if (eta <= 0.0) return J * K_;
    const double d = 1.0 - S1_ * eta;
    return J * K_ * (1.0 + S1_ * eta) / (d * d * d);
  }
  double yield_stress(double alpha) const {
    return power_ ? yield_ * std::pow(1.0 + alpha / eps0_, n_) : yield_ + H_ * alpha;
  }
  double yield_slope(double alpha) const {
    return power_ ? yield_ * n_ / eps0_ * std::pow(1.0 + alpha / eps0_, n_ - 1.0) : H_;
  }

  Mat3 kirchhoff(const Mat3& F) const override {
    // Elastic response with U = 0 (no history): shear from the isochoric b of F.
    const double J = F.determinant();
    const Mat3 b = std::pow(J, -2.0 / 3.0) * F * F.transpose();
    const Mat3 s = G_ * (b - b.trace() / 3.0 * Mat3::Identity());
    return s - J * pressure(J, 0.0) * Mat3::Identity();
  }
  double energy_density(const Mat3& F) const override {
    const double J = F.determinant();
    const double I1 = std::pow(J, -2.0 / 3.0) * (F * F.transpose()).trace();
    const double eta = 1.0 - J;
    return 0.5 * G_ * (I1 - 3.0) + 0.5 * K_ * eta * eta;  // cold-curve estimate, for reference
  }
  double internal_energy_density(const Mat3&, const double* state) const override {
    return density() * state[U_];
  }
  double wave_speed(const Mat3& F) const override {
    const double J = F.determinant();
    return std::sqrt((bulk_tangent(J) + 4.0 * G_ / 3.0) * J / density());
  }

  bool uses_increment() const override { return true; }
  Mat3 update(const MaterialPoint& pt) const override {
    double* st = pt.state;
    const Mat3 dF = pt.dF ? *pt.dF : tensor_exp(pt.L * pt.dt);
    const double J = pt.F.determinant();
    const Mat3 I = Mat3::Identity();
    // Deviatoric part: trial elastic state and radial return.
    const Mat3 f = std::pow(dF.determinant(), -1.0 / 3.0) * dF;
    Mat3 be = f * load_be(st) * f.transpose();
    const double Ibar = be.trace() / 3.0;
    Mat3 s = G_ * (be - Ibar * I);
    double plastic_work = 0.0;  // per unit reference volume
    const double alpha = st[ALPHA];
    if (yield_ > 0.0) {
      const double norm = s.norm();
      const double Gbar = G_ * Ibar;
      if (norm > std::sqrt(2.0 / 3.0) * yield_stress(alpha)) {
        double dg = 0.0;
        for (int it = 0; it < 30; ++it) {
          const double a = alpha + std::sqrt(2.0 / 3.0) * dg;
          const double r = norm - 2.0 * Gbar * dg - std::sqrt(2.0 / 3.0) * yield_stress(a);
          const double dr = -2.0 * Gbar - (2.0 / 3.0) * yield_slope(a);
          const double step = r / dr;
          dg -= step;
          if (std::abs(step) <= 1e-14 * (1.0 + std::abs(dg))) break;
        }
        dg = std::max(0.0, dg);
        const Mat3 n = s / norm;
        s -= 2.0 * Gbar * dg * n;
        st[ALPHA] = alpha + std::sqrt(2.0 / 3.0) * dg;
        be = s / G_ + Ibar * I;
        plastic_work = std::sqrt(2.0 / 3.0) * yield_stress(st[ALPHA]) * dg;  // |s| dgamma
      }
    }
    st[ALPHA_RATE] = pt.dt > 0.0 ? (st[ALPHA] - alpha) / pt.dt : 0.0;
    store_be(st, be);
    // Pressure with the predicted internal energy, plus artificial viscosity.
    const Mat3 D = 0.5 * (pt.L + pt.L.transpose());
    const double Dkk = D.trace();
    const double rho0 = density();
    const Mat3 tau_old = pt.tau_old ? pt.tau_old->full() : Mat3::Zero();
    const double U_pred = st[U_] + tau_old.cwiseProduct(D).sum() * pt.dt / rho0;
    double q = 0.0;
    if (Dkk < 0.0 && (A1_ > 0.0 || A2_ > 0.0)) {
      const double rho = rho0 / J;
      const double C = std::sqrt(bulk_tangent(J) / rho);
      const double dx = pt.cell_size;
      q = rho * dx * std::abs(Dkk) * (A1_ * C + A2_ * dx * std::abs(Dkk));  // seed 004 Eq. 52
    }
    const Mat3 tau = s - J * (pressure(J, U_pred) + q) * I;
    st[U_] += 0.5 * (tau_old + tau).cwiseProduct(D).sum() * pt.dt / rho0;
    if (pt.temperature) {
      double& T = *pt.temperature;
      const double viscous_work = J * q * std::abs(Dkk) * pt.dt;  // per unit reference volume
      T += -gamma0_ * J * T * Dkk * pt.dt;
      if (cv_ > 0.0) T += (plastic_work + viscous_work) / (rho0 * cv_);
    }
    return tau;
  }

 private:
  double K_, G_, gamma0_, S1_, yield_, H_;
  bool power_;
  double n_, eps0_, A1_, A2_, cv_, T0_;
};

KeyDecl key(std::string name, std::string doc, std::string def = "", double min = 0.0) {
  KeyDecl k;
  k.section = "material";
  k.name = std::move(name);
  k.type = KeyType::real;
  k.default_value = std::move(def);
  k.required = k.default_value.empty();
  k.min = min;
  k.doc = std::move(doc);
  return k;
}

MaterialModelInfo info() {
  std::vector<KeyDecl> keys = {
      key("bulk_modulus", "bulk modulus K of the EOS (seed 004 Eq. 51)"),
      key("shear_modulus", "shear modulus G of the neo-Hookean shear term (seed 004 Eq. 18)"),
      key("gamma0", "Grueneisen parameter gamma0"),
      key("s1", "slope S1 of the shock-speed / particle-speed line"),
      key("yield_stress", "initial yield stress sigma_y0; 0 = no plasticity", "0.0"),
      key("hardening_modulus", "linear hardening modulus H", "0.0"),
      key("hardening_exponent", "power-law hardening exponent n", "0.0"),
      key("hardening_strain", "power-law reference strain eps0", "1.0"),
      key("av_a1", "artificial viscosity A1 (seed 004 Eq. 52)", "0.0"),
      key("av_a2", "artificial viscosity A2 (seed 004 Eq. 52)", "0.0"),
      key("initial_temperature", "initial temperature of the particles", "298.15"),
  };
  keys.push_back(material_choice_key("hardening", "linear", {"linear", "power"},
                                     "hardening law: linear (sigma_y0 + H alpha) or power (sigma_y0 (1 + "
                                     "alpha/eps0)^n)"));
  return {"Mie-Grueneisen EOS with neo-Hookean shear, J2 plasticity, artificial viscosity and "
          "heating (seed 004 Eq. 18, 51, 52)",
          keys, nullptr};
}

}  // namespace
CAIRN_REGISTER_MATERIAL(MieGruneisen, "mie_gruneisen", info());
}  // namespace cairn
