// FMPM(k), seed 000 Table 1 and Task 4: grid velocities from the k-term full mass matrix
// inverse, v+ = m~_k^-1 p+, then
//     A dt = S v+ - V,    VV = V,
// and the velocity gradient of the stress update also uses v+ (Task 5). FMPM(1) is a PIC
// update (seed 000 Eq. 2).
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class Fmpm final : public UpdateScheme<D> {
 public:
  explicit Fmpm(const MethodConfig&) {}
  FullMass full_mass() const override { return FullMass::of_updated; }
  Effective<D> effective(const GridAtParticle<D>& g) const override { return {g.Sv_full - g.V, g.V}; }
};

}  // namespace
CAIRN_REGISTER_SCHEME(Fmpm, "fmpm", "FMPM(k): V = S m~_k^-1 p+, VV = V (seed 000 Task 4)");
}  // namespace cairn
