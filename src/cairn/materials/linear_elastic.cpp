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
