// FLIP updates (P = I, seed 002 Sec. 1.4.2):
//  flip       A dt = S a dt, VV = S v: standard FLIP, second-order position update (seed 000
//             Task 4, seed 002 Eq. 1.58 first form)
//  flip1      A dt = S a dt, VV = S v + 1/2 S a dt: "modified FLIP #1", X += S v~ dt
//             (seed 002 Eq. 1.60-1.62; seed 003 Eq. 9-10)
//  flip2      A dt = S a dt, VV = V + 1/2 S a dt: "modified FLIP #2", X += V^(n+1) dt
//             (seed 002 Eq. 1.63-1.65)
//  flip_vv    A dt = S a dt, VV = V: midpoint update with the particle velocity (seed 002
//             Sec. 1.3.1, Eq. 1.58 second form) -- known to be poor, kept for comparison
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class Flip final : public UpdateScheme<D> {
 public:
  explicit Flip(const MethodConfig&) {}
  Effective<D> effective(const GridAtParticle<D>& g) const override { return {g.Sv_new - g.Sv, g.Sv}; }
};

template <int D>
class FlipFirstOrder final : public UpdateScheme<D> {
 public:
  explicit FlipFirstOrder(const MethodConfig&) {}
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    const Vec<D> a_dt = g.Sv_new - g.Sv;
    return {a_dt, g.Sv + 0.5 * a_dt};
  }
};

template <int D>
class FlipParticleEnd final : public UpdateScheme<D> {
 public:
  explicit FlipParticleEnd(const MethodConfig&) {}
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    const Vec<D> a_dt = g.Sv_new - g.Sv;
    return {a_dt, g.V + 0.5 * a_dt};
  }
};

template <int D>
class FlipParticleVelocity final : public UpdateScheme<D> {
 public:
  explicit FlipParticleVelocity(const MethodConfig&) {}
  Effective<D> effective(const GridAtParticle<D>& g) const override { return {g.Sv_new - g.Sv, g.V}; }
};

}  // namespace
CAIRN_REGISTER_SCHEME(Flip, "flip", "FLIP, VV = S v, second-order position update (seed 000 Task 4)");
CAIRN_REGISTER_SCHEME(FlipFirstOrder, "flip1", "FLIP with X += S v+ dt (seed 002 Eq. 1.60-1.61)");
CAIRN_REGISTER_SCHEME(FlipParticleEnd, "flip2", "FLIP with X += V(n+1) dt (seed 002 Eq. 1.63-1.64)");
CAIRN_REGISTER_SCHEME(FlipParticleVelocity, "flip_vv", "FLIP with VV = V (seed 002 Sec. 1.3.1)");
}  // namespace cairn
