// Particles from the [[body]] tables: a regular lattice of particles_per_cell^D points in every
// grid cell, kept where the point lies inside the body's shape. Each particle carries the volume
// of its lattice cell (times the thickness in 2D, the cross-section in 1D), mass rho0 V0 and
// edge lengths h / ppc. An optional displacement field u(X) places it at x = X + u(X) with
// F = I + grad u (central differences), and its initial velocity is evaluated at X.
//
// arrangement = "radial" replaces the lattice of a circle, annulus or sphere by concentric rings
// or shells (seed 001 Fig. 4b), each particle with the area/volume of its piece; under
// method.integration = "wls" every body also gets zero-volume surface particles
// (wls/arrangement.hpp). Seeds outside the grid are dropped, like lattice points.
//
// An image shape (2D) keeps X when the pixel under it has a grey level in [level_min,
// level_max]: pixel (col, row) of a W x H picture covers [ox + col s, ox + (col + 1) s) x
// [oy + (H - 1 - row) s, oy + (H - row) s), so row 0 (the top of the picture) lies at the
// highest y; positions outside the picture are outside the body. A position on a pixel edge
// (to 1e-6 pixel, so that rounding does not decide) belongs to the pixel on its +x / +y side:
// lattices whose points fall on pixel corners sample the picture consistently. An image_stack
// (3D) does the same in each slice, slice k covering [oz + k dz, oz + (k + 1) dz) along z with
// dz = slice_spacing (seed 004 Sec. 4.2 extended from one picture to a stack).
//
// Shapes from files (docs/geometry.md): a mesh (3D) keeps X when X is inside its closed surface
// (geometry/surface_mesh.hpp; the lattice is visited line by line along x, which is what the
// surface's per-line memo is for); an outline (2D) by the even-odd rule over its loops, as a
// polygon; volume_mesh and points replace the lattice by their own particles (geometry/
// volume_mesh.hpp, point_set.hpp), each with its own volume and a domain of a square/cube of that
// volume, a point file's velocities and temperatures replacing the body's, and its stresses
// giving each particle the stretch that carries them (materials/initial_stress.hpp).
//
// Only the lattice points inside the shape's bounds are visited (sim/resources.hpp), in the same
// order as a sweep of the whole grid would visit them. A shape reaching past the grid is an error
// unless the body says clip = true; bodies sharing space (a particle of one inside another's
// shape) are an error or a warning by simulation.body_overlap.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "cairn/bc/expression.hpp"
#include "cairn/geometry/outline.hpp"
#include "cairn/geometry/point_set.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/geometry/image.hpp"
#include "cairn/materials/initial_stress.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/sim/resources.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/wls/arrangement.hpp"

namespace cairn {
namespace {

/// `line`: the memo of a mesh shape's inside test (geometry/surface_mesh.hpp), one per body.
template <int D>
bool inside(const BodyShapeConfig& s, const GreyImage* image, geometry::LineCache& line, const Vec<D>& x) {
  auto vec = [](const std::vector<double>& v) {
    Vec<D> out = Vec<D>::Zero();
    for (int a = 0; a < D && a < static_cast<int>(v.size()); ++a) out[a] = v[a];
    return out;
  };
  if (s.kind == "box") {
    const Vec<D> lo = vec(s.min), hi = vec(s.max);
    return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all();
  }
  if (s.kind == "circle" || s.kind == "sphere") return (x - vec(s.center)).norm() <= s.radius;
  if (s.kind == "cylinder") {
    if constexpr (D == 3) {
      const Vec<D> d = x - vec(s.center);
      return d[2] >= 0.0 && d[2] <= s.height && std::hypot(d[0], d[1]) <= s.radius;
    }
    return false;
  }
  if (s.kind == "ellipse") {
    const Vec<D> d = (x - vec(s.center)).cwiseQuotient(vec(s.semi_axes));
    return d.squaredNorm() <= 1.0;
  }
  if (s.kind == "annulus") {
    const double r = (x - vec(s.center)).norm();
    return r >= s.inner_radius && r <= s.outer_radius;
  }
  if (s.kind == "polygon") {
    if constexpr (D == 2) return geometry::inside_loop(s.vertices, x[0], x[1]);  // even-odd crossing rule
  }
  if (s.kind == "outline") {
    if constexpr (D == 2) return geometry::inside_loops(s.loops, x[0], x[1]);  // holes by the same rule
  }
  if (s.kind == "mesh" && s.mesh) {
    if constexpr (D == 3) return s.mesh->inside(x[0], x[1], x[2], line);
  }
  if ((s.kind == "image" || s.kind == "image_stack") && image) {
    if constexpr (D >= 2) {
      const Vec<D> o = vec(s.origin);
      auto pixel = [&](double t) {
        const double r = std::round(t);
        return std::floor(std::abs(t - r) <= 1e-6 ? r : t);
      };
      const double u = pixel((x[0] - o[0]) / s.pixel_size);
      const double v = pixel((x[1] - o[1]) / s.pixel_size);
      if (!(u >= 0.0 && u < image->width && v >= 0.0 && v < image->height)) return false;
      int slice = 0;
      if constexpr (D == 3) {
        const double w = pixel((x[2] - o[2]) / s.slice_spacing);
        if (!(w >= 0.0 && w < image->depth)) return false;
        slice = static_cast<int>(w);
      }
      const int level = image->at(static_cast<int>(u), image->height - 1 - static_cast<int>(v), slice);
      return level >= s.level_min && level <= s.level_max;
    }
  }
  return false;
}

/// Bodies sharing space: a particle of a later body inside an earlier body's shape (the mass
/// there counts twice). An error or a warning naming both, by simulation.body_overlap.
/// shared[b][a]: particles of body b (a > b excluded) inside the shape of body a; count[b]: the
/// particles of body b (both counted over every generated particle, stored or not).
inline void check_overlaps(const Config& config, const std::vector<std::vector<std::size_t>>& shared,
                           const std::vector<std::size_t>& count) {
  for (std::size_t b = 1; b < config.bodies.size(); ++b)
    for (std::size_t a = 0; a < b; ++a) {
      if (shared[b][a] == 0) continue;
      const BodyConfig& first = config.bodies[a];
      const BodyConfig& second = config.bodies[b];
      const std::string what = fmt::format(
          "bodies '{}' ({}) and '{}' ({}) overlap: {} of the {} particles of '{}' lie inside the shape of "
          "'{}', where the mass counts twice",
          first.name, first.where.str(), second.name, second.where.str(), shared[b][a], count[b], second.name,
          first.name);
      if (config.simulation.body_overlap == "warn") {
        if (Comm::world().is_root()) std::fprintf(stderr, "cairn: warning: %s\n", what.c_str());
        continue;
      }
      throw InputError(second.where.file, second.where.line, fmt::format("body[{}].shape", b),
                       fmt::format("a shape that shares no space with another body's (or "
                                   "simulation.body_overlap = \"warn\" to run anyway)"),
                       what);
    }
}

}  // namespace

template <int D>
void create_particles(const Config& config, const Grid<D>& grid,
                      const std::vector<std::unique_ptr<Material>>& materials, Mode mode,
                      Particles<D>& particles, const ParticleSelection<D>* select,
                      const GenerationShare<D>* share) {
  const double thickness = D == 3 ? 1.0 : config.simulation.thickness;
  const std::size_t n_bodies = config.bodies.size();
  const int margin = share && share->decomposition ? share->margin : 0;  // > 0: select only, no checks
  // Over every generated particle, stored or not (per-rank generation stores a subset).
  std::int64_t next_id = static_cast<std::int64_t>(particles.n());
  std::vector<std::size_t> count_of(n_bodies, 0);
  std::vector<std::vector<std::size_t>> shared(n_bodies, std::vector<std::size_t>(n_bodies, 0));
  std::vector<ShapeBounds<D>> bounds_of;
  std::vector<std::shared_ptr<const GreyImage>> image_of;
  std::vector<geometry::LineCache> line_of(n_bodies);
  for (std::size_t b = 0; b < config.bodies.size(); ++b) {
    const BodyConfig& body = config.bodies[b];
    int mat = -1;
    for (std::size_t m = 0; m < config.materials.size(); ++m)
      if (config.materials[m].name == body.material) mat = static_cast<int>(m);
    if (mat < 0)
      throw InputError(body.where.file, body.where.line, fmt::format("body[{}].material", b),
                       "the name of a [[material]]", "\"" + body.material + "\"");
    IVec<D> ppc;
    for (int a = 0; a < D; ++a) ppc[a] = body.particles_per_cell[a];
    const Vec<D> lp = grid.cell_size().cwiseQuotient(ppc.template cast<double>());
    const double vol = lp.prod() * thickness;
    const double mass = materials[mat]->density() * vol;

    std::unique_ptr<ExpressionVector<D>> velocity, displacement;
    try {
      if (!body.velocity.empty())
        velocity = std::make_unique<ExpressionVector<D>>(body.velocity, config.constants);
      if (!body.displacement.empty())
        displacement = std::make_unique<ExpressionVector<D>>(body.displacement, config.constants);
    } catch (const std::invalid_argument& e) {
      throw InputError(body.where.file, body.where.line, fmt::format("body[{}].velocity", b),
                       "expressions in X, Y, Z and [constants]", e.what());
    }

    // The picture of an image shape: read by the loader, else (a Config built in code) here,
    // once per body rather than per lattice point.
    std::shared_ptr<const GreyImage> image;
    try {
      image = body_image(body, config);
    } catch (const std::invalid_argument& e) {  // (the loader has read the images of an input file)
      throw std::invalid_argument(body.where.str() + ": body '" + body.name + "': " + e.what());
    }
    const ShapeBounds<D> bounds = shape_bounds<D>(body.shape, image.get(), grid);
    check_inside_grid<D>(body, b, bounds, grid, lp);
    bounds_of.push_back(bounds);
    image_of.push_back(image);

    // Earlier bodies whose bounds meet this one's: their shapes are checked for overlaps.
    std::vector<std::size_t> near_bodies;
    for (std::size_t a = 0; a < b; ++a) {
      const bool apart = (bounds_of[a].hi.array() < bounds.lo.array()).any() ||
                         (bounds.hi.array() < bounds_of[a].lo.array()).any();
      if (!apart) near_bodies.push_back(a);
    }
    // The lattice points in the bounds, axis 0 fastest (the order of a sweep of the grid).
    const LatticeBox<D> box = lattice_box<D>(bounds, grid, lp);
    std::array<long long, D> span{};
    long long total = 1;
    for (int a = 0; a < D; ++a) {
      span[a] = std::max(0LL, box.hi[a] - box.lo[a] + 1);
      total *= span[a];
    }
    // The lattice, or the seed 001 Fig. 4b rings/shells; WLS adds surface particles (zero volume)
    // between lattice points in and out of the shape, on a lattice one point wider than the box.
    const bool radial = body.arrangement == "radial";
    // A point file: its rows are the particles, with their own volumes (geometry/point_set.hpp).
    const geometry::PointSet* points = body.shape.points.get();  // (points, volume_mesh)
    const bool surface = config.method.integration == "wls" && !points;
    // A point file's initial stresses: each particle starts at the stretch that carries its
    // stress (materials/initial_stress.hpp), which only a model whose stress is tau(F) can take.
    const bool stressed = points && !points->stress.empty();
    if (stressed && !takes_initial_stress(*materials[mat]))
      throw InputError(body.where.file, body.where.line, fmt::format("body[{}].shape.points.file", b),
                       "a material whose stress follows from the deformation alone (linear_elastic, neo_hookean) "
                       "for a point file with stress columns",
                       fmt::format("material '{}' (model {}), which keeps its stress in state variables and "
                                   "cannot start from a given stress",
                                   body.material, config.materials[static_cast<std::size_t>(mat)].model));
    if (stressed && displacement)
      throw InputError(body.where.file, body.where.line, fmt::format("body[{}].displacement", b),
                       "no displacement on a body whose point file gives initial stresses (the stress sets F)",
                       "a displacement");
    std::vector<wls::Seed<D>> seeds;
    if (points) {
      for (std::size_t i = 0; i < points->n(); ++i) {
        Vec<D> X;
        for (int a = 0; a < D; ++a) X[a] = points->position[i][static_cast<std::size_t>(a)];
        seeds.push_back({X, points->volume[i]});
      }
    } else if (radial) {
      for (auto& s : wls::radial_arrangement<D>(body.shape, lp.minCoeff(), surface))
        if ((s.X.array() >= grid.origin().array()).all() && (s.X.array() < grid.extent_max().array()).all())
          seeds.push_back(s);
    } else if (surface && total > 0) {
      auto in = [&](const Vec<D>& X) { return inside<D>(body.shape, image.get(), line_of[b], X); };
      Vec<D> first;
      IVec<D> count;
      for (int a = 0; a < D; ++a) {
        const long long lo = std::max(0LL, box.lo[a] - 1);
        const long long hi = std::min(static_cast<long long>(grid.n_cells()[a]) * ppc[a] - 1, box.hi[a] + 1);
        first[a] = grid.origin()[a] + (static_cast<double>(lo) + 0.5) * lp[a];
        count[a] = static_cast<int>(hi - lo + 1);
      }
      for (const Vec<D>& X : wls::lattice_surface_points<D>(in, first, lp, count)) seeds.push_back({X, 0.0});
    }
    const long long n_lattice = radial || points ? 0 : total;
    auto lattice_point = [&](long long k) {
      Vec<D> X;
      for (int a = 0; a < D; ++a) {
        const long long ia = box.lo[a] + k % span[a];
        k /= span[a];
        X[a] = grid.origin()[a] + (static_cast<double>(ia) + 0.5) * lp[a];
      }
      return X;
    };
    // A generated particle counts for the body and for its overlaps with earlier bodies
    // (zero-volume particles carry no mass: they make no overlap).
    auto tally = [&](const Vec<D>& X, double particle_volume) {
      if (particle_volume > 0.0)
        for (std::size_t a : near_bodies)
          if (inside<D>(config.bodies[a].shape, image_of[a].get(), line_of[a], X)) ++shared[b][a];
      ++count_of[b];
    };
    // The stretch that carries a point file's initial stress on row `row` (none without stresses);
    // an InputError when the material cannot carry it.
    auto stretch_of = [&](std::size_t row) -> std::optional<Mat3> {
      if (!stressed) return std::nullopt;
      SymMat3 sigma0;
      sigma0.voigt() = points->stress[row];
      std::optional<Mat3> stretch = initial_stretch(*materials[mat], sigma0.full(), D < 3, mode == Mode::plane_stress);
      if (!stretch)
        throw InputError(body.where.file, body.where.line, fmt::format("body[{}].shape.points.file", b),
                         fmt::format("initial stresses that material '{}' can carry (a stretch F0 with "
                                     "tau(F0) = det(F0) sigma0)",
                                     body.material),
                         fmt::format("particle {} of '{}' (xx, yy, zz, yz, xz, xy = {}): no such stretch found",
                                     row + 1, points->file, fmt::join(points->stress[row], ", ")));
      return stretch;
    };
    // The particle: stored when `select` keeps it. `k`: its lattice point, or n_lattice + its seed.
    auto emit = [&](long long k, const Vec<D>& X, std::int64_t id, double particle_volume, double particle_mass,
                    bool in_share) {
      const std::size_t row = static_cast<std::size_t>(k - n_lattice);
      const std::optional<Mat3> stretch = stretch_of(row);  // (before the selection: refused alike)
      const Vec<D> x = displacement ? Vec<D>(X + (*displacement)(X, X, 0.0)) : X;
      if (select && !(*select)(id, static_cast<std::int32_t>(b), X, x, in_share)) return;
      Vec<D> v0 = velocity ? (*velocity)(X, X, 0.0) : Vec<D>::Zero();
      Vec<D> domain = lp;  // a point file's particle: a cube (square) of its own volume (area)
      if (points) {
        domain = Vec<D>::Constant(std::pow(points->volume[row], 1.0 / D));
        if (!points->velocity.empty())
          for (int a = 0; a < D; ++a) v0[a] = points->velocity[row][static_cast<std::size_t>(a)];
      }
      particles.add(X, v0, particle_mass, particle_volume, domain, mat, static_cast<std::int32_t>(b));
      particles.id.back() = id;
      const std::size_t p = particles.n() - 1;
      if (particles.has_temperature)
        particles.temperature[p] = points && !points->temperature.empty() ? points->temperature[row]
                                                                           : materials[mat]->initial_temperature();
      if (particles.n_state_per_particle > 0)
        materials[mat]->initialize_state(&particles.state[p * static_cast<std::size_t>(particles.n_state_per_particle)]);
      if (stretch) particles.deformation_gradient[p] = *stretch;  // its stress: below, from F
      if (displacement) {
        particles.position[p] = x;
        Mat3 F = Mat3::Identity();
        for (int a = 0; a < D; ++a) {
          const double h = 1e-6 * grid.cell_size()[a];
          Vec<D> Xp = X, Xm = X;
          Xp[a] += h;
          Xm[a] -= h;
          const Vec<D> du = ((*displacement)(Xp, Xp, 0.0) - (*displacement)(Xm, Xm, 0.0)) / (2.0 * h);
          F.col(a).template head<D>() += du;
        }
        particles.deformation_gradient[p] = F;
      }
    };
    // Candidate k (a lattice point, then the seeds): its reference position, volume and mass, and
    // whether it is a particle (a lattice point inside the shape; every seed is).
    auto candidate = [&](long long k, Vec<D>& X, double& particle_volume, double& particle_mass) {
      if (k < n_lattice) {
        X = lattice_point(k);
        particle_volume = vol;
        particle_mass = mass;
        return inside<D>(body.shape, image.get(), line_of[b], X);
      }
      const auto& s = seeds[static_cast<std::size_t>(k - n_lattice)];
      X = s.X;
      particle_volume = s.measure * thickness;
      particle_mass = materials[mat]->density() * particle_volume;
      return true;
    };
    // A walk shared by the ranks: the body's count and overlaps over every rank (each particle
    // was tallied by one rank), and the ids that follow it.
    auto sum_tallies = [&](const Comm& comm) {
      std::vector<std::int64_t> sums(n_bodies + 1, 0);
      sums[0] = static_cast<std::int64_t>(count_of[b]);
      for (std::size_t a = 0; a < n_bodies; ++a) sums[a + 1] = static_cast<std::int64_t>(shared[b][a]);
      comm.sum(sums.data(), static_cast<int>(sums.size()));
      count_of[b] = static_cast<std::size_t>(sums[0]);
      for (std::size_t a = 0; a < n_bodies; ++a) shared[b][a] = static_cast<std::size_t>(sums[a + 1]);
      next_id += sums[0];
    };
    // A plain lattice body (no seeds, no displacement) is made in two sweeps over the lattice
    // points: the first tests each point and keeps one bit, so that the particle arrays can be
    // reserved for the count before the second makes the particles. On several ranks each rank
    // sweeps only its own points (generation_share; docs/parallel.md).
    const bool plain = !radial && !points && !surface && !displacement;
    const bool ranks_share = share && share->comm && share->comm->parallel();
    if (plain && total > 0 && (ranks_share || margin == 0)) {
      const long long rows = total / span[0];  // lines along x, in sweep order
      const Decomposition<D>* dec = ranks_share ? share->decomposition : nullptr;
      // With a decomposition a row meets several ranks' boxes, in segments between the boxes'
      // x faces: the counts per (row, segment), summed over the ranks, in sweep order, give
      // every point its id.
      std::vector<long long> cuts;  // lattice x indices (from box.lo) where a segment starts
      std::array<long long, 3> lo{0, 0, 0}, hi{0, 0, 0};  // this rank's points, inclusive, from box.lo
      if (dec) {
        for (int q = 0; q < dec->n_boxes(); ++q)
          for (long long c : {static_cast<long long>(dec->box(q).lo[0]), static_cast<long long>(dec->box(q).hi[0])})
            cuts.push_back(c * ppc[0] - box.lo[0]);
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        const CellBox<D>& cells = dec->box(share->comm->rank());
        for (int a = 0; a < D; ++a) {
          lo[a] = std::max(box.lo[a], static_cast<long long>(cells.lo[a] - margin) * ppc[a]) - box.lo[a];
          hi[a] = std::min(box.hi[a], static_cast<long long>(cells.hi[a] + margin) * ppc[a] - 1) - box.lo[a];
        }
      }
      const auto n_seg = static_cast<long long>(cuts.size());
      auto segment = [&](long long i) {
        return static_cast<long long>(std::upper_bound(cuts.begin(), cuts.end(), i) - cuts.begin()) - 1;
      };
      // fn(k) for the lattice points this walk tests, in sweep order: all of them (serial), the
      // r-th block of whole rows (the census on several ranks), or those in the cells of this
      // rank's box.
      auto sweep = [&](auto&& fn) {
        if (!dec) {
          const auto r = ranks_share ? static_cast<long long>(share->comm->rank()) : 0LL;
          const auto n = ranks_share ? static_cast<long long>(share->comm->size()) : 1LL;
          for (long long k = rows * r / n * span[0]; k < rows * (r + 1) / n * span[0]; ++k) fn(k);
          return;
        }
        const long long stride2 = D == 3 ? span[std::min(1, D - 1)] : 0;  // rows per z layer
        if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])
          for (long long i2 = lo[2]; i2 <= hi[2]; ++i2)
            for (long long i1 = lo[1]; i1 <= hi[1]; ++i1)
              for (long long i0 = lo[0]; i0 <= hi[0]; ++i0) fn(i0 + span[0] * (i1 + stride2 * i2));
      };
      std::vector<std::int64_t> count(dec && margin == 0 ? static_cast<std::size_t>(rows * n_seg) : 0, 0);
      std::vector<bool> in;  // per tested point, in sweep order: inside the shape
      std::size_t n_in = 0;
      sweep([&](long long k) {
        const Vec<D> X = lattice_point(k);
        const bool yes = inside<D>(body.shape, image.get(), line_of[b], X);
        in.push_back(yes);
        if (!yes) return;
        ++n_in;
        if (margin > 0) return;
        tally(X, vol);
        if (dec) ++count[static_cast<std::size_t>(k / span[0] * n_seg + segment(k % span[0]))];
      });
      std::int64_t first = next_id;  // the first id (serial, census)
      if (ranks_share && !dec) first += share->comm->exclusive_prefix(static_cast<std::int64_t>(n_in));
      if (dec) {
        constexpr std::size_t chunk = 1u << 24;
        for (std::size_t at = 0; at < count.size(); at += chunk)
          share->comm->sum(count.data() + at, static_cast<int>(std::min(chunk, count.size() - at)));
        std::int64_t before = 0;  // count -> the first id offset of each (row, segment)
        for (auto& c : count) before += std::exchange(c, before);
      }
      // Room for the particles where this walk stores them: serially and in the walk over the
      // rank's own box (the census and a selecting walk store none).
      if (!ranks_share || (dec && margin == 0)) particles.reserve(particles.n() + n_in);
      std::size_t j = 0;  // tested points so far
      sweep([&](long long k) {
        if (!in[j++]) return;
        std::int64_t id = first++;
        if (dec) {
          id = margin > 0 ? -1 : next_id + count[static_cast<std::size_t>(k / span[0] * n_seg + segment(k % span[0]))]++;
        }
        emit(k, lattice_point(k), id, vol, mass, false);
      });
      if (margin > 0) continue;  // a selecting walk: no ids, counts or checks
      if (ranks_share)
        sum_tallies(*share->comm);
      else
        next_id += static_cast<std::int64_t>(n_in);
    } else if (ranks_share && margin == 0) {
      // Any other body (point file or mesh elements, the radial arrangement, a displacement):
      // rank r takes the r-th block of its candidates, in creation order, and stores every
      // particle it makes wherever it lies (x = X + u(X) is known only here); the simulation
      // sends them to their owners afterwards (Distribution::place). Ids: the counts of the
      // blocks before this rank's.
      const Comm& comm = *share->comm;
      const long long n_candidates = n_lattice + static_cast<long long>(seeds.size());
      const auto r = static_cast<long long>(comm.rank()), n = static_cast<long long>(comm.size());
      struct Made {
        long long k;
        Vec<D> X;
        double volume, mass;
      };
      std::vector<Made> made;
      for (long long k = n_candidates * r / n; k < n_candidates * (r + 1) / n; ++k) {
        Made m{k, Vec<D>::Zero(), 0.0, 0.0};
        if (!candidate(k, m.X, m.volume, m.mass)) continue;
        tally(m.X, m.volume);
        made.push_back(m);
      }
      const std::int64_t first = next_id + comm.exclusive_prefix(static_cast<std::int64_t>(made.size()));
      // An initial stress the material cannot carry is refused on every rank at the first such
      // row of the body, as a serial run refuses it.
      std::int64_t refused = std::numeric_limits<std::int64_t>::max();
      for (std::size_t j = 0; j < made.size(); ++j) {
        try {
          emit(made[j].k, made[j].X, first + static_cast<std::int64_t>(j), made[j].volume, made[j].mass, true);
        } catch (const InputError&) {
          refused = made[j].k;
          break;
        }
      }
      refused = comm.min(refused);
      if (refused != std::numeric_limits<std::int64_t>::max()) {
        (void)stretch_of(static_cast<std::size_t>(refused - n_lattice));  // throws
        throw std::logic_error("create_particles: a refused initial stress solved on another rank");
      }
      sum_tallies(comm);
    } else {
      // The whole body: a serial run, or a selecting walk (margin > 0) over a body of the kind above.
      for (long long k = 0; k < n_lattice + static_cast<long long>(seeds.size()); ++k) {
        Vec<D> X;
        double particle_volume = 0.0, particle_mass = 0.0;
        if (!candidate(k, X, particle_volume, particle_mass)) continue;
        tally(X, particle_volume);
        emit(k, X, next_id++, particle_volume, particle_mass, false);
      }
    }
    if (count_of[b] == 0) {
      std::string spacing;
      for (int a = 0; a < D; ++a) spacing += fmt::format("{}{:.6g}", a ? ", " : "", lp[a]);
      throw InputError(
          body.where.file, body.where.line, fmt::format("body[{}].shape", b),
          fmt::format("a shape holding at least one particle position: the lattice of "
                      "particles_per_cell = [{}] points per grid cell (spacing [{}]) inside the grid",
                      fmt::join(body.particles_per_cell, ", "), spacing),
          bounds.empty() ? fmt::format("body '{}' with an empty shape (no pixel in its levels)", body.name)
                         : fmt::format("body '{}', a {} whose bounds [{}]..[{}] hold no lattice point{}", body.name,
                                       body.shape.kind, fmt::join(std::vector<double>(bounds.lo.begin(), bounds.lo.end()), ", "),
                                       fmt::join(std::vector<double>(bounds.hi.begin(), bounds.hi.end()), ", "),
                                       box.count() == 0.0 ? " inside the grid" : ""));
    }
  }
  if (margin == 0) check_overlaps(config, shared, count_of);
  // Initial stresses of pre-deformed bodies (a displacement, or a point file's stresses).
  for (std::size_t p = 0; p < particles.n(); ++p) {
    if (particles.deformation_gradient[p].isIdentity(0.0)) continue;
    const Mat3 L = Mat3::Zero();
    double* state = particles.n_state_per_particle
                        ? &particles.state[p * static_cast<std::size_t>(particles.n_state_per_particle)]
                        : nullptr;
    const MaterialPoint point{particles.deformation_gradient[p], L, state, 0.0};
    particles.kirchhoff_stress[p] = materials[particles.material[p]]->update(point);
  }
}

template void create_particles<1>(const Config&, const Grid<1>&, const std::vector<std::unique_ptr<Material>>&, Mode,
                                  Particles<1>&, const ParticleSelection<1>*, const GenerationShare<1>*);
template void create_particles<2>(const Config&, const Grid<2>&, const std::vector<std::unique_ptr<Material>>&, Mode,
                                  Particles<2>&, const ParticleSelection<2>*, const GenerationShare<2>*);
template void create_particles<3>(const Config&, const Grid<3>&, const std::vector<std::unique_ptr<Material>>&, Mode,
                                  Particles<3>&, const ParticleSelection<3>*, const GenerationShare<3>*);

}  // namespace cairn
