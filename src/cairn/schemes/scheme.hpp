// Particle-update schemes in the unified form of seed 002 (Eq. 1.7-1.12) and seed 000 Task 4:
// every explicit update is a choice of effective acceleration A and velocity VV per particle,
//     V <- V + A dt,    X <- X + VV dt + 1/2 A dt^2.
// A scheme reads the step's grid velocities (v = m^-1 p and v+ = m^-1 p+, both with velocity
// conditions applied) through the transfer cache and moves the particles. One file and one
// CAIRN_REGISTER_SCHEME line per scheme.
#pragma once

#include <memory>

#include "cairn/grid/grid.hpp"
#include "cairn/io/config.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/util/registry.hpp"

namespace cairn {

template <int D>
struct StepState {
  const Grid<D>& grid;
  const NodeField<D>& nodes;
  const TransferCache<D>& cache;
  Particles<D>& particles;
  double dt;
};

template <int D>
class UpdateScheme {
 public:
  virtual ~UpdateScheme() = default;
  /// Move particles: velocities and positions from the grid solution of this step.
  virtual void update_particles(StepState<D>& step) const = 0;
};

template <int D>
using SchemeRegistry = Registry<UpdateScheme<D>, const MethodConfig&>;

#define CAIRN_REGISTER_SCHEME(Class, key, doc)                                                   \
  static const bool cairn_scheme_registered_##Class =                                            \
      (::cairn::SchemeRegistry<1>::instance().add(                                               \
           key, doc, [](const ::cairn::MethodConfig& m) { return std::make_unique<Class<1>>(m); }), \
       ::cairn::SchemeRegistry<2>::instance().add(                                               \
           key, doc, [](const ::cairn::MethodConfig& m) { return std::make_unique<Class<2>>(m); }), \
       ::cairn::SchemeRegistry<3>::instance().add(                                               \
           key, doc, [](const ::cairn::MethodConfig& m) { return std::make_unique<Class<3>>(m); }), \
       true)

}  // namespace cairn
