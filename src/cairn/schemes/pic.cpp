// The three PIC updates of seed 000 Eq. 2. All replace the particle velocity by the lumped grid
// velocity, A dt = S m^-1 p+ - V, and differ only in the effective velocity (the position update):
//  pic      "MPM PIC": VV = (V^(n+1) + V^(n)) / 2, i.e. X += S v+ dt (first order)
//  xpic     with method.order = 1 is XPIC(1): VV = S m^-1 p (see xpic.cpp)
//  fmpm     with method.order = 1 is FMPM(1): VV = V (see fmpm.cpp)
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class MpmPic final : public UpdateScheme<D> {
 public:
  explicit MpmPic(const MethodConfig&) {}
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    return {g.Sv_new - g.V, 0.5 * (g.Sv_new + g.V)};
  }
};

}  // namespace
CAIRN_REGISTER_SCHEME(MpmPic, "pic", "MPM PIC: V = S v+, X += S v+ dt (seed 000 Eq. 2)");
}  // namespace cairn
