// Shape-function families. A family fills the transfer cache with each particle's stencil
// (node indices, S_pi and G_pi) once per step; every transfer then reads the cache. Adding a
// family is one file with a class and one CAIRN_REGISTER_SHAPE line.
#pragma once

#include <memory>
#include <string>

#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/util/registry.hpp"

namespace cairn {

/// What a family may read when it is created.
struct ShapeContext {
  const MethodConfig& method;
  int dimension;
};

/// How a family's grid values meet the non-periodic domain faces; velocity conditions
/// (bc/grid_conditions) act accordingly.
enum class FaceBasis {
  /// One value per grid node. Wide stencils reach ghost nodes beyond the faces (seed 003
  /// Sec. 3.4.2): Dirichlet faces hold them too, symmetry faces mirror them.
  ghost_nodes,
  /// Open-knot boundary B-splines (seed 003 Eq. 22-23): the value stored at the face node belongs
  /// to the only basis function that is non-zero on the face (it equals 1 there), so a condition
  /// on that value alone holds exactly on the whole face. Ghost slots hold the extra interior
  /// functions of the open knot vector and are never constrained.
  open_knot,
};

/// How the particle domain a family integrates over follows the deformation; tractions on
/// particle faces use it for the face areas (bc/traction).
enum class ParticleDomain {
  undeformed,  ///< the initial box l_p0 (GIMP, uGIMP, splines, linear)
  stretched,   ///< the box l_p0 diag(F) (cpGIMP, seed 003 Sec. 3.3)
  convected,   ///< the parallelogram/parallelepiped F diag(l_p0) (CPDI, B2CPDI)
};

template <int D>
class ShapeFamily {
 public:
  virtual ~ShapeFamily() = default;
  /// Ghost node layers the family needs beyond each non-periodic domain face.
  [[nodiscard]] virtual int ghost_layers() const = 0;
  /// How the family's values relate to the faces (default: ghost nodes).
  [[nodiscard]] virtual FaceBasis face_basis() const { return FaceBasis::ghost_nodes; }
  /// The particle domain the family tracks (default: the undeformed box).
  [[nodiscard]] virtual ParticleDomain particle_domain() const { return ParticleDomain::undeformed; }
  /// Position of the degree of freedom stored at node `index`: the node itself for nodal
  /// families, the Greville abscissa (knot average) for open-knot splines. sum_i S_pi x_i = x_p
  /// holds with these positions; tests and plots use it.
  [[nodiscard]] virtual Vec<D> dof_position(const Grid<D>& grid, std::int32_t index) const {
    return grid.node_position(index);
  }
  /// Fill the cache's stencils (either layout) and reach for every particle. Throws
  /// SimulationFailure naming the lowest-index particle whose stencil leaves the stored grid.
  virtual void build(const Grid<D>& grid, const Particles<D>& particles,
                     TransferCache<D>& cache) const = 0;
};

template <int D>
using ShapeRegistry = Registry<ShapeFamily<D>, const ShapeContext&>;

template <int D>
std::unique_ptr<ShapeFamily<D>> make_shape_family(const ShapeContext& ctx) {
  return ShapeRegistry<D>::instance().create("shape family", ctx.method.shape, ctx);
}

/// One registration line per family: registers the class template for D = 1, 2, 3.
#define CAIRN_REGISTER_SHAPE(Class, key, doc)                                                  \
  static const bool cairn_shape_registered_##Class =                                           \
      (::cairn::ShapeRegistry<1>::instance().add(                                              \
           key, doc, [](const ::cairn::ShapeContext& c) { return std::make_unique<Class<1>>(c); }), \
       ::cairn::ShapeRegistry<2>::instance().add(                                              \
           key, doc, [](const ::cairn::ShapeContext& c) { return std::make_unique<Class<2>>(c); }), \
       ::cairn::ShapeRegistry<3>::instance().add(                                              \
           key, doc, [](const ::cairn::ShapeContext& c) { return std::make_unique<Class<3>>(c); }), \
       true)

}  // namespace cairn
