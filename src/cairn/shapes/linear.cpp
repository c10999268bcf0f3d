// Linear (tent) grid shape functions, standard MPM: seed 003 Eq. 17-18.
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct LinearKernel {
  int width(const Particles<D>&) const { return 2; }
  int eval(const Particles<D>&, std::size_t, int, double xi, double* w, double* dw) const {
    const double f = std::floor(xi);
    const double t = xi - f;  // seed 003 Eq. 17 with |x| = t and 1 - t
    w[0] = 1.0 - t;
    w[1] = t;
    dw[0] = -1.0;
    dw[1] = 1.0;
    return static_cast<int>(f);
  }
};

template <int D>
class Linear final : public ShapeFamily<D> {
 public:
  explicit Linear(const ShapeContext&) {}
  int ghost_layers() const override { return 1; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_tensor_product(LinearKernel<D>{}, g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(Linear, "linear", "piecewise-linear tent functions (seed 003 Eq. 17)");
}  // namespace cairn
