// APIC (Jiang et al. 2015, cited in seed 000 Sec. 2.6): particles carry an affine velocity
// matrix C_p. P2G adds it to the momentum, p_i = sum_p S_pi M_p (V_p + C_p (x_i - x_p)); G2P
// takes the PIC velocity and rebuilds C_p = sum_i v+_i (x) G_pi (for quadratic B-splines this is
// B_p D_p^-1 with D_p = h^2/4 I; for linear functions it is the multilinear form of the paper).
// In the unified form it is a PIC update: A dt = S v+ - V, VV = (S v+ + V) / 2 (X += S v+ dt).
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class Apic final : public UpdateScheme<D> {
 public:
  explicit Apic(const MethodConfig&) {}
  bool affine() const override { return true; }
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    return {g.Sv_new - g.V, 0.5 * (g.Sv_new + g.V)};
  }
};

}  // namespace
CAIRN_REGISTER_SCHEME(Apic, "apic", "affine PIC: affine momentum in P2G, C = sum v+ (x) G (Jiang et al. 2015)");
}  // namespace cairn
