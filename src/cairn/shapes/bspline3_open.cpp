// Cubic (order 4) open-knot boundary B-splines: seed 003 Eq. 22-23, Fig. 3(b).
#include "cairn/shapes/bspline_open.hpp"

namespace cairn {
namespace {

template <int D>
class OpenCubicSpline final : public OpenKnotSpline<D, 3> {
 public:
  explicit OpenCubicSpline(const ShapeContext&) {}
};

}  // namespace
CAIRN_REGISTER_SHAPE(OpenCubicSpline, "bspline3_open",
                     "cubic (order 4) B-splines on an open knot vector: boundary functions equal 1 "
                     "on the faces, no ghost nodes (seed 003 Eq. 22-23)");
}  // namespace cairn
