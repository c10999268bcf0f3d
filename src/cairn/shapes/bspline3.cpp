// Cubic B-spline grid functions with ghost nodes beyond the faces (seed 003 Eq. 19 with one more
// convolution): four nodes per axis.
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct CubicSplineKernel {
  int width(const Particles<D>&) const { return 4; }
  int eval(const Particles<D>&, std::size_t, int, double xi, double* w, double* dw) const {
    const double f = std::floor(xi);
    const double t = xi - f;  // nodes f-1, f, f+1, f+2
    const double u = 1.0 - t;
    w[0] = u * u * u / 6.0;
    w[1] = (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0;
    w[2] = (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0;
    w[3] = t * t * t / 6.0;
    dw[0] = -0.5 * u * u;
    dw[1] = (9.0 * t * t - 12.0 * t) / 6.0;
    dw[2] = (-9.0 * t * t + 6.0 * t + 3.0) / 6.0;
    dw[3] = 0.5 * t * t;
    return static_cast<int>(f) - 1;
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
