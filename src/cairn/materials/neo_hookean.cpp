// Compressible neo-Hookean hyperelasticity in the three forms the seeds use, chosen by `form`:
//
//  "ln_j"      seed 001 Eq. 31-32 = seed 003 Eq. 46:
//              W = lambda/2 (ln J)^2 - G ln J + G/2 (I1 - 3),
//              tau = lambda ln J I + G (B - I)
//  "j_squared" seed 000 Eq. 6:
//              W = lambda/2 ((J^2 - 1)/2 - ln J) + G/2 (I1 - 3 - 2 ln J),
//              tau = lambda/2 (J^2 - 1) I + G (B - I)
//  "isochoric" seed 004 Eq. 18:
//              W = G/2 (I1 / J^(2/3) - 3) + K/2 ((J^2 - 1)/2 - ln J),
//              tau = K/2 (J^2 - 1) I + G J^(-2/3) (B - I1/3 I)
//
// with B = F F^T, I1 = tr B, J = det F and tau = J sigma the Kirchhoff stress. The wave speed for
// the time step is sqrt((lambda + 3G)/rho0), seed 001 Eq. 33.
#include <cmath>

#include "cairn/materials/elastic_constants.hpp"
#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

enum class Form { ln_j, j_squared, isochoric };

Form parse_form(const MaterialConfig& cfg) {
  const auto it = cfg.strings.find("form");
  const std::string f = it == cfg.strings.end() ? "ln_j" : it->second;
  if (f == "j_squared") return Form::j_squared;
  if (f == "isochoric") return Form::isochoric;
  return Form::ln_j;
}

class NeoHookean final : public Material {
 public:
  explicit NeoHookean(const MaterialConfig& cfg)
      : Material(cfg), c_(elastic_constants(cfg)), form_(parse_form(cfg)) {}
  // bench/material_cost.py (docs/parallel.md, "Load balance").
  double relative_cost() const override { return 0.77; }

  Mat3 kirchhoff(const Mat3& F) const override {
    const double J = F.determinant();
    const Mat3 B = F * F.transpose();
    const Mat3 I = Mat3::Identity();
    switch (form_) {
      case Form::ln_j:
        return c_.lambda * std::log(J) * I + c_.shear * (B - I);
      case Form::j_squared:
        return 0.5 * c_.lambda * (J * J - 1.0) * I + c_.shear * (B - I);
      case Form::isochoric:
        return 0.5 * c_.bulk() * (J * J - 1.0) * I +
               c_.shear * std::pow(J, -2.0 / 3.0) * (B - (B.trace() / 3.0) * I);
    }
    return Mat3::Zero();
  }

  // The same stresses for a planar F (MaterialPoint::planar): B = F F^T and J = det F from the
  // 2x2 block and F_zz, six components written directly.
  void update_stress(const MaterialPoint& point, SymMat3& tau) const override {
    const Mat3& F = point.F;
    if (!point.planar) {
      tau = kirchhoff(F);
      return;
    }
    const double Fzz = F(2, 2);
    const double J = (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * Fzz;
    const double Bxx = F(0, 0) * F(0, 0) + F(0, 1) * F(0, 1), Byy = F(1, 0) * F(1, 0) + F(1, 1) * F(1, 1);
    const double Bxy = F(0, 0) * F(1, 0) + F(0, 1) * F(1, 1), Bzz = Fzz * Fzz;
    double pressure_part = 0.0, shear = c_.shear, shift = 1.0;  // tau = p I + shear (B - shift I)
    switch (form_) {
      case Form::ln_j:
        pressure_part = c_.lambda * std::log(J);
        break;
      case Form::j_squared:
        pressure_part = 0.5 * c_.lambda * (J * J - 1.0);
        break;
      case Form::isochoric:
        pressure_part = 0.5 * c_.bulk() * (J * J - 1.0);
        shear = c_.shear * std::pow(J, -2.0 / 3.0);
        shift = (Bxx + Byy + Bzz) / 3.0;
        break;
    }
    auto& v = tau.voigt();  // xx, yy, zz, yz, xz, xy
    v = {pressure_part + shear * (Bxx - shift), pressure_part + shear * (Byy - shift),
         pressure_part + shear * (Bzz - shift), 0.0, 0.0, shear * Bxy};
  }

  double energy_density(const Mat3& F) const override {
    const double J = F.determinant();
    const double lnJ = std::log(J);
    const double I1 = (F * F.transpose()).trace();
    switch (form_) {
      case Form::ln_j:
        return 0.5 * c_.lambda * lnJ * lnJ - c_.shear * lnJ + 0.5 * c_.shear * (I1 - 3.0);
      case Form::j_squared:
        return 0.5 * c_.lambda * (0.5 * (J * J - 1.0) - lnJ) + 0.5 * c_.shear * (I1 - 3.0 - 2.0 * lnJ);
      case Form::isochoric:
        return 0.5 * c_.shear * (I1 * std::pow(J, -2.0 / 3.0) - 3.0) +
               0.5 * c_.bulk() * (0.5 * (J * J - 1.0) - lnJ);
    }
    return 0.0;
  }

  double wave_speed(const Mat3&) const override {
    return std::sqrt((c_.lambda + 3.0 * c_.shear) / density());  // seed 001 Eq. 33
  }
  bool wave_speed_varies() const override { return false; }

 private:
  ElasticConstants c_;
  Form form_;
};

MaterialModelInfo info() {
  auto keys = elastic_constant_keys();
  keys.push_back(material_choice_key("form", "ln_j", {"ln_j", "j_squared", "isochoric"},
                                     "strain-energy form: ln_j (seed 001 Eq. 31), j_squared (seed 000 Eq. 6), "
                                     "isochoric (seed 004 Eq. 18)"));
  return {"compressible neo-Hookean hyperelasticity", keys, &check_elastic_constants};
}

}  // namespace
CAIRN_REGISTER_MATERIAL(NeoHookean, "neo_hookean", info());
}  // namespace cairn
