// Particle-update schemes in the unified form of seed 002 (Eq. 1.7-1.12) and seed 000 Task 4:
// every explicit update is a choice of effective acceleration A and velocity VV per particle,
//     V <- V + A dt,    X <- X + VV dt + 1/2 A dt^2.
// A scheme sees, at one particle, the grid velocities of the step extrapolated with S:
//     Sv      = S m^-1 p            (lumped, velocity conditions applied)
//     Sv_new  = S m^-1 p+           (lumped; "S v~" in seed 002)
//     Sv_full = S m~_k^-1 q         (q = p+ or p as the scheme asks, seed 000 Eq. 1)
// and returns A dt and VV. Damping (seed 002 Eq. 1.83) and the dissipated-energy tally
// (Eq. 1.47-1.50) are applied by the step for every scheme alike. One file and one
// CAIRN_REGISTER_SCHEME line per scheme.
#pragma once

#include <memory>

#include "cairn/config/config.hpp"
#include "cairn/math/types.hpp"
#include "cairn/util/registry.hpp"

namespace cairn {

/// Which full-mass-matrix grid velocity a scheme needs this step (seed 000 Sec. 2.2-2.3).
enum class FullMass : std::uint8_t {
  none,        ///< lumped mass only (FLIP, PIC)
  of_updated,  ///< v+_k = m~_k^-1 p+ (FMPM); it also drives the velocity gradient
  of_initial,  ///< v_k = m~_k^-1 p (XPIC, blends with the XPIC projector)
};

template <int D>
struct GridAtParticle {
  Vec<D> V;        ///< particle velocity V^(n)
  Vec<D> Sv;       ///< S m^-1 p
  Vec<D> Sv_new;   ///< S m^-1 p+
  Vec<D> Sv_full;  ///< S m~_k^-1 q (equals Sv_new or Sv when the scheme needs no full mass)
  double dt;
};

template <int D>
struct Effective {
  Vec<D> A_dt;  ///< effective acceleration times dt: V^(n+1) - V^(n)
  Vec<D> VV;    ///< effective velocity V^(n)
};

template <int D>
class UpdateScheme {
 public:
  virtual ~UpdateScheme() = default;
  [[nodiscard]] virtual FullMass full_mass() const { return FullMass::none; }
  /// APIC: particles carry an affine velocity matrix used in P2G and rebuilt in G2P.
  [[nodiscard]] virtual bool affine() const { return false; }
  [[nodiscard]] virtual Effective<D> effective(const GridAtParticle<D>& g) const = 0;
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
