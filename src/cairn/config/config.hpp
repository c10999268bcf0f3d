// The validated, resolved input of one simulation. Filled only by load_config() (input/input.hpp),
// which has checked every key against its declaration; the rest of Cairn trusts these values.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cairn/config/plugin_keys.hpp"
#include "cairn/math/types.hpp"

namespace cairn {

/// Where a value came from, for error messages raised after validation (e.g. a body that
/// produced no particle): "file.toml:12" or "--set method.order".
struct SourceLocation {
  std::string file;
  int line = 0;
  [[nodiscard]] std::string str() const {
    return line > 0 ? file + ":" + std::to_string(line) : file;
  }
};

struct SimulationConfig {
  std::string title;
  int dimension = 2;
  Mode mode = Mode::plane_strain;
  double end_time = 0.0;
  double cfl = 0.5;       ///< dt = cfl * h_min / (c_max + max|V|)  (seed 001 Eq. 34)
  double fixed_dt = 0.0;  ///< > 0: use this time step instead of the CFL rule
  /// adaptive: cfl h / (c_max + max|V|) every step (seed 001 Eq. 34); nominal: cfl h / c_max of
  /// the undeformed materials, fixed for the run (Eq. 35).
  std::string time_step = "adaptive";
  long long max_steps = 0;  ///< 0: no limit
  double thickness = 1.0;   ///< out-of-plane thickness in 2D; cross-section area in 1D
  int threads = 0;          ///< 0: OpenMP default
  bool adapt_threads = true;  ///< pick all threads or one from measured step times
  bool sort_particles = true;  ///< keep large runs' particles in memory in cell-block order
  std::string units = "SI"; ///< declared unit system (labels the output; config/units.hpp)
  double memory_limit = 0.0;  ///< GiB the setup may need; 0: the machine's memory
  double rebalance_threshold = 0.25;  ///< MPI: repartition when max/mean particles - 1 exceeds it
  double max_estimated_steps = 1e8;  ///< refuse end_time / first dt above this; 0: no check
  double mpi_timeout = 300.0;  ///< MPI: s without a completed step before the run stops; 0: never
  std::string body_overlap = "error";  ///< bodies sharing space: error | warn
  SourceLocation where;     ///< the [simulation] table (end_time's line when given)
};

/// [parallel]: how a run on several MPI ranks shares its grid (docs/parallel.md).
struct ParallelConfig {
  /// nodes: each rank scatters its own particles and node sums are exchanged across a halo one
  /// stencil wide; particles: ghost copies of the neighbours' particles, node sums in serial
  /// order (bit-identical to a serial run); auto: nodes.
  std::string halo = "auto";
  /// What the bisection balances: count = particles per rank; cost = the particles' measured
  /// cost per step (their material model's, or the material's balance_cost).
  std::string balance = "count";
};

struct GridConfig {
  std::vector<double> origin;     ///< D values
  std::vector<double> extent;     ///< D values: domain size
  std::vector<double> cell_size;  ///< D values (one given value is repeated)
  SourceLocation where;           ///< of grid.cell_size
};

struct MethodConfig {
  std::string shape = "bspline2";
  std::string update = "flip";
  int order = 1;
  std::string stress_update = "usl";
  std::string position_update = "scheme";  ///< scheme | updated: X += S v+ dt (docs/update-schemes.md)
  double grid_damping = 0.0;      ///< alpha_g (seed 002 Eq. 1.83)
  double particle_damping = 0.0;  ///< alpha_p (seed 002 Eq. 1.83)
  double full_mass_cfl = 0.0;     ///< periodic FMPM/XPIC CFL_X; 0 = every step
  std::string velocity_bc_method = "constrained";  ///< FMPM/XPIC velocity conditions: velocity|lumped|combined|constrained
  std::string time_integration = "forward_euler";  ///< or central_difference
  /// mpm: integrate at the particles (every shape family and update); wls: the weighted-least-
  /// squares PIC method of seed 001 (src/cairn/wls, docs/wls.md).
  std::string integration = "mpm";
  /// The [method] keys of shape families, schemes and the WLS method (smoothing_length,
  /// cpdi_max_span, beta, blend_position, trigger_weight, ...), declared beside them.
  PluginValues plugin;
};

/// A material's parameters after validation against the model's declared keys (defaults filled).
struct MaterialConfig {
  std::string name;
  std::string model;
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> strings;
  SourceLocation where;
  [[nodiscard]] bool has(const std::string& key) const { return numbers.count(key) != 0; }
  [[nodiscard]] double number(const std::string& key) const { return numbers.at(key); }
};

struct GreyImage;  // geometry/image.hpp
namespace geometry {
class SurfaceMesh;  // geometry/surface_mesh.hpp
struct PointSet;    // geometry/point_set.hpp
}  // namespace geometry

struct BodyShapeConfig {
  std::string kind;  ///< box | circle | ellipse | annulus | polygon | sphere | cylinder | image | image_stack | mesh | volume_mesh | points | outline
  std::vector<double> min, max;         ///< box
  std::vector<double> center;           ///< circle, ellipse, annulus, sphere, cylinder
  double radius = 0.0;                  ///< circle, sphere, cylinder
  double height = 0.0;                  ///< cylinder (3D, axis along +z from center)
  std::vector<double> semi_axes;        ///< ellipse (2D) / ellipsoid (3D)
  double inner_radius = 0.0, outer_radius = 0.0;  ///< annulus
  std::vector<std::vector<double>> vertices;      ///< polygon (2D)
  /// image (2D): PNG file (absolute once loaded; relative = to the input file's directory),
  /// square pixel edge, physical position of the picture's lower-left corner, and the grey
  /// levels [level_min, level_max] (0..255) that belong to the body.
  std::string file;
  double pixel_size = 0.0;
  std::vector<double> origin;
  int level_min = 0, level_max = 255;
  /// image_stack (3D): `file` is the folder of the slices, `pattern` the glob their names match
  /// (geometry/image.hpp); slice k (in the order of the numbers in the names) covers
  /// z in [origin_z + k slice_spacing, origin_z + (k + 1) slice_spacing).
  std::string pattern;
  double slice_spacing = 0.0;
  /// image, image_stack: the pixels (voxels), read once by the loader and shared by bodies naming
  /// the same file (folder and pattern); null when the Config was built in code (bodies.cpp then
  /// reads `file`).
  std::shared_ptr<const GreyImage> image;
  /// mesh (3D): a closed triangle surface (STL, OBJ, PLY, OFF) in `file`, placed by x = R (s x_file) + t
  /// with s = scale times the file's unit in the model's length unit, R the rotation by the Euler
  /// angles `rotate` (degrees, about x, then y, then z) and t = `translate` (docs/geometry.md).
  double scale = 1.0;
  std::vector<double> rotate, translate;
  std::string units;
  /// mesh: the checked surface and its inside test, read by the loader (null in a Config built in code).
  std::shared_ptr<const geometry::SurfaceMesh> mesh;
  /// volume_mesh / points: particles given one by one (position, volume, optional fields), read by the
  /// loader from a Gmsh mesh (`quadrature` points per element) or a CSV/HDF5 point file.
  int quadrature = 1;
  std::shared_ptr<const geometry::PointSet> points;
  /// outline (2D): closed loops, the first the outside and the others holes (even-odd rule), from a
  /// CSV file, or the cut of the plane z = slice_z through a surface mesh file.
  std::vector<std::vector<std::vector<double>>> loops;
  double slice_z = 0.0;
};

struct BodyConfig {
  std::string name;
  std::string material;  ///< name of a [[material]]
  BodyShapeConfig shape;
  std::vector<int> particles_per_cell;  ///< per direction, D values (one given value is repeated)
  std::vector<std::string> velocity;    ///< D expressions in X,Y,Z (numbers are expressions too)
  std::vector<std::string> displacement;  ///< D expressions in X,Y,Z; empty = none
  std::string arrangement = "cartesian";  ///< cartesian lattice | radial (seed 001 Fig. 4b)
  bool clip = false;  ///< keep the part of the shape inside the grid; false: past the grid is an error
  SourceLocation where;
};

enum class FaceCondition { free, fixed, symmetry, periodic };
enum class BoundaryAcceleration { zero, velocity_change };

struct BoundaryConfig {
  /// Index 2*axis + side (side 0 = min face, 1 = max face).
  std::array<FaceCondition, 6> face{FaceCondition::free, FaceCondition::free, FaceCondition::free,
                                    FaceCondition::free, FaceCondition::free, FaceCondition::free};
  /// Acceleration seen by the particle update at constrained nodes: zero (both grid velocities
  /// constrained) or from the velocity change (seed 003 Eq. 30).
  BoundaryAcceleration acceleration = BoundaryAcceleration::zero;
};

struct BodyForceConfig {
  std::vector<std::string> expression;  ///< D expressions in x,y,z,X,Y,Z,t; empty = no body force
};

/// Piecewise-linear factor of time: (t, value) points with increasing t, constant beyond the
/// ends; empty means 1 (docs/boundary-conditions.md).
using TimeTable = std::vector<std::pair<double, double>>;

/// [[traction]]: a traction on the exposed faces of particles (seed 000 Sec. 2.4, first equation).
struct TractionConfig {
  std::string name;
  std::string body;                      ///< "" = every body
  int side = -1;                         ///< face 2*axis + (0 min, 1 max); -1 = any exposed face
  std::vector<double> box_min, box_max;  ///< D values each, or empty (no box)
  std::vector<double> traction;          ///< D values: force per current face area
  std::string scale = "1";               ///< time factor: expression in t
  TimeTable table;                       ///< further time factor; empty = 1
  SourceLocation where;
};

/// [[velocity]]: a grid velocity condition on a node set (seed 000 Sec. 2.4, Eq. 3).
struct VelocityConditionConfig {
  std::string name;
  int face = -1;                         ///< 2*axis + side of a grid face; -1 = none
  std::vector<double> box_min, box_max;  ///< D values each, or empty
  int plane_axis = -1;                   ///< nodes on the plane x_axis = plane_at; -1 = none
  double plane_at = 0.0;
  std::vector<double> direction;         ///< D values, unit length
  std::string velocity = "0";            ///< value along direction: expression in t
  TimeTable table;                       ///< factor of velocity; empty = 1
  SourceLocation where;
};

enum class WallGradient { zero, given, estimate };

/// [[wall]]: a moving wall normal to an axis (seed 000 Sec. 2.5, Eq. 4, Fig. 1B).
struct WallConfig {
  std::string name;
  int axis = 0;
  bool inside_below = true;       ///< the material lies at coordinates below the wall
  double position = 0.0;          ///< wall position at t = 0
  std::string velocity = "0";     ///< v_b(t) along the axis: expression in t
  TimeTable table;                ///< factor of velocity; empty = 1
  WallGradient gradient = WallGradient::zero;
  std::string gradient_expression = "0";  ///< given gradient: expression in t
  double depth = 1.0;             ///< d, in cells along the axis
  SourceLocation where;
};

/// Heat conduction (thermal/conduction.hpp). Faces: index 2*axis + side.
enum class ThermalFace : std::uint8_t { adiabatic, temperature, flux };
struct ThermalConfig {
  bool conduction = false;
  std::array<ThermalFace, 6> face{};  ///< adiabatic by default
  std::array<double, 6> value{};      ///< fixed temperature, or heat flux per area into the body
};

/// Multimaterial contact (docs/contact.md, seed 004). mode "none" keeps the single velocity field.
struct ContactLawConfig {
  std::string law = "frictionless";  ///< a ContactLaw registry name (contact/law.hpp)
  PluginValues plugin;  ///< the laws' own keys (friction, dynamic_friction, slide), declared beside them
};
struct ContactPairConfig {
  std::string first, second;  ///< field names (materials or bodies by [contact] mode)
  ContactLawConfig law;
  SourceLocation where;
};
struct ContactConfig {
  std::string mode = "none";        ///< none | material | body
  ContactLawConfig law;             ///< default law of every pair
  std::string normal = "lr";        ///< lr | linear | ag | specified
  std::vector<double> normal_direction;  ///< specified: from the first field to the second
  std::string lr_weights = "shape"; ///< lr/linear point weights: shape (S_ip) | uniform (seed 004 Appendix)
  std::string lr_refine = "margin"; ///< lr/linear: margin (max-margin normal when separable) | none
  std::string first_correction = "extrapolation";  ///< extrapolation (Eq. 34) | impulse (contact changes reach the particles)
  std::string detection = "lr";     ///< lr | velocity | cp | df
  double critical_separation = 0.8; ///< cp: delta_c in cells (seed 004 Eq. 16)
  double touching_tolerance = 1e-3; ///< lr/df: touching when the separation < this many cells
  std::string lr_separation = "cloud";  ///< lr detection edges: cloud (Eq. 22-24) | column (the node's column)
  std::string release = "gap";      ///< gap (both tests every step, seed 004) | separation (in contact until the fields separate)
  std::string corrections = "twice";///< twice | once (seed 004 Sec. 3.2)
  std::string three_or_more = "lump";  ///< lump (Eq. 50) | pairs
  bool xpic_correction = true;      ///< the Delta v term of multimaterial XPIC/FMPM (Eq. 37)
  SourceLocation where;
  std::vector<ContactPairConfig> pairs;  ///< [[contact_pair]]
  [[nodiscard]] bool enabled() const { return mode != "none"; }
};

/// [fem]: the reference explicit FEM of seed 001 Appendix A (docs/fem.md). When enabled the run
/// has no grid and no particles: [grid] and [[body]] are absent and the mesh is the body.
struct FemConfig {
  bool enabled = false;
  std::string material;             ///< name of a [[material]]
  std::string mesh_file;            ///< Gmsh .msh file (absolute once loaded); "" = generate from shape
  BodyShapeConfig shape;            ///< generated mesh: box | circle | ellipse | annulus | polygon
  std::vector<double> hole_center;  ///< D values: circular hole cut from the shape; empty = none
  double hole_radius = 0.0;
  double size = 0.0;                ///< characteristic element size of generated meshes
  std::string mesher = "gmsh";      ///< gmsh | structured
  std::vector<std::string> velocity;      ///< D expressions in X,Y: initial velocity
  std::vector<std::string> displacement;  ///< D expressions in X,Y; empty = none
  /// D expressions in X,Y,t: an exact displacement; history.csv then gets the node error of
  /// seed 001 Eq. 38 every step (displacement_error, and its maximum over all steps so far).
  std::vector<std::string> exact_displacement;
  SourceLocation where;
};

struct OutputConfig {
  std::string directory;        ///< default out/<input file stem>
  double every = 0.0;           ///< snapshot interval in time; 0 = first and last only
  double history_every = 0.0;   ///< history interval; 0 = same as `every`
  double checkpoint_every = 0.0;///< checkpoint interval; 0 = only at the end
  bool snapshots = true;        ///< write HDF5/XDMF particle snapshots
  bool grid_snapshots = false;  ///< also write node fields
  bool checkpoints = true;
  /// D expressions of the exact displacement u(X, t) (manufactured solutions); empty = none.
  std::vector<std::string> exact_displacement;
  double checkpoint_wall_interval = 1800.0;  ///< wall-clock seconds between checkpoints; 0 = off
  int compression = 0;          ///< gzip level 0-9 of large HDF5 datasets; 0 = off
  /// An earlier run's numbered files in the folder of a new run: "remove", "keep" or "error".
  std::string existing = "remove";
};

struct Config {
  std::string source_file;  ///< path of the input file ("" if built in code)
  std::string resolved_toml;///< the fully resolved input (defaults filled, overrides applied)
  SimulationConfig simulation;
  ParallelConfig parallel;
  GridConfig grid;
  MethodConfig method;
  std::vector<MaterialConfig> materials;
  std::vector<BodyConfig> bodies;
  BoundaryConfig boundary;
  BodyForceConfig body_force;
  std::vector<TractionConfig> tractions;                   ///< [[traction]]
  std::vector<VelocityConditionConfig> velocity_conditions;///< [[velocity]]
  std::vector<WallConfig> walls;                           ///< [[wall]]
  std::vector<std::pair<std::string, double>> constants;  ///< [constants]: names usable in expressions
  ThermalConfig thermal;
  ContactConfig contact;
  FemConfig fem;
  OutputConfig output;
  /// Values that are valid but suspicious (e.g. a density of 1e308), one message each with file,
  /// line and key; the CLI prints them.
  std::vector<std::string> warnings;
};

}  // namespace cairn
