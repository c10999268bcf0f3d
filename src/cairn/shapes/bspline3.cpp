// Cubic B-spline grid functions with ghost nodes beyond the faces (seed 003 Eq. 19 with one more
// convolution): four nodes per axis.
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct CubicSplineKernel {
  int width(const Particles<D>&) const { return 4; }
  int eval(const Particles<D>&, std::size_t, int, double xi, double* w, double* dw) const {
    return cubic_spline_weights(xi, w, dw);
  }
};

template <int D>
class CubicSpline final : public ShapeFamily<D> {
 public:
  explicit CubicSpline(const ShapeContext&) {}
  int ghost_layers() const override { return 3; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_tensor_product(CubicSplineKernel<D>{}, g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(CubicSpline, "bspline3", "cubic B-splines with ghost nodes (seed 003 Eq. 19)");
}  // namespace cairn
