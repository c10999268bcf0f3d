// XPIC(k), seed 000 Sec. 2.3 (and seed 004 Eq. 36) in full-mass notation:
//     V^(n+1) = S (m~_k^-1 p + m^-1 f dt),  X^(n+1) = X + [S m^-1 p + (V^(n+1) - V^(n))/2] dt
// so A dt = S m~_k^-1 p + S a dt - V and VV = S m^-1 p. XPIC(1) is a PIC update (seed 000 Eq. 2).
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class Xpic final : public UpdateScheme<D> {
 public:
  explicit Xpic(const MethodConfig&) {}
  FullMass full_mass() const override { return FullMass::of_initial; }
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    return {g.Sv_full + (g.Sv_new - g.Sv) - g.V, g.Sv};
  }
};

}  // namespace
CAIRN_REGISTER_SCHEME(Xpic, "xpic", "XPIC(k): V = S(m~_k^-1 p + m^-1 f dt), VV = S v (seed 000 Sec. 2.3)");
}  // namespace cairn
