// Standard FLIP with the second-order position update (seed 000 Task 4, seed 002 Eq. 1.58):
//     A dt = S m^-1 f dt = S (v+ - v),    VV = S m^-1 p = S v.
#include "cairn/schemes/scheme.hpp"
#include "cairn/transfer/transfer.hpp"

namespace cairn {
namespace {

template <int D>
class Flip final : public UpdateScheme<D> {
 public:
  explicit Flip(const MethodConfig&) {}
  void update_particles(StepState<D>& step) const override {
    const auto& c = step.cache;
    const auto& v = step.nodes.velocity;
    const auto& v_new = step.nodes.velocity_new;
    const double dt = step.dt;
    auto& P = step.particles;
    gather(c, [&](std::int64_t p, std::size_t begin, std::size_t end) {
      Vec<D> a_dt = Vec<D>::Zero(), vv = Vec<D>::Zero();
      for (std::size_t s = begin; s < end; ++s) {
        const std::int32_t i = c.node[s];
        a_dt += c.weight[s] * (v_new[i] - v[i]);
        vv += c.weight[s] * v[i];
      }
      P.velocity[p] += a_dt;
      P.position[p] += vv * dt + 0.5 * a_dt * dt;
    });
  }
};

}  // namespace
CAIRN_REGISTER_SCHEME(Flip, "flip", "FLIP, second-order position update (seed 000 Task 4)");
}  // namespace cairn
