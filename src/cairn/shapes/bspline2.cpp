// Quadratic B-spline grid functions with ghost nodes beyond the faces: seed 003 Eq. 19-21.
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct QuadraticSplineKernel {
  int width(const Particles<D>&) const { return 3; }
  int eval(const Particles<D>&, std::size_t, int, double xi, double* w, double* dw) const {
    return quadratic_spline_weights(xi, w, dw);
  }
};

template <int D>
class QuadraticSpline final : public ShapeFamily<D> {
 public:
  explicit QuadraticSpline(const ShapeContext&) {}
  int ghost_layers() const override { return 2; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_tensor_product(QuadraticSplineKernel<D>{}, g, p, c);
  }
};

}  // namespace
CAIRN_REGISTER_SHAPE(QuadraticSpline, "bspline2",
                     "quadratic B-splines on the uniform grid with ghost nodes (seed 003 Eq. 21)");
}  // namespace cairn
