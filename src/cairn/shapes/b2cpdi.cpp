// B2CPDI: CPDI with quadratic B-spline grid functions (seed 000 Sec. 2.1). See cpdi.hpp.
#include "cairn/shapes/cpdi.hpp"

namespace cairn {
namespace {

template <int D>
class B2Cpdi final : public ShapeFamily<D> {
 public:
  explicit B2Cpdi(const ShapeContext& ctx) : max_span_(ctx.method.plugin.real("cpdi_max_span")) {}
  int ghost_layers() const override { return 3; }
  ParticleDomain particle_domain() const override { return ParticleDomain::convected; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_cpdi<D, QuadraticGridFunction>(max_span_, g, p, c);
  }

 private:
  double max_span_;
};

}  // namespace
CAIRN_REGISTER_SHAPE(B2Cpdi, "b2cpdi",
                     "CPDI with quadratic B-spline grid functions (seed 000 Sec. 2.1); guard "
                     "method.cpdi_max_span");
}  // namespace cairn
