// CPDI: linear grid functions integrated over the convected parallelogram / parallelepiped
// domain (seed 000 Sec. 2.1, bracketed forms; Sadeghirad, Brannon & Burghardt 2011). See cpdi.hpp.
#include "cairn/shapes/cpdi.hpp"

namespace cairn {
namespace {

template <int D>
class Cpdi final : public ShapeFamily<D> {
 public:
  explicit Cpdi(const ShapeContext& ctx) : max_span_(ctx.method.plugin.real("cpdi_max_span")) {}
  int ghost_layers() const override { return 2; }
  ParticleDomain particle_domain() const override { return ParticleDomain::convected; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_cpdi<D, LinearGridFunction>(max_span_, g, p, c);
  }

 private:
  double max_span_;
};

}  // namespace
// The guard of both CPDI families (cpdi, b2cpdi).
CAIRN_DECLARE_KEYS(cpdi, {"cpdi", {"method"}, {
    Key("", "cpdi_max_span", KeyType::real,
      "CPDI/B2CPDI guard: a particle whose deformed domain spans more than this many "
      "cells along an axis uses the GIMP weights of its undeformed box for that step.")
      .by_default("2.0")
      .min(above_zero)}, {}, "smoothing_length"});
CAIRN_REGISTER_SHAPE(Cpdi, "cpdi",
                     "CPDI: linear functions interpolated over the particle domain convected by F "
                     "(seed 000 Sec. 2.1); guard method.cpdi_max_span");
}  // namespace cairn
