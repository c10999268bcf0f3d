// Quadratic (order 3) open-knot boundary B-splines: seed 003 Eq. 22-23, Fig. 3(a).
#include "cairn/shapes/bspline_open.hpp"

namespace cairn {
namespace {

template <int D>
class OpenQuadraticSpline final : public OpenKnotSpline<D, 2> {
 public:
  explicit OpenQuadraticSpline(const ShapeContext&) {}
};

}  // namespace
CAIRN_REGISTER_SHAPE(OpenQuadraticSpline, "bspline2_open",
                     "quadratic (order 3) B-splines on an open knot vector: boundary functions "
                     "equal 1 on the faces, no ghost nodes (seed 003 Eq. 22-23)");
}  // namespace cairn
