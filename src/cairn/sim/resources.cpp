#include "cairn/sim/resources.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "cairn/geometry/outline.hpp"
#include "cairn/geometry/point_set.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/geometry/image.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

constexpr double pi = 3.141592653589793238462643383279502884;
constexpr double gib = 1024.0 * 1024.0 * 1024.0;

template <int D>
Vec<D> vec(const std::vector<double>& v) {
  Vec<D> out = Vec<D>::Zero();
  for (int a = 0; a < D && a < static_cast<int>(v.size()); ++a) out[a] = v[a];
  return out;
}

template <int D>
std::string point_text(const Vec<D>& x) {
  std::string s = "[";
  for (int a = 0; a < D; ++a) s += fmt::format("{}{:.6g}", a ? ", " : "", x[a]);
  return s + "]";
}

std::string grid_key_where(const Config& c) { return c.grid.where.file; }

/// A machine's memory in bytes: physical pages, or the cgroup (v2, then v1) limit when lower.
double machine_memory_bytes() {
  double bytes = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    double limit = 0.0;
    if (in >> limit && limit > 0.0) bytes = std::min(bytes, limit);  // "max" fails to parse: no limit
  }
  return bytes;
}

/// Bytes the address-space limit (`ulimit -v`, RLIMIT_AS) leaves for the run's data: the limit
/// less what the process maps already (code, libraries, thread stacks); infinite without one.
double address_space_room() {
  struct rlimit r {};
  if (::getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return std::numeric_limits<double>::infinity();
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0;
  statm >> pages;
  return std::max(0.0, static_cast<double>(r.rlim_cur) - pages * static_cast<double>(::sysconf(_SC_PAGE_SIZE)));
}

/// The limit memory_limit_bytes() returns, in words for a message.
std::string memory_limit_text(const Config& config, double limit) {
  if (config.simulation.memory_limit > 0.0)
    return fmt::format("simulation.memory_limit = {:.4g} GiB", config.simulation.memory_limit);
  if (limit < machine_memory_bytes())
    return fmt::format("the {:.4g} GiB that the process's address-space limit (ulimit -v) leaves free "
                       "(simulation.memory_limit = 0)",
                       limit / gib);
  return fmt::format("this machine's {:.4g} GiB (simulation.memory_limit = 0)", limit / gib);
}

}  // namespace

std::shared_ptr<const GreyImage> body_image(const BodyConfig& body, const Config& config) {
  if (body.shape.kind != "image" && body.shape.kind != "image_stack") return nullptr;
  if (body.shape.image) return body.shape.image;
  const std::string file = resolve_input_relative(body.shape.file, config.source_file);
  return std::make_shared<const GreyImage>(body.shape.kind == "image" ? read_png_grey(file)
                                                                      : read_png_stack(file, body.shape.pattern));
}

template <int D>
ShapeBounds<D> shape_bounds(const BodyShapeConfig& s, const GreyImage* image, const Grid<D>& grid) {
  ShapeBounds<D> b;
  const Vec<D> c = vec<D>(s.center);
  const double ball = D == 3 ? pi / 6.0 : D == 2 ? pi / 4.0 : 1.0;  // ball volume / cube volume
  if (s.kind == "box") {
    b.lo = vec<D>(s.min);
    b.hi = vec<D>(s.max);
  } else if (s.kind == "circle" || s.kind == "sphere") {
    b.lo = c.array() - s.radius;
    b.hi = c.array() + s.radius;
    b.fill = ball;
  } else if (s.kind == "ellipse") {
    b.lo = c - vec<D>(s.semi_axes);
    b.hi = c + vec<D>(s.semi_axes);
    b.fill = ball;
  } else if (s.kind == "annulus") {
    b.lo = c.array() - s.outer_radius;
    b.hi = c.array() + s.outer_radius;
    const double r = s.inner_radius / s.outer_radius;
    b.fill = ball * (1.0 - std::pow(r, D));
  } else if (s.kind == "polygon" && D == 2 && !s.vertices.empty()) {
    b.lo = b.hi = vec<D>(s.vertices[0]);
    double twice_area = 0.0;
    for (std::size_t i = 0; i < s.vertices.size(); ++i) {
      b.lo = b.lo.cwiseMin(vec<D>(s.vertices[i]));
      b.hi = b.hi.cwiseMax(vec<D>(s.vertices[i]));
      const auto& p = s.vertices[i];
      const auto& q = s.vertices[(i + 1) % s.vertices.size()];
      twice_area += p[0] * q[1] - q[0] * p[1];
    }
    const double box = (b.hi - b.lo).prod();
    b.fill = box > 0.0 ? std::min(1.0, 0.5 * std::abs(twice_area) / box) : 1.0;
  } else if ((s.kind == "image" || s.kind == "image_stack") && D >= 2 && image) {
    // The pixels (voxels) with a level in [level_min, level_max]; pixel (col, row) of slice k
    // covers [ox + col s, ox + (col + 1) s) x [oy + (H - 1 - row) s, oy + (H - row) s)
    // (x [oz + k dz, oz + (k + 1) dz) in 3D).
    int c0 = image->width, c1 = -1, r0 = image->height, r1 = -1, k0 = image->depth, k1 = -1;
    long long in_level = 0;
    for (int k = 0; k < image->depth; ++k)
      for (int row = 0; row < image->height; ++row)
        for (int col = 0; col < image->width; ++col) {
          const int level = image->at(col, row, k);
          if (level < s.level_min || level > s.level_max) continue;
          c0 = std::min(c0, col);
          c1 = std::max(c1, col);
          r0 = std::min(r0, row);
          r1 = std::max(r1, row);
          k0 = std::min(k0, k);
          k1 = std::max(k1, k);
          ++in_level;
        }
    const Vec<3> o = vec<3>(s.origin);
    const double px = s.pixel_size, dz = s.slice_spacing;
    const double lo[3] = {o[0] + c0 * px, o[1] + (image->height - 1 - r1) * px, o[2] + k0 * dz};
    const double hi[3] = {o[0] + (c1 + 1) * px, o[1] + (image->height - r0) * px, o[2] + (k1 + 1) * dz};
    for (int a = 0; a < D; ++a) {
      b.lo[a] = lo[a];
      b.hi[a] = hi[a];
    }
    const double box_voxels = static_cast<double>(c1 - c0 + 1) * (r1 - r0 + 1) * (k1 - k0 + 1);
    if (in_level > 0) b.fill = static_cast<double>(in_level) / box_voxels;
  } else if (s.kind == "outline" && D == 2 && !s.loops.empty()) {
    b.lo = b.hi = vec<D>(s.loops[0][0]);
    for (const auto& loop : s.loops)  // (every loop: a cut through a mesh may hold several islands)
      for (const auto& v : loop) {
        b.lo = b.lo.cwiseMin(vec<D>(v));
        b.hi = b.hi.cwiseMax(vec<D>(v));
      }
    const double box = (b.hi - b.lo).prod();
    b.fill = box > 0.0 ? std::min(1.0, geometry::loops_area(s.loops) / box) : 1.0;
  } else if (s.points) {  // points, volume_mesh
    // The particles' positions; fill 1 (the estimate then counts every lattice point there).
    for (int a = 0; a < D; ++a) {
      b.lo[a] = s.points->lo[static_cast<std::size_t>(a)];
      b.hi[a] = s.points->hi[static_cast<std::size_t>(a)];
    }
  } else if (s.kind == "mesh" && D == 3 && s.mesh) {
    for (int a = 0; a < D; ++a) {
      b.lo[a] = s.mesh->lo()[static_cast<std::size_t>(a)];
      b.hi[a] = s.mesh->hi()[static_cast<std::size_t>(a)];
    }
    const double box = (b.hi - b.lo).prod();
    b.fill = box > 0.0 ? std::min(1.0, s.mesh->volume() / box) : 1.0;
  } else {
    // A kind without known bounds: the whole grid (generation then visits every lattice point).
    b.lo = grid.origin();
    b.hi = grid.extent_max();
  }
  return b;
}

template <int D>
LatticeBox<D> lattice_box(const ShapeBounds<D>& bounds, const Grid<D>& grid, const Vec<D>& spacing) {
  LatticeBox<D> box;
  for (int a = 0; a < D; ++a) {
    const double points = static_cast<double>(grid.n_cells()[a]) * (grid.cell_size()[a] / spacing[a]);
    const double last = std::round(points) - 1.0;
    // Point i at origin + (i + 1/2) spacing lies in [lo, hi] for (lo - o)/l - 1/2 <= i <= (hi - o)/l - 1/2.
    const double first_in = std::ceil((bounds.lo[a] - grid.origin()[a]) / spacing[a] - 0.5) - 1.0;
    const double last_in = std::floor((bounds.hi[a] - grid.origin()[a]) / spacing[a] - 0.5) + 1.0;
    box.lo[a] = static_cast<long long>(std::clamp(first_in, 0.0, std::max(last, 0.0)));
    box.hi[a] = static_cast<long long>(std::clamp(last_in, -1.0, last));
    if (!(first_in <= last_in) || bounds.lo[a] > bounds.hi[a]) box.hi[a] = box.lo[a] - 1;
  }
  return box;
}

template <int D>
void check_inside_grid(const BodyConfig& body, std::size_t index, const ShapeBounds<D>& bounds,
                       const Grid<D>& grid, const Vec<D>& spacing) {
  if (body.clip || bounds.empty()) return;
  const Vec<D> lo = grid.origin(), hi = grid.extent_max();
  for (int a = 0; a < D; ++a) {
    // Half a spacing past a face is where the first lattice point beyond the grid would lie.
    const double margin = 0.5 * spacing[a] * (1.0 - 1e-9);
    const double below = lo[a] - bounds.lo[a], above = bounds.hi[a] - hi[a];
    if (below < margin && above < margin) continue;
    const bool low = below >= margin;
    throw InputError(body.where.file, body.where.line, fmt::format("body[{}].shape", index),
                     fmt::format("a shape inside the grid {}..{} (or clip = true in this [[body]] "
                                 "to keep only the part inside the grid)",
                                 point_text<D>(lo), point_text<D>(hi)),
                     fmt::format("body '{}' with bounds {}..{}, reaching {:.6g} past the grid's {} "
                                 "face on axis {} (particle spacing {:.6g}): its particles there "
                                 "would be dropped",
                                 body.name, point_text<D>(bounds.lo), point_text<D>(bounds.hi),
                                 low ? below : above, low ? "min" : "max", "xyz"[a], spacing[a]));
  }
}

int velocity_fields(const Config& config) {
  if (config.contact.mode == "material") return static_cast<int>(std::max<std::size_t>(1, config.materials.size()));
  if (config.contact.mode == "body") return static_cast<int>(std::max<std::size_t>(1, config.bodies.size()));
  return 1;
}

void check_node_count(const Config& config, const std::vector<long long>& n_cells,
                      const std::vector<bool>& periodic, int ghost_layers, int n_fields) {
  long double nodes = 1.0L;
  std::string text;
  for (std::size_t a = 0; a < n_cells.size(); ++a) {
    const long long stored = periodic[a] ? n_cells[a] : n_cells[a] + 1 + 2LL * ghost_layers;
    nodes *= static_cast<long double>(stored);
    text += fmt::format("{}{}", a ? " x " : "", stored);
  }
  const long double slots = nodes * n_fields;
  if (slots <= static_cast<long double>(INT32_MAX)) return;
  throw InputError(grid_key_where(config), config.grid.where.line, "grid.cell_size",
                   fmt::format("at most {} stored grid nodes (times velocity fields): node indices "
                               "are 32-bit integers",
                               INT32_MAX),
                   fmt::format("{} stored nodes (with {} ghost layers){} = {:.6g}", text, ghost_layers,
                               n_fields > 1 ? fmt::format(" x {} fields", n_fields) : std::string(),
                               static_cast<double>(slots)));
}

double memory_limit_bytes(const Config& config) {
  if (config.simulation.memory_limit > 0.0) return config.simulation.memory_limit * gib;
  return std::min(machine_memory_bytes(), address_space_room());
}

template <int D>
void check_memory(const Config& config, const Grid<D>& grid, int n_fields, int n_state, int stencil_width,
                  int ranks) {
  // Bytes per particle (particles/particles.hpp: 4 D-vectors, 3 scalars, 4 Mat3, 2 int32, the
  // material state), the simulation's per-particle scratch (3 vectors and a scalar), the
  // transfer cache (per stencil node: node and slot int32, weight, gradient; cell, count, order).
  // An upper bound: the tensor layout of tensor-product families stores less, and snapshots and
  // checkpoints are written from the particle arrays through a small block buffer (no second
  // copy; docs/performance.md measures about 360 bytes per particle in 2D and 450 in 3D).
  const double slots = std::pow(static_cast<double>(stencil_width), D);
  const double particle_arrays = 8.0 * (4 * D + 3 + 4 * 9 + n_state) + 8.0;
  const double per_particle = particle_arrays + 8.0 * (2 * D + 1) + 4.0 +
                              slots * (4.0 + 4.0 + 8.0 + 8.0 * D) + 4.0 * D + 2.0 + 12.0;
  // Bytes per node and field: NodeField (mass, 7 vectors) and the simulation's 3 node vectors.
  const double per_node = 8.0 + 8.0 * D * 10.0;
  const double nodes = static_cast<double>(grid.n_nodes()) * n_fields;

  double particles = 0.0, largest = -1.0;
  std::size_t largest_body = 0;
  std::string largest_text;
  for (std::size_t b = 0; b < config.bodies.size(); ++b) {
    const BodyConfig& body = config.bodies[b];
    std::shared_ptr<const GreyImage> image;
    try {
      image = body_image(body, config);
    } catch (const std::invalid_argument&) {
      // create_particles reports an unreadable image with its key.
    }
    const ShapeBounds<D> bounds = shape_bounds<D>(body.shape, image.get(), grid);
    Vec<D> spacing;
    for (int a = 0; a < D; ++a) spacing[a] = grid.cell_size()[a] / body.particles_per_cell[a];
    const LatticeBox<D> box = lattice_box<D>(bounds, grid, spacing);
    const double n = box.count() * bounds.fill;
    particles += n;
    if (n > largest) {
      largest = n;
      largest_body = b;
      std::string dims;
      for (int a = 0; a < D; ++a)
        dims += fmt::format("{}{}", a ? " x " : "", std::max(0LL, box.hi[a] - box.lo[a] + 1));
      largest_text = fmt::format("body '{}': about {:.3g} particles ({} lattice points in its bounds, "
                                 "particles_per_cell {})",
                                 body.name, n, dims, fmt::join(body.particles_per_cell, " x "));
    }
  }
  const double share = 1.0 / std::max(ranks, 1);  // one rank's part of a distributed run
  const double bytes = share * (particles * per_particle + nodes * per_node);
  const double limit = memory_limit_bytes(config);
  const bool too_many = share * particles > static_cast<double>(INT32_MAX);
  if (bytes <= limit && !too_many) return;

  const std::string limit_text = memory_limit_text(config, limit);
  std::string found = fmt::format(
      "an estimated {:.3g} GiB: {:.3g} particles x {:.0f} bytes (largest {}) and {:.3g} grid "
      "nodes x {} field(s) x {:.0f} bytes (grid.cell_size)",
      bytes / share / gib, particles, per_particle, largest_text, static_cast<double>(grid.n_nodes()), n_fields,
      per_node);
  if (ranks > 1) found += fmt::format(", of which each of the {} MPI ranks holds about 1/{}", ranks, ranks);
  const std::string expected =
      too_many ? fmt::format("at most {} particles{} (particle indices are 32-bit integers)", INT32_MAX,
                             ranks > 1 ? " per MPI rank" : "")
               : fmt::format("a setup that fits {}", limit_text);
  if (!too_many && nodes * per_node >= particles * per_particle)
    throw InputError(config.grid.where.file, config.grid.where.line, "grid.cell_size", expected, found);
  const BodyConfig& body = config.bodies[largest_body];
  throw InputError(body.where.file, body.where.line, fmt::format("body[{}].particles_per_cell", largest_body),
                   expected, found);
}

template <int D>
void check_run_length(const Simulation<D>& sim) {
  const Config& config = sim.config();
  const SimulationConfig& s = config.simulation;
  if (s.max_estimated_steps <= 0.0 || s.max_steps > 0) return;
  const double dt = sim.next_dt();
  const double steps = s.end_time / dt;
  if (steps <= s.max_estimated_steps) return;  // NaN dt falls through to the refusal

  std::string cause;
  if (s.fixed_dt > 0.0) {
    cause = fmt::format("simulation.dt = {:.6g} sets the step", s.fixed_dt);
  } else {
    // dt = cfl h / (c + |v|) (seed 001 Eq. 34): which material's c, or the velocity.
    const Particles<D>& ps = sim.particles();
    std::vector<double> c(sim.materials().size(), 0.0);
    double v = 0.0;
    for (std::size_t p = 0; p < ps.n(); ++p) {
      const auto m = static_cast<std::size_t>(ps.material[p]);
      c[m] = std::max(c[m], damped_signal_speed(sim.materials()[m]->wave_speed(ps.deformation_gradient[p]),
                                                sim.materials()[m]->damping_time(), sim.grid().min_cell_size()));
      v = std::max(v, ps.velocity[p].norm());
    }
    // Over every rank's particles (the same message on every rank).
    c.push_back(v);
    sim.comm().max(c.data(), static_cast<int>(c.size()));
    v = c.back();
    c.pop_back();
    const auto fastest = static_cast<std::size_t>(std::max_element(c.begin(), c.end()) - c.begin());
    const double cfl_dt = s.cfl * sim.grid().min_cell_size() / (c.empty() ? v : c[fastest] + v);
    if (dt < cfl_dt * (1.0 - 1e-9)) {
      cause = "heat conduction ([thermal] conduction = true) sets the step";
    } else if (!c.empty() && !(c[fastest] < v)) {
      const MaterialConfig& m = config.materials[fastest];
      cause = fmt::format("material '{}' ({}) sets it: wave speed {:.6g} (with cfl {:.6g}, cell size {:.6g})",
                          m.name, m.where.str(), c[fastest], s.cfl, sim.grid().min_cell_size());
      if (sim.materials()[fastest]->damping_time() > 0.0)
        cause += " (the signal speed of its damping_time: the wave speed times sqrt(1 + zeta^2) + zeta, "
                 "zeta = damping_time c / h)";
    } else {
      cause = fmt::format("the initial particle speed {:.6g} sets it (bodies' velocity)", v);
    }
  }
  throw InputError(s.where.file, s.where.line, "simulation.end_time",
                   fmt::format("a run of at most simulation.max_estimated_steps = {:.6g} steps "
                               "(end_time / first time step), or max_steps > 0 to stop early",
                               s.max_estimated_steps),
                   fmt::format("end_time {:.6g} / first time step {:.6g} = {:.6g} steps; {}", s.end_time,
                               dt, steps, cause));
}

template <int D>
void check_positions_in_grid(const Grid<D>& grid, const Particles<D>& particles, const std::string& source) {
  const Vec<D> lo = grid.origin(), hi = grid.extent_max();
  for (std::size_t p = 0; p < particles.n(); ++p) {
    const Vec<D>& x = particles.position[p];
    bool ok = Grid<D>::indexable(grid.to_cell_units(x));
    for (int a = 0; a < D && ok; ++a) {
      if (grid.periodic(a)) continue;  // positions are not wrapped into a periodic axis
      const double reach = grid.ghost_layers() * grid.cell_size()[a];
      ok = x[a] >= lo[a] - reach && x[a] <= hi[a] + reach;
    }
    if (ok) continue;
    throw InputError(source, 0, fmt::format("/particles/position[{}]", p),
                     fmt::format("a finite position inside the grid {}..{} (with its ghost layers)",
                                 point_text<D>(lo), point_text<D>(hi)),
                     point_text<D>(x) + " (a damaged or edited checkpoint)");
  }
}

#define CAIRN_RESOURCES(D)                                                                          \
  template ShapeBounds<D> shape_bounds<D>(const BodyShapeConfig&, const GreyImage*, const Grid<D>&);  \
  template LatticeBox<D> lattice_box<D>(const ShapeBounds<D>&, const Grid<D>&, const Vec<D>&);       \
  template void check_inside_grid<D>(const BodyConfig&, std::size_t, const ShapeBounds<D>&,          \
                                     const Grid<D>&, const Vec<D>&);                                 \
  template void check_memory<D>(const Config&, const Grid<D>&, int, int, int, int);                  \
  template void check_run_length<D>(const Simulation<D>&);                                          \
  template void check_positions_in_grid<D>(const Grid<D>&, const Particles<D>&, const std::string&);
CAIRN_RESOURCES(1)
CAIRN_RESOURCES(2)
CAIRN_RESOURCES(3)
#undef CAIRN_RESOURCES

}  // namespace cairn
