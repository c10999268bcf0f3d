// Quadratic B-spline grid functions with ghost nodes beyond the faces: seed 003 Eq. 19-21.
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct QuadraticSplineKernel {
  int width(const Particles<D>&) const { return 3; }
  int eval(const Particles<D>&, std::size_t, int, double xi, double* w, double* dw) const {
    // Nearest node c = round(xi); d = xi - c in [-1/2, 1/2). Seed 003 Eq. 21 evaluated at the
    // three nodes c-1, c, c+1 (distances d+1, d, d-1).
    const double c = std::floor(xi + 0.5);
    const double d = xi - c;
    w[0] = 0.5 * (0.5 - d) * (0.5 - d);
    w[1] = 0.75 - d * d;
    w[2] = 0.5 * (0.5 + d) * (0.5 + d);
    dw[0] = d - 0.5;
    dw[1] = -2.0 * d;
    dw[2] = d + 0.5;
    return static_cast<int>(c) - 1;
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
