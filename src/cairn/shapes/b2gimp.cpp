// B2GIMP: quadratic B-spline grid functions integrated over each particle's initial box
// translated to the particle (seed 000 Sec. 2.1, the uGIMP form with quadratic N_i).
#include "cairn/shapes/gimp_kernel.hpp"

namespace cairn {
namespace {

template <int D>
class B2Gimp final : public ShapeFamily<D> {
 public:
  explicit B2Gimp(const ShapeContext&) {}
  int ghost_layers() const override { return 3; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    const Vec<D> h = g.cell_size();
    build_convolved<D, QuadraticGridFunction>(
        [h](const Particles<D>& parts, std::size_t q, int a) { return 0.5 * parts.size0[q][a] / h[a]; },
        g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(B2Gimp, "b2gimp",
                     "quadratic B-splines integrated over the initial particle box (seed 000 "
                     "Sec. 2.1)");
}  // namespace cairn
