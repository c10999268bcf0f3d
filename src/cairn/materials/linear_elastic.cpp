// Small-strain isotropic linear elasticity: eps = sym(F) - I, sigma = lambda tr(eps) I + 2 G eps,
// W = eps : sigma / 2. Meant for small deformations (the strain is not objective under rotation).
#include <cmath>

#include "cairn/materials/elastic_constants.hpp"
#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

class LinearElastic final : public Material {
 public:
  explicit LinearElastic(const MaterialConfig& cfg) : Material(cfg), c_(elastic_constants(cfg)) {}

  Mat3 cauchy(const Mat3& F) const {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    return c_.lambda * eps.trace() * Mat3::Identity() + 2.0 * c_.shear * eps;
  }
  Mat3 kirchhoff(const Mat3& F) const override { return F.determinant() * cauchy(F); }
  // The same, written as six components (eps is symmetric); planar F: J from the 2x2 block.
  void update_stress(const MaterialPoint& point, SymMat3& tau) const override {
    const Mat3& F = point.F;
    const double J = point.planar ? (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F(2, 2) : F.determinant();
    const double exx = F(0, 0) - 1.0, eyy = F(1, 1) - 1.0, ezz = F(2, 2) - 1.0;
    const double pressure_part = c_.lambda * (exx + eyy + ezz), G2 = 2.0 * c_.shear;
    auto& v = tau.voigt();  // xx, yy, zz, yz, xz, xy
    v = {J * (pressure_part + G2 * exx), J * (pressure_part + G2 * eyy), J * (pressure_part + G2 * ezz),
         J * (c_.shear * (F(1, 2) + F(2, 1))), J * (c_.shear * (F(0, 2) + F(2, 0))),
         J * (c_.shear * (F(0, 1) + F(1, 0)))};
  }
  double energy_density(const Mat3& F) const override {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    return 0.5 * eps.cwiseProduct(cauchy(F)).sum();
  }
  double wave_speed(const Mat3&) const override {
    return std::sqrt((c_.lambda + 2.0 * c_.shear) / density());
  }
  bool wave_speed_varies() const override { return false; }

 private:
  ElasticConstants c_;
};

MaterialModelInfo info() {
  return {"small-strain isotropic linear elasticity", elastic_constant_keys(), &check_elastic_constants};
}

}  // namespace
CAIRN_REGISTER_MATERIAL(LinearElastic, "linear_elastic", info());
}  // namespace cairn
