// Standard GIMP: linear grid functions integrated over each particle's own initial box,
// l_p = l_p0 for all time (seed 003 Sec. 3.3, Eq. 26-29; seed 000 Sec. 2.1 "uGIMP").
#include "cairn/shapes/gimp_kernel.hpp"

namespace cairn {
namespace {

template <int D>
class Gimp final : public ShapeFamily<D> {
 public:
  explicit Gimp(const ShapeContext&) {}
  int ghost_layers() const override { return 2; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    const Vec<D> h = g.cell_size();
    build_convolved<D, LinearGridFunction>(
        [h](const Particles<D>& parts, std::size_t q, int a) { return 0.5 * parts.size0[q][a] / h[a]; },
        g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(Gimp, "gimp",
                     "standard GIMP: linear functions integrated over each particle's initial box "
                     "l_p0 (seed 003 Sec. 3.3)");
}  // namespace cairn
