// Contiguous-particle GIMP: the particle box follows the stretch of the diagonal of the
// deformation gradient, l_p = l_p0 diag(F) (seed 003 Sec. 3.3), linear grid functions, exact box
// integrals (seed 003 Eq. 29). Axis-aligned deformations keep the boxes tiling space, which is
// why the cube of seed 003 Sec. 6.3 converges at second order with it.
#include "cairn/shapes/gimp_kernel.hpp"

namespace cairn {
namespace {

template <int D>
class CpGimp final : public ShapeFamily<D> {
 public:
  explicit CpGimp(const ShapeContext&) {}
  int ghost_layers() const override { return 2; }
  ParticleDomain particle_domain() const override { return ParticleDomain::stretched; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    const Vec<D> h = g.cell_size();
    build_convolved<D, LinearGridFunction>(
        [h](const Particles<D>& parts, std::size_t q, int a) {
          return 0.5 * parts.size0[q][a] * std::abs(parts.deformation_gradient[q](a, a)) / h[a];
        },
        g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(CpGimp, "cpgimp",
                     "contiguous-particle GIMP: box l_p0 diag(F) (seed 003 Sec. 3.3)");
}  // namespace cairn
