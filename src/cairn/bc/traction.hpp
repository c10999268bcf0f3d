// Tractions on particle faces (seed 000 Sec. 2.4, first equation):
//     f_i^(T) = sum over loaded faces (p, s) of T_{p,s}(t) int_{A_s} N_i(x) dS,
// added to the grid forces of Task 2, so that every particle update and stress-update timing
// works unchanged (seed 000: "no changes are needed in FMPM").
//
// Faces. A [[traction]] selects, once at setup on the reference configuration, the exposed faces
// of a body's particles: face s of particle p (normal -e_a or +e_a) is exposed when the body has
// no particle in the neighbouring lattice site across it (bodies are filled on a lattice of
// spacing h / ppc, sim/bodies.cpp). `side` keeps the faces of one outward normal, the box keeps
// faces whose reference centre lies in it.
//
// Face geometry each step, by what the shape family tracks (docs/boundary-conditions.md):
//   convected  (cpdi, b2cpdi): the domain x_p + F diag(l_p0/2) [-1, 1]^D, faces are the deformed
//              parallelograms of CPDI (seed 000 Sec. 2.1, Sadeghirad et al. 2011);
//   stretched  (cpgimp): the box l_p0 diag(F) (seed 003 Sec. 3.3);
//   undeformed (every other family): the initial box l_p0 translated to x_p.
// The area A_s is that of the face (times the thickness in 2D, the cross-section in 1D).
//
// Integral. int_{A_s} N_i dS is evaluated the way the shape family evaluates its own particle
// integrals, by building the family's stencil for one proxy particle per face: the face itself,
// a particle domain centred on the face with the particle's extent along the face, zero extent
// along its normal, and the particle's F. So S_pi of the proxy is the family's approximation of
// (1/A_s) int_{A_s} N_i dS: the exact face average for the GIMP families, the CPDI average of N_i
// over the corners of the deformed face for cpdi/b2cpdi (seed 000 Sec. 2.1 bracketed form, "CPDI
// style" of Sec. 2.4), and N_i at the face centre for the point families (linear, B-splines).
// The proxies' gradients are not used (CPDI leaves them undefined for a flat domain).
//
// Why not a finer quadrature for the point families: their lumped masses m_i = sum_p M_p N_i(x_p)
// sample N_i at the particles, one point per particle. Integrating the traction more exactly
// along the face than the mass is sampled gives the low-mass nodes just outside the body's edges
// (the corners of a loaded end) more force per unit mass than the body has; the grid
// accelerations then vary along the face and leave a checkerboard residual stress at the corners
// once the load is gone (verification/traction_pulse, README). Sampling the face like the mass
// keeps f_i / m_i uniform along the face.
//
// The traction vector is fixed in space (it does not turn with the face) and is evaluated at the
// middle of the step, t + dt/2, so that the impulse of a step is second-order accurate.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_set>
#include <vector>

#include "cairn/bc/time_function.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/parallel/exact_sum.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/transfer/cache.hpp"

namespace cairn {

template <int D>
class Tractions {
 public:
  Tractions() = default;
  /// Select the loaded faces of every [[traction]]. `domain`: the particle domain of the run's
  /// shape family (ShapeFamily::particle_domain), which sets how face areas deform. Throws
  /// std::invalid_argument naming the traction and its line when one selects no face or its
  /// scale does not parse.
  Tractions(const Config& config, const Grid<D>& grid, const Particles<D>& particles, ParticleDomain domain);
  /// Per-rank generation (docs/parallel.md): `particles` are this rank's share, `occupied[b]`
  /// the lattice sites (lattice_site) of body b's particles next to them, on any rank; the faces
  /// of every rank are gathered (collective), so every rank holds the run's whole face list in
  /// the serial order and refuses an empty selection alike.
  Tractions(const Config& config, const Grid<D>& grid, const Particles<D>& particles, ParticleDomain domain,
            const std::vector<std::unordered_set<std::int64_t>>& occupied, const Comm& comm);

  /// Key of the lattice site of a particle at reference position X on a lattice of `spacing`
  /// from `origin` (bodies are filled on such lattices, sim/bodies.cpp), shifted by `shift`
  /// sites along `axis`.
  [[nodiscard]] static std::int64_t lattice_site(const Vec<D>& X, const Vec<D>& origin, const Vec<D>& spacing,
                                                 int axis = 0, int shift = 0);

  [[nodiscard]] bool empty() const { return loads_.empty(); }
  /// Number of faces loaded by traction `k`.
  [[nodiscard]] std::size_t n_faces(std::size_t k) const { return loads_[k].n_faces; }

  /// force_i += f_i^(T) at time t for the current particle configuration. `field_offset`
  /// (multimaterial mode) gives per particle the shift of its field's node entries.
  void add_forces(const Grid<D>& grid, const Particles<D>& particles, const ShapeFamily<D>& shape,
                  double t, std::vector<Vec<D>>& force,
                  const std::vector<std::int32_t>* field_offset = nullptr);
  /// Each loaded face at time t in the current configuration, for a method that integrates the
  /// loads itself (method.integration = "wls", docs/wls.md): fn(group, centre, outward normal
  /// times area, force T(t) A_s), group = 2 D k + 2 axis + (0 min, 1 max side) for traction k
  /// (n_loads() tractions). The faces deform as in add_forces; the totals follow them.
  void for_each_face(const Particles<D>& particles, double t,
                     const std::function<void(std::int32_t, const Vec<D>&, const Vec<D>&, const Vec<D>&)>& fn);
  [[nodiscard]] std::size_t n_loads() const { return loads_.size(); }
  /// The particle (local index) of the q-th face for_each_face visits.
  [[nodiscard]] std::int32_t face_particle(std::size_t q) const { return faces_[q].particle; }
  /// sum_i f_i^(T) . v_i for the forces of the last add_forces (work rate at grid velocity v),
  /// over the faces of owned particles, summed exactly (the caller adds the ranks).
  [[nodiscard]] ExactSum power(const std::vector<Vec<D>>& v,
                               const std::vector<std::int32_t>* field_offset = nullptr) const;
  /// Total force of traction k at the last add_forces (sum over the faces of owned particles of
  /// T A_s).
  [[nodiscard]] Vec<D> total_force(std::size_t k) const { return loads_[k].total; }
  /// A distributed run: load the faces of this rank's particles, owned ones [0, n_owned) and
  /// ghost copies after them (each part in increasing id), keeping the setup's face order.
  void localise(const Particles<D>& particles, std::size_t n_owned);
  /// A serial run whose particles were reordered: the particle stored at k was stored at
  /// old_index[k] (Simulation::sort_particles). The faces and their order stay.
  void renumber(const std::vector<std::int32_t>& old_index);

 private:
  /// The selection of both constructors: faces of `particles` whose neighbouring sites are
  /// not in `occupied`.
  void select(const Config& config, const Grid<D>& grid, const Particles<D>& particles,
              const std::vector<std::unordered_set<std::int64_t>>& occupied, const Comm& comm);

  struct Face {
    std::int32_t particle;  ///< local index
    std::int16_t axis;  ///< normal axis a
    std::int16_t sign;  ///< -1: the min face, +1: the max face
    std::int32_t load;  ///< index into loads_
    std::int64_t id = 0;  ///< the particle's id
    bool owned = true;    ///< false: a ghost copy's face (forces only, no totals)
  };
  /// Centre, outward normal times area and area of face q of the current configuration.
  struct FaceGeometry {
    Vec<D> centre;
    Vec<D> normal_area;
    double area;
  };
  [[nodiscard]] FaceGeometry face_geometry(const Particles<D>& particles, std::size_t q) const;
  struct Load {
    Vec<D> traction = Vec<D>::Zero();
    TimeFunction factor;
    std::size_t n_faces = 0;
    Vec<D> total = Vec<D>::Zero();
  };

  std::vector<Face> faces_;
  std::vector<Face> all_faces_;  ///< every loaded face of the run (setup order), for localise
  std::vector<Load> loads_;
  ParticleDomain domain_ = ParticleDomain::undeformed;
  double thickness_ = 1.0;
  Particles<D> points_;              ///< one proxy particle per face: the face itself
  std::vector<Vec<D>> point_force_;  ///< T(t) A_s of each face
  TransferCache<D> cache_;           ///< the family's stencils of the proxies
};

}  // namespace cairn
