// The single list of input-key declarations, and the key reference generated from it
// (`cairn keys`, docs/input.md).
#include "cairn/io/schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "cairn/geometry/shape_keys.hpp"
#include "cairn/io/units.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/sim/names.hpp"

namespace cairn {

namespace {

std::vector<std::string> face_conditions() { return {"free", "fixed", "symmetry", "periodic"}; }
std::vector<std::string> boundary_acceleration_names() { return {"zero", "velocity_change"}; }
std::vector<std::string> face_names_list() { return {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"}; }
std::vector<std::string> axis_names() { return {"x", "y", "z"}; }
std::vector<std::string> mode_names() { return {"plane_strain", "plane_stress", "3d", "uniaxial"}; }

/// Fluent construction of a KeyDecl (designated initializers that skip members warn under -Wextra).
class Key {
 public:
  Key(std::string section, std::string name, KeyType type, std::string doc) {
    decl_.section = std::move(section);
    decl_.name = std::move(name);
    decl_.type = type;
    decl_.doc = std::move(doc);
  }
  Key& by_default(std::string toml_text) {
    decl_.default_value = std::move(toml_text);
    return *this;
  }
  Key& required() {
    decl_.required = true;
    return *this;
  }
  Key& min(double v) {
    decl_.min = v;
    return *this;
  }
  Key& max(double v) {
    decl_.max = v;
    return *this;
  }
  Key& choices(std::function<std::vector<std::string>()> f) {
    decl_.choices = std::move(f);
    return *this;
  }
  operator KeyDecl() const { return decl_; }  // NOLINT(google-explicit-constructor)

 private:
  KeyDecl decl_;
};

std::vector<KeyDecl> make_declarations() {
  using T = KeyType;
  std::vector<KeyDecl> k;
  // [simulation]
  k.push_back(Key("simulation", "title", T::string,
                 "Free-text title, copied into the output metadata.")
                .by_default("\"\""));
  k.push_back(Key("simulation", "dimension", T::integer,
                 "Spatial dimension D of the grid, the particles and every vector key.")
                .required()
                .min(1)
                .max(3));
  k.push_back(Key("simulation", "mode", T::string,
                 "Out-of-plane kinematics; must match the dimension: uniaxial (strain) in 1D, "
                 "plane_strain or plane_stress in 2D, 3d in 3D.")
                .choices(mode_names));
  k.push_back(Key("simulation", "end_time", T::real,
                 "Simulated time at which the run stops.")
                .required()
                .min(above_zero));
  k.push_back(Key("simulation", "cfl", T::real,
                 "Courant number: dt = cfl * h_min / (c_max + max|v|). FMPM(k) needs less (about "
                 "0.6 / sqrt(k); docs/update-schemes.md).")
                .by_default("0.5")
                .min(above_zero)
                .max(2.0));
  k.push_back(Key("simulation", "dt", T::real,
                 "Fixed time step; 0 = use the CFL rule.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("simulation", "time_step", T::string,
                 "CFL rule of the time step (without simulation.dt): adaptive = cfl h_min / "
                 "(c_max + max|v|) every step (seed 001 Eq. 34); nominal = cfl h_min / c_max with "
                 "the wave speeds of the undeformed materials, fixed for the run (Eq. 35).")
                .by_default("\"adaptive\"")
                .choices([] { return std::vector<std::string>{"adaptive", "nominal"}; }));
  k.push_back(Key("simulation", "max_steps", T::integer,
                 "Stop after this many steps; 0 = no limit.")
                .by_default("0")
                .min(0));
  k.push_back(Key("simulation", "thickness", T::real,
                 "Out-of-plane thickness in 2D, cross-section area in 1D; unused in 3D.")
                .by_default("1.0")
                .min(above_zero));
  k.push_back(Key("simulation", "threads", T::integer,
                 "OpenMP threads, at most 1024; 0 = the command line's -t, else OMP_NUM_THREADS, "
                 "else all cores up to the CPU limit of the process's control group (a container's "
                 "CPU quota).")
                .by_default("0")
                .min(0)
                .max(1024));
  k.push_back(Key("simulation", "adapt_threads", T::boolean,
                 "Between steps, time the step with all threads and, now and then, with one, and "
                 "run with the faster (a busy machine makes a team of threads slower than one "
                 "thread); results do not depend on the thread count. false: always all threads.")
                .by_default("true"));
  k.push_back(Key("simulation", "sort_particles", T::boolean,
                 "Keep the particles of a run of 32768 or more particles in memory in the order "
                 "of the grid's cell blocks, sorted again when they have moved out of it (the "
                 "particle-to-grid transfers then read memory in order; docs/performance.md). "
                 "Results are bit-identical either way and output lists particles in id order. "
                 "Runs on one MPI rank only.")
                .by_default("true"));
  k.push_back(Key("simulation", "rebalance_threshold", T::real,
                 "Runs on several MPI ranks (docs/parallel.md): repartition the domain when the "
                 "largest particle count of a rank exceeds the mean count by more than this "
                 "fraction (history column `imbalance` = largest / mean); checked every step. A "
                 "large value (e.g. 1e9) keeps the start-up partition. Unused on one rank.")
                .by_default("0.25")
                .min(0.0));
  k.push_back(Key("simulation", "memory_limit", T::real,
                 "GiB of memory the setup may need (grid nodes, particles, transfer caches, "
                 "estimated before anything is allocated); 0 = the machine's memory (its cgroup "
                 "limit when lower). A larger estimate is refused, naming the keys that drive it.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("simulation", "max_estimated_steps", T::real,
                 "Refuse a run whose end_time / first time step exceeds this (a run that would "
                 "never end), naming the material that sets the step; 0 = no check. Not checked "
                 "when max_steps > 0.")
                .by_default("1e8")
                .min(0.0));
  k.push_back(Key("simulation", "body_overlap", T::string,
                 "Bodies whose shapes share space (their mass counts twice there): error refuses "
                 "the input, warn prints a warning naming both and runs.")
                .by_default("\"error\"")
                .choices([] { return std::vector<std::string>{"error", "warn"}; }));
  k.push_back(Key("simulation", "units", T::string,
                 "Unit system the input's numbers are in. Cairn computes in any consistent set; "
                 "this labels the output files (SI: m kg s, derived N Pa J; mm_t_s: mm tonne s, "
                 "N MPa mJ; mm_kg_ms: mm kg ms, kN GPa J; cgs: cm g s, dyn Ba erg; unspecified: "
                 "dimensions only).")
                .by_default("\"SI\"")
                .choices(unit_system_names));

  // [grid]
  k.push_back(Key("grid", "origin", T::real_array,
                 "Lower corner of the grid, one coordinate per axis.")
                .required());
  k.push_back(Key("grid", "extent", T::real_array,
                 "Size of the grid along each axis.")
                .required()
                .min(above_zero));
  k.push_back(Key("grid", "cell_size", T::real_array,
                 "Cell size, one value for every axis or one per axis; extent / cell_size "
                 "must be a whole number of cells on every axis.")
                .required()
                .min(above_zero));

  // [method]
  k.push_back(Key("method", "shape", T::string,
                 "Shape-function (basis) family.")
                .by_default("\"bspline2\"")
                .choices(shape_family_names));
  k.push_back(Key("method", "update", T::string,
                 "Particle velocity and position update scheme.")
                .by_default("\"flip\"")
                .choices(update_scheme_names));
  k.push_back(Key("method", "order", T::integer,
                 "Order k of FMPM(k) and XPIC(k); unused by other updates.")
                .by_default("1")
                .min(1)
                .max(64));
  k.push_back(Key("method", "stress_update", T::string,
                 "When in the step the stress is updated.")
                .by_default("\"usl\"")
                .choices(stress_update_names));
  k.push_back(Key("method", "smoothing_length", T::real,
                 "uGIMP smoothing length l (full width of the particle function); 0 = the "
                 "initial particle size. At most twice the smallest cell size.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("method", "cpdi_max_span", T::real,
                 "CPDI/B2CPDI guard: a particle whose deformed domain spans more than this many "
                 "cells along an axis uses the GIMP weights of its undeformed box for that step.")
                .by_default("2.0")
                .min(above_zero));
  k.push_back(Key("method", "beta", T::real,
                 "FLIP fraction beta of the `blend` update (seed 002 Eq. 1.79).")
                .by_default("0.99")
                .min(0.0)
                .max(1.0));
  k.push_back(Key("method", "blend_position", T::string,
                 "Effective velocity of the `blend` update: grid = S v, projected = "
                 "beta S v + (1 - beta) P V (seed 002 Eq. 1.80).")
                .by_default("\"grid\"")
                .choices([] { return std::vector<std::string>{"grid", "projected"}; }));
  k.push_back(Key("method", "position_update", T::string,
                 "Particle position update: scheme = the update's own (second order for FLIP and "
                 "XPIC, X += (S v + S v+) dt/2 for FLIP); updated = X += S v+ dt, the grid velocity "
                 "whose gradient USL uses for F (seed 002 Eq. 1.60-1.61 for every update; stable "
                 "under strong compression, docs/update-schemes.md).")
                .by_default("\"scheme\"")
                .choices([] { return std::vector<std::string>{"scheme", "updated"}; }));
  k.push_back(Key("method", "grid_damping", T::real,
                 "Grid damping alpha_g in 1/time (seed 002 Eq. 1.83).")
                .by_default("0.0"));
  k.push_back(Key("method", "particle_damping", T::real,
                 "Particle damping alpha_p in 1/time (seed 002 Eq. 1.83).")
                .by_default("0.0"));
  k.push_back(Key("method", "full_mass_cfl", T::real,
                 "Periodic FMPM/XPIC: full-mass steps only every CFL_X h / c of time, FLIP "
                 "steps between (seed 000 Sec. 3.1); 0 = every step.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("method", "velocity_bc_method", T::string,
                 "How FMPM/XPIC impose grid velocity conditions: velocity, lumped or combined "
                 "(seed 000 Sec. 2.4), or constrained (conditions imposed after every term of the "
                 "expansion; same as combined for k <= 2, stays stable at held faces for any k "
                 "where combined grows; docs/boundary-conditions.md).")
                .by_default("\"constrained\"")
                .choices([] { return std::vector<std::string>{"velocity", "lumped", "combined", "constrained"}; }));
  k.push_back(Key("method", "time_integration", T::string,
                 "forward_euler (seed 003 Eq. 6-10) or central_difference: velocities at half "
                 "steps, started by half the first acceleration (seed 003 Eq. 11-15, seed 001 "
                 "Sec. 4.7).")
                .by_default("\"forward_euler\"")
                .choices([] { return std::vector<std::string>{"forward_euler", "central_difference"}; }));
  k.push_back(Key("method", "integration", T::string,
                 "Where the weak form is integrated: mpm = at the particles (every shape family and "
                 "update above); wls = the weighted-least-squares PIC method of seed 001 (node "
                 "fits, cut grid cells with one centroid point per region, central differences; "
                 "shape, update, order and stress_update are then unused; docs/wls.md).")
                .by_default("\"mpm\"")
                .choices([] { return std::vector<std::string>{"mpm", "wls"}; }));
  k.push_back(Key("method", "trigger_weight", T::real,
                 "WLS trigger weight TW (seed 001 Sec. 3.5): a node whose particles all have a "
                 "wide weight W below TW is spurious (constant fit, averaged internal force).")
                .by_default("0.12")
                .min(above_zero)
                .max(1.0));
  k.push_back(Key("method", "surface_distance", T::string,
                 "WLS signed distance of near-surface nodes (seed 001 Sec. 3.3): projection of "
                 "x_surf - x_i on the unit normal (the text) or distance |x_surf - x_i| with the "
                 "normal's sign (Eq. 17 as printed).")
                .by_default("\"distance\"")
                .choices([] { return std::vector<std::string>{"projection", "distance"}; }));
  k.push_back(Key("method", "spurious_force", T::string,
                 "WLS internal force of spurious nodes (seed 001 Sec. 4.5): per_mass = the node "
                 "mass times the mean f_int / m of its well-conditioned neighbours; force = the "
                 "mean f_int of those neighbours (docs/wls.md).")
                .by_default("\"per_mass\"")
                .choices([] { return std::vector<std::string>{"per_mass", "force"}; }));
  k.push_back(Key("method", "velocity_gradient", T::string,
                 "WLS particle velocity gradient: quadrature = the gradients at the integration "
                 "points (the strain rate conjugate to Eq. 24), averaged to the nodes and "
                 "interpolated with S; narrow = sum v_i (x) G_ip (seed 001 Eq. 29 as printed, "
                 "unstable at free surfaces in our runs; docs/wls.md).")
                .by_default("\"quadrature\"")
                .choices([] { return std::vector<std::string>{"quadrature", "narrow"}; }));
  k.push_back(Key("method", "filter_acceleration", T::boolean,
                 "WLS: replace each node's velocity increment a dt by the planar least-squares "
                 "fit over it and its neighbours with mass (weights W m), so linear fields pass "
                 "and the node-to-node zig-zag of small cut cells does not (docs/wls.md; not "
                 "energy conserving); false = seed 001 as printed.")
                .by_default("false"));

  // [[material]] (the model's own keys come from material_model_info())
  k.push_back(Key("material", "name", T::string,
                 "Unique name, referenced by [[body]] material.")
                .required());
  k.push_back(Key("material", "model", T::string,
                 "Constitutive model.")
                .required()
                .choices(material_model_names));
  k.push_back(Key("material", "density", T::real,
                 "Reference mass density rho_0.")
                .required()
                .min(above_zero));
  k.push_back(Key("material", "conductivity", T::real,
                 "Thermal conductivity k (used when [thermal] conduction = true).")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("material", "heat_capacity", T::real,
                 "Heat capacity per unit mass c_p (conduction; heating by plastic and viscous work).")
                .by_default("0.0")
                .min(0.0));

  // [[body]]
  k.push_back(Key("body", "name", T::string,
                 "Unique name used in output; default body<N> for the N-th [[body]] (from 0)."));
  k.push_back(Key("body", "material", T::string,
                 "Name of a [[material]].")
                .required());
  k.push_back(Key("body", "shape", T::table,
                 "Region filled with particles: an inline table with exactly one shape kind.")
                .required());
  k.push_back(Key("body", "particles_per_cell", T::integer_array,
                 "Particles per cell along each axis, one value for every axis or one per axis.")
                .by_default("2")
                .min(1)
                .max(16));
  k.push_back(Key("body", "velocity", T::expression_array,
                 "Initial velocity, one entry per axis: numbers or expressions in X, Y, Z "
                 "(reference position) and [constants], evaluated once (no t); default zeros."));
  k.push_back(Key("body", "displacement", T::expression_array,
                 "Initial displacement field, entries as for velocity (F is set from its "
                 "gradient); default none."));
  k.push_back(Key("body", "clip", T::boolean,
                 "Keep only the part of the shape inside the grid; false: a shape reaching past "
                 "the grid (by half a particle spacing or more) is an error.")
                .by_default("false"));

  k.push_back(Key("body", "arrangement", T::string,
                 "Particle placement: cartesian = the lattice of particles_per_cell; radial = "
                 "concentric rings (2D) or shells (3D) about h / particles_per_cell apart, for "
                 "circle, annulus and sphere shapes (seed 001 Fig. 4b). Under method.integration = "
                 "\"wls\" every body also gets zero-volume surface particles.")
                .by_default("\"cartesian\"")
                .choices([] { return std::vector<std::string>{"cartesian", "radial"}; }));

  // [[body]] shape kinds
  k.push_back(Key("body.shape.box", "min", T::real_array,
                 "Lower corner, one coordinate per axis.")
                .required());
  k.push_back(Key("body.shape.box", "max", T::real_array,
                 "Upper corner, one coordinate per axis, each above min.")
                .required());
  k.push_back(Key("body.shape.circle", "center", T::real_array,
                 "Centre [x, y].")
                .required());
  k.push_back(Key("body.shape.circle", "radius", T::real,
                 "Radius.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.ellipse", "center", T::real_array,
                 "Centre, one coordinate per axis.")
                .required());
  k.push_back(Key("body.shape.ellipse", "semi_axes", T::real_array,
                 "Semi-axes along x, y (and z), one per axis.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.annulus", "center", T::real_array,
                 "Centre [x, y].")
                .required());
  k.push_back(Key("body.shape.annulus", "inner_radius", T::real,
                 "Inner radius, below outer_radius.")
                .required()
                .min(0.0));
  k.push_back(Key("body.shape.annulus", "outer_radius", T::real,
                 "Outer radius.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.polygon", "vertices", T::real_array,
                 "At least 3 vertices [[x, y], ...] in order around a simple polygon.")
                .required());
  k.push_back(Key("body.shape.sphere", "center", T::real_array,
                 "Centre [x, y, z].")
                .required());
  k.push_back(Key("body.shape.sphere", "radius", T::real,
                 "Radius.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.cylinder", "center", T::real_array,
                 "Centre [x, y, z] of the bottom face; the axis points along +z.")
                .required());
  k.push_back(Key("body.shape.cylinder", "radius", T::real,
                 "Radius.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.cylinder", "height", T::real,
                 "Length along z.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.image", "file", T::string,
                 "PNG picture, relative to the directory of the input file (any PNG: colour "
                 "becomes grey luma 0.2126 R + 0.7152 G + 0.0722 B, 16 bits become 8, alpha "
                 "is ignored).")
                .required());
  k.push_back(Key("body.shape.image", "pixel_size", T::real,
                 "Edge of one (square) pixel in length units.")
                .required()
                .min(above_zero));
  k.push_back(Key("body.shape.image", "origin", T::real_array,
                 "Position [x, y] of the picture's lower-left corner: the picture covers "
                 "width * pixel_size by height * pixel_size from there, its first (top) row at "
                 "the highest y.")
                .by_default("[0.0, 0.0]"));
  k.push_back(Key("body.shape.image", "levels", T::integer_array,
                 "Grey levels [lo, hi] (0 = black, 255 = white), lo <= hi: a particle position "
                 "belongs to the body when the pixel under it has a level in lo..hi.")
                .required()
                .min(0)
                .max(255));
  // Shapes read from files, declared beside their readers (geometry/shape_keys.cpp).
  for (KeyDecl& d : geometry::shape_keys()) k.push_back(std::move(d));

  // [boundary]
  const char* faces[] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  for (int i = 0; i < 6; ++i) {
    const std::string axis(1, faces[i][0]);
    const std::string side = i % 2 == 0 ? "lower" : "upper";
    std::string doc = fmt::format("Condition on the {} {} face of the grid.", side, axis);
    if (i >= 2) doc += fmt::format(" Only when dimension >= {}.", i / 2 + 1);
    k.push_back(Key("boundary", faces[i], T::string,
                 doc)
                .by_default("\"free\"")
                .choices(face_conditions));
  }
  k.push_back(Key("boundary", "acceleration", T::string,
                 "Acceleration at nodes held by fixed and symmetry faces: zero (both grid "
                 "velocities held) or velocity_change (seed 003 Eq. 30: from the projected "
                 "velocity to the held one).")
                .by_default("\"zero\"")
                .choices(boundary_acceleration_names));

  // [thermal]
  k.push_back(Key("thermal", "conduction", T::boolean,
                 "Explicit heat conduction on the grid, coupled with particle temperatures; its "
                 "stability limit h^2 / (2 D kappa) joins the time step (docs/thermal.md).")
                .by_default("false"));
  for (int i = 0; i < 6; ++i) {
    k.push_back(Key("thermal", faces[i], T::string,
                   fmt::format("Thermal condition on the {} face: adiabatic, temperature (held at "
                               "{}_value) or flux ({}_value per unit area into the body).",
                               faces[i], faces[i], faces[i]))
                  .by_default("\"adiabatic\"")
                  .choices([] { return std::vector<std::string>{"adiabatic", "temperature", "flux"}; }));
    k.push_back(Key("thermal", std::string(faces[i]) + "_value", T::real,
                   fmt::format("Temperature or heat flux of the {} face.", faces[i]))
                  .by_default("0.0"));
  }


  // [contact] and [[contact_pair]] (seed 004, docs/contact.md)
  k.push_back(Key("contact", "mode", T::string,
                 "Multimaterial mode (seed 004 Eq. 5-6): none (one velocity field), material (one "
                 "field per [[material]]) or body (one field per [[body]]). Nodes that see two or "
                 "more fields are contact nodes.")
                .by_default("\"none\"")
                .choices([] { return std::vector<std::string>{"none", "material", "body"}; }));
  for (const char* section : {"contact", "contact_pair"}) {
    const bool pair = std::string(section) == "contact_pair";
    auto law = Key(section, "law", T::string,
                   pair ? "Contact law of this pair (see [contact] law)."
                        : "Default contact law of every pair (seed 004 Eq. 7-10): perfect (bonded, no "
                          "detection), stick, frictionless, coulomb or general.");
    if (!pair) law.by_default("\"frictionless\"");
    k.push_back(law.choices(contact_law_names));
    k.push_back(Key(section, "friction", T::real,
                   "Coulomb friction coefficient (static: the interface sticks while the tangential "
                   "force needed is at most friction times the normal force).")
                  .by_default("0.0")
                  .min(0.0));
    k.push_back(Key(section, "dynamic_friction", T::real,
                   "Coulomb sliding coefficient; negative = friction.")
                  .by_default("-1.0"));
    k.push_back(Key(section, "slide", T::expression,
                   "general: sliding traction S_slide as an expression in Nc (normal traction), "
                   "vslip (tangential slip speed), t and [constants]; capped at the stick value.")
                  .by_default("\"0\""));
  }
  k.push_back(Key("contact_pair", "first", T::string,
                 "First field of the pair: a [[material]] name (mode material) or [[body]] name "
                 "(mode body).")
                .required());
  k.push_back(Key("contact_pair", "second", T::string, "Second field of the pair.").required());
  k.push_back(Key("contact", "normal", T::string,
                 "Contact normal: lr (logistic regression on the point cloud, seed 004 Eq. 19-21, "
                 "53-57), linear (its first, linear-regression iterate), ag (average volume "
                 "gradient, Eq. 11-13) or specified (normal_direction).")
                .by_default("\"lr\"")
                .choices([] { return std::vector<std::string>{"lr", "linear", "ag", "specified"}; }));
  k.push_back(Key("contact", "normal_direction", T::real_array,
                 "specified: the normal, one entry per axis, pointing from the lower-numbered field "
                 "to the higher-numbered one."));
  k.push_back(Key("contact", "lr_weights", T::string,
                 "Point weights w_p of the lr and linear fits: shape (each particle's shape-function "
                 "weight S_ip at the node; a flat interface through a regular particle lattice then "
                 "gets its exact normal at any offset, docs/contact.md) or uniform (w_p = 1, the "
                 "seed 004 Appendix).")
                .by_default("\"shape\"")
                .choices([] { return std::vector<std::string>{"shape", "uniform"}; }));
  k.push_back(Key("contact", "lr_refine", T::string,
                 "Normal of the lr and linear fits: margin (where the two point clouds are linearly "
                 "separable, the normal of the widest-gap separating plane, the limit the logistic fit "
                 "approaches; flat interfaces and corners of lattice-filled bodies get their exact "
                 "normal, docs/contact.md) or none (the fit's own normal, seed 004 Eq. 21).")
                .by_default("\"margin\"")
                .choices([] { return std::vector<std::string>{"margin", "none"}; }));
  k.push_back(Key("contact", "detection", T::string,
                 "Contact detection; every method also needs approach, (v_b - v_a).n < 0: lr "
                 "(separation of the point clouds with deformed particle radii, Eq. 22-25), "
                 "velocity (approach alone, Eq. 14), cp (extrapolated positions closer than "
                 "critical_separation cells, Eq. 16) or df (edge distances from the tabulated "
                 "d(x) of the shape family, Eq. 15).")
                .by_default("\"lr\"")
                .choices([] { return std::vector<std::string>{"lr", "velocity", "cp", "df"}; }));
  k.push_back(Key("contact", "critical_separation", T::real,
                 "cp: critical separation delta_c in cells (seed 004 Eq. 16).")
                .by_default("0.8")
                .min(0.0));
  k.push_back(Key("contact", "touching_tolerance", T::real,
                 "lr and df: the fields touch when their edge separation is below this many cells "
                 "(0 = seed 004 Eq. 24 exactly; particles in steady contact have a separation of "
                 "zero to round-off, which then flips contact on and off).")
                .by_default("1e-3")
                .min(0.0));
  k.push_back(Key("contact", "lr_separation", T::string,
                 "lr detection: which particles give the two fields' edges at a node: cloud (every "
                 "particle whose stencil holds the node, seed 004 Eq. 22-24) or column (those within "
                 "half a cell of the line through the node along the normal: the gap at the node "
                 "itself, so that a curved surface near the contact point is not taken for touching; "
                 "docs/contact.md, \"Rolling\").")
                .by_default("\"cloud\"")
                .choices([] { return std::vector<std::string>{"cloud", "column"}; }));
  k.push_back(Key("contact", "corrections", T::string,
                 "twice: correct the extrapolated momenta and the updated momenta (seed 004 Eq. "
                 "26-34); once: only the updated momenta (for comparison).")
                .by_default("\"twice\"")
                .choices([] { return std::vector<std::string>{"twice", "once"}; }));
  k.push_back(Key("contact", "first_correction", T::string,
                 "How the first correction (on the extrapolated momenta) reaches the particles: "
                 "extrapolation (seed 004 Eq. 33-34, a = a^a,1 for every law: under FLIP the "
                 "particles keep the approach velocity the correction removed, which makes frictional "
                 "sliding chatter) or impulse (its change at contact interfaces is a contact impulse "
                 "on the particle velocities, V += S dv; bonded, perfect-law changes stay part of the "
                 "extrapolation; cures the chatter but lets interfaces under sustained compression "
                 "drift apart, so it is not the default; docs/contact.md).")
                .by_default("\"extrapolation\"")
                .choices([] { return std::vector<std::string>{"impulse", "extrapolation"}; }));
  k.push_back(Key("contact", "three_or_more", T::string,
                 "Nodes that see three or more fields: lump (each field against all others lumped, "
                 "Eq. 50) or pairs (the pairs in contact solved together; lumped when three or "
                 "more pairs touch).")
                .by_default("\"lump\"")
                .choices([] { return std::vector<std::string>{"lump", "pairs"}; }));
  k.push_back(Key("contact", "xpic_correction", T::boolean,
                 "Add the Delta v term of multimaterial XPIC(m) and FMPM(k) (seed 004 Eq. 37, seed "
                 "000 Eq. 5); false gives the uncorrected variant.")
                .by_default("true"));

  // [body_force]
  k.push_back(Key("body_force", "expression", T::expression_array,
                 "Body force per unit mass, one entry per axis: numbers or expressions in "
                 "x, y, z (current position), X, Y, Z (reference position), t and "
                 "[constants]; default none."));

  // [[traction]] (seed 000 Sec. 2.4, docs/boundary-conditions.md)
  k.push_back(Key("traction", "name", T::string,
                 "Name used in messages; default traction<N> for the N-th [[traction]] (from 0)."));
  k.push_back(Key("traction", "body", T::string,
                 "Name of the loaded [[body]]; \"\" = every body.")
                .by_default("\"\""));
  k.push_back(Key("traction", "side", T::string,
                 "Load only the exposed particle faces with this outward normal (x_min: -x, ...); "
                 "default every exposed face (then box_min/box_max are required).")
                .choices(face_names_list));
  k.push_back(Key("traction", "box_min", T::real_array,
                 "With box_max: load only faces whose reference centre lies in this box."));
  k.push_back(Key("traction", "box_max", T::real_array,
                 "Upper corner of the face-selection box."));
  k.push_back(Key("traction", "traction", T::real_array,
                 "Traction vector (force per current face area), one entry per axis; multiplied "
                 "by scale(t) and table(t).")
                .required());
  k.push_back(Key("traction", "scale", T::expression,
                 "Time factor: an expression in t with tri(t, w), ramp(t, r) and [constants].")
                .by_default("1.0"));
  k.push_back(Key("traction", "table", T::real_array,
                 "Piecewise-linear time factor [[t0, f0], [t1, f1], ...] (increasing t, constant "
                 "beyond the ends), multiplied with scale; default none."));

  // [[velocity]]
  k.push_back(Key("velocity", "name", T::string,
                 "Name used in history.csv (reaction_<name>_x, ...); default velocity<N>."));
  k.push_back(Key("velocity", "face", T::string,
                 "Select the nodes of this grid face and the ghost nodes beyond it.")
                .choices(face_names_list));
  k.push_back(Key("velocity", "box_min", T::real_array,
                 "With box_max: select the nodes inside this box (a line or plane when the box is "
                 "flat)."));
  k.push_back(Key("velocity", "box_max", T::real_array,
                 "Upper corner of the node-selection box."));
  k.push_back(Key("velocity", "plane_axis", T::string,
                 "With plane_at: select the nodes on the plane (2D: line) <plane_axis> = plane_at.")
                .choices(axis_names));
  k.push_back(Key("velocity", "plane_at", T::real,
                 "Coordinate of the selection plane along plane_axis."));
  k.push_back(Key("velocity", "direction", T::real_array,
                 "Direction of the prescribed velocity component, one entry per axis (normalised).")
                .required());
  k.push_back(Key("velocity", "velocity", T::expression,
                 "Prescribed velocity along direction: an expression in t with tri, ramp and "
                 "[constants], times table(t).")
                .by_default("0.0"));
  k.push_back(Key("velocity", "table", T::real_array,
                 "Piecewise-linear factor [[t0, f0], [t1, f1], ...] of velocity; default none."));

  // [[wall]] (seed 000 Sec. 2.5)
  k.push_back(Key("wall", "name", T::string,
                 "Name used in history.csv (reaction_<name>_x, wall_<name>_position); default "
                 "wall<N>."));
  k.push_back(Key("wall", "axis", T::string,
                 "The wall is normal to this axis and moves along it.")
                .required()
                .choices(axis_names));
  k.push_back(Key("wall", "inside", T::string,
                 "Side of the wall where the material is: below (coordinates < position) or above.")
                .required()
                .choices([] { return std::vector<std::string>{"below", "above"}; }));
  k.push_back(Key("wall", "position", T::real,
                 "Wall position along axis at t = 0; inside the grid.")
                .required());
  k.push_back(Key("wall", "velocity", T::expression,
                 "Wall velocity v_b(t) along axis: an expression in t, times table(t); the wall "
                 "moves with it.")
                .by_default("0.0"));
  k.push_back(Key("wall", "table", T::real_array,
                 "Piecewise-linear factor [[t0, f0], [t1, f1], ...] of velocity; default none."));
  k.push_back(Key("wall", "gradient", T::expression,
                 "Velocity gradient along axis: \"zero\", \"estimate\" (seed 000 Eq. 4) or "
                 "an expression in t.")
                .by_default("\"zero\""));
  k.push_back(Key("wall", "depth", T::real,
                 "Depth d in cells: nodes inside the material within d of the wall are "
                 "controlled (seed 000 Sec. 2.5).")
                .by_default("1.0")
                .min(above_zero));

  // [fem] (docs/fem.md, seed 001 Appendix A)
  k.push_back(Key("fem", "material", T::string,
                 "Name of the [[material]] of the meshed body.")
                .required());
  k.push_back(Key("fem", "mesh_file", T::string,
                 "Gmsh .msh file (relative to the input file) read through the Gmsh API; its "
                 "3-node triangles are the mesh. Give either mesh_file or shape.")
                .by_default("\"\""));
  k.push_back(Key("fem", "shape", T::table,
                 "Generated mesh: an inline table with one shape kind as in [[body]] (box, circle, "
                 "ellipse, annulus, polygon)."));
  k.push_back(Key("fem", "hole_center", T::real_array,
                 "Centre of a circular hole cut from the generated shape (plate with a hole)."));
  k.push_back(Key("fem", "hole_radius", T::real,
                 "Radius of the hole; 0 = no hole.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("fem", "size", T::real,
                 "Characteristic element size (edge length) of a generated mesh; halve it for the "
                 "next mesh of a refinement sequence.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("fem", "mesher", T::string,
                 "gmsh: unstructured Frontal-Delaunay triangles from the Gmsh API; structured: a "
                 "mapped mesh (boxes: crossed-diagonal quads; annuli: polar quads split in two).")
                .by_default("\"gmsh\"")
                .choices([] { return std::vector<std::string>{"gmsh", "structured"}; }));
  k.push_back(Key("fem", "velocity", T::expression_array,
                 "Initial node velocity, one entry per axis: numbers or expressions in X, Y "
                 "(reference position) and [constants]; default zeros."));
  k.push_back(Key("fem", "displacement", T::expression_array,
                 "Initial node displacement, entries as for velocity; default none."));
  k.push_back(Key("fem", "exact_displacement", T::expression_array,
                 "Exact displacement u(X, Y, t) of a manufactured solution; history.csv then has "
                 "displacement_error (max over nodes of |x - X - u|, seed 001 Eq. 38, every step) and "
                 "displacement_error_max (its maximum over all steps so far); default none."));

  // [output]
  k.push_back(Key("output", "directory", T::string,
                 "Output folder; \"\" = out/<input file stem>. A relative folder lies next to the "
                 "input file (with --set: relative to the working directory).")
                .by_default("\"\""));
  k.push_back(Key("output", "every", T::real,
                 "Snapshot interval in simulated time; 0 = first and last only.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("output", "history_every", T::real,
                 "History (energies, probes) interval; 0 = same as every.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("output", "checkpoint_every", T::real,
                 "Checkpoint interval; 0 = only at the end.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("output", "snapshots", T::boolean,
                 "Write HDF5/XDMF particle snapshots.")
                .by_default("true"));
  k.push_back(Key("output", "grid_snapshots", T::boolean,
                 "Also write grid node fields.")
                .by_default("false"));
  k.push_back(Key("output", "checkpoints", T::boolean,
                 "Write checkpoints for `cairn restart`.")
                .by_default("true"));
  k.push_back(Key("output", "exact_displacement", T::expression_array,
                 "Exact displacement u(X, t) of a manufactured solution, one expression per axis "
                 "in X, Y, Z, t and [constants]: history.csv gets displacement_error, the largest "
                 "|x - X - u(X, t)| over the particles at the row's time, and "
                 "displacement_error_max, the largest over every step so far (seed 001 Eq. 38); "
                 "default none."));
  k.push_back(Key("output", "checkpoint_wall_interval", T::real,
                 "Wall-clock seconds between checkpoints (checkpoint-autosave.h5, overwritten); "
                 "0 = none. SIGINT/SIGTERM also write it.")
                .by_default("1800.0")
                .min(0.0));
  k.push_back(Key("output", "compression", T::integer,
                 "gzip level (1-9) of the large HDF5 datasets (chunked, shuffled); 0 = off.")
                .by_default("0")
                .min(0)
                .max(9));
  k.push_back(Key("output", "existing", T::string,
                 "What a new run (not a restart) does with the numbered files an earlier run left in "
                 "its folder (snapshots/particles-*.h5, checkpoint-*.h5, checkpoint-autosave.h5, "
                 "failure files): remove = delete them first, saying how many (the new run writes its "
                 "own); keep = leave them beside the new ones; error = refuse to run (exit 2).")
                .by_default("\"remove\"")
                .choices([] { return std::vector<std::string>{"remove", "keep", "error"}; }));
  return k;
}

/// Computed defaults, shown instead of the (empty) TOML default.
const std::map<std::string, std::string>& computed_defaults() {
  static const std::map<std::string, std::string> m{
      {"simulation.mode", "by dimension"},
      {"body.name", "body<N>"},
      {"body.velocity", "zeros"},
      {"traction.name", "traction<N>"},
      {"velocity.name", "velocity<N>"},
      {"wall.name", "wall<N>"},
  };
  return m;
}

/// Type names that "real[D]"-style generic text would get wrong.
const std::map<std::string, std::string>& type_overrides() {
  static const std::map<std::string, std::string> m{
      {"grid.cell_size", "real or real[D]"},
      {"body.particles_per_cell", "integer or integer[D]"},
      {"body.shape", "inline table"},
      {"body.shape.circle.center", "real[2]"},
      {"body.shape.annulus.center", "real[2]"},
      {"body.shape.sphere.center", "real[3]"},
      {"body.shape.cylinder.center", "real[3]"},
      {"body.shape.polygon.vertices", "real[2][n]"},
      {"body.shape.image.origin", "real[2]"},
      {"body.shape.image.levels", "integer[2]"},
      {"body.shape.mesh.rotate", "real[3]"},
      {"body.shape.mesh.translate", "real[3]"},
      {"body.shape.outline.translate", "real[2]"},
      {"body.shape.volume_mesh.rotate", "real[3]"},
      {"body.shape.volume_mesh.translate", "real[3]"},
      {"traction.table", "real[2][n]"},
      {"velocity.table", "real[2][n]"},
      {"wall.table", "real[2][n]"},
  };
  return m;
}

std::string number_text(double v) { return v == above_zero ? "0" : fmt::format("{}", v); }

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

bool is_numeric(KeyType t) {
  return t == KeyType::integer || t == KeyType::real || t == KeyType::integer_array ||
         t == KeyType::real_array;
}
bool is_integer(KeyType t) { return t == KeyType::integer || t == KeyType::integer_array; }

}  // namespace

std::string range_phrase(const KeyDecl& d) {
  if (!is_numeric(d.type)) return "";
  const bool positive = d.min && *d.min == above_zero;
  if (d.min && d.max) {
    if (positive) return fmt::format(" in (0, {}]", number_text(*d.max));
    if (is_integer(d.type)) return fmt::format(" in {}..{}", number_text(*d.min), number_text(*d.max));
    return fmt::format(" in [{}, {}]", number_text(*d.min), number_text(*d.max));
  }
  if (d.min) return positive ? " > 0" : fmt::format(" >= {}", number_text(*d.min));
  if (d.max) return fmt::format(" <= {}", number_text(*d.max));
  return "";
}

namespace {

// ---- documentation text ------------------------------------------------------------------

struct SectionDoc {
  std::string name;     ///< "simulation"
  std::string heading;  ///< "[simulation]" or "[[material]]"
  std::string intro;
  std::string example;
};

const std::vector<SectionDoc>& section_docs() {
  static const std::vector<SectionDoc> docs{
      {"simulation", "[simulation]",
       "What is simulated and for how long: dimension, kinematic mode, end time and time-step "
       "control. Required.",
       "[simulation]\n"
       "title = \"two blocks\"\n"
       "dimension = 2\n"
       "mode = \"plane_strain\"\n"
       "end_time = 2.0e-3\n"
       "cfl = 0.5\n"},
      {"grid", "[grid]",
       "The regular background grid. Every array has D entries. Required.",
       "[grid]\n"
       "origin = [0.0, 0.0]\n"
       "extent = [0.12, 0.04]\n"
       "cell_size = 1.0e-3   # or [1.0e-3, 1.0e-3]\n"},
      {"method", "[method]",
       "The numerical method: shape functions, particle update and stress-update timing. The "
       "choices are the names registered in this build.",
       "[method]\n"
       "shape = \"bspline2\"\n"
       "update = \"fmpm\"\n"
       "order = 4\n"
       "stress_update = \"usl\"\n"},
      {"constants", "[constants]",
       "A free table of named numbers usable in every expression (body velocity, displacement, "
       "body force, tractions, velocity conditions, walls). Names must be identifiers other than "
       "x, y, z, X, Y, Z, t, _pi and _e.",
       "[constants]\n"
       "A = 0.05\n"
       "omega = 1.2e3\n"},
      {"material", "[[material]]",
       "One table per material. Besides name, model and density, each model has keys of its own, "
       "listed below; a model may also require a particular combination of them (e.g. exactly two "
       "elastic constants).",
       "[[material]]\n"
       "name = \"rubber\"\n"
       "model = \"neo_hookean\"\n"
       "density = 1500.0\n"
       "# ... the model's own keys\n"},
      {"body", "[[body]]",
       "One table per body: a region of the grid filled with particles of one material. At "
       "least one is required.",
       "[[body]]\n"
       "name = \"left\"\n"
       "material = \"rubber\"\n"
       "shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }\n"
       "particles_per_cell = 2\n"
       "velocity = [8.165, 0.0]\n"
       "\n"
       "[[body]]\n"
       "material = \"rubber\"\n"
       "shape = { circle = { center = [0.09, 0.02], radius = 0.01 } }\n"
       "displacement = [\"A*sin(2*_pi*X)\", \"0\"]\n"},
      {"boundary", "[boundary]",
       "Conditions on the faces of the grid. A periodic axis needs periodic on both of its faces; "
       "y_* and z_* keys exist only in 2D and 3D, z_* only in 3D. fixed holds every velocity "
       "component at zero on the face nodes and the ghost nodes beyond; symmetry holds the normal "
       "component on the face and mirrors ghost nodes (normal component negated); with the "
       "open-knot families (bspline2_open, bspline3_open) only the face value, whose basis "
       "function is the only one non-zero on the face, is held. See docs/shape-functions.md.",
       "[boundary]\n"
       "x_min = \"fixed\"\n"
       "x_max = \"free\"\n"
       "y_min = \"symmetry\"\n"},
      {"thermal", "[thermal]",
       "Heat conduction on the grid and thermal conditions on the grid faces (docs/thermal.md). "
       "Materials give conductivity and heat_capacity.",
       "[thermal]\n"
       "conduction = true\n"
       "x_min = \"temperature\"\n"
       "x_min_value = 400.0\n"},
      {"body_force", "[body_force]",
       "A body force per unit mass (e.g. gravity), applied to every particle.",
       "[body_force]\n"
       "expression = [0.0, \"-9.81\"]\n"},
      {"traction", "[[traction]]",
       "A traction on the exposed faces of a body's particles, added to the grid forces (seed 000 "
       "Sec. 2.4): T(t) = traction * scale(t) * table(t), spread with the grid functions over each "
       "face; the face area follows the deformation with cpdi, b2cpdi and cpgimp. Faces are "
       "selected by side, by box or both. See docs/boundary-conditions.md.",
       "[[traction]]\n"
       "body = \"bar\"\n"
       "side = \"x_min\"\n"
       "traction = [-500.0, 0.0]\n"
       "scale = \"tri(t, 1e-3)\"\n"},
      {"velocity", "[[velocity]]",
       "A prescribed grid velocity component on a node set: the intersection of the selectors "
       "given (face, box, plane). Imposed with the [boundary] faces in every scheme, including the "
       "velocity, lumped, combined and constrained full-mass methods (seed 000 Eq. 3); its reaction force is in "
       "history.csv. See docs/boundary-conditions.md.",
       "[[velocity]]\n"
       "name = \"grip\"\n"
       "face = \"x_max\"\n"
       "direction = [1.0, 0.0]\n"
       "velocity = \"0.01*ramp(t, 1e-3)\"\n"},
      {"wall", "[[wall]]",
       "A moving wall normal to an axis (seed 000 Sec. 2.5): it sets v = v_b + grad v_b (x - "
       "x_wall) along its axis on the nodes inside the material within depth d and on the nodes "
       "outside it that carry mass. Its position and reaction force are in history.csv. See "
       "docs/boundary-conditions.md.",
       "[[wall]]\n"
       "name = \"right\"\n"
       "axis = \"x\"\n"
       "inside = \"below\"\n"
       "position = 10.0\n"
       "velocity = 0.025\n"
       "gradient = \"estimate\"\n"
       "depth = 1.5\n"},
      {"contact", "[contact]",
       "Multimaterial contact (seed 004; docs/contact.md): one velocity field per material or "
       "body, contact corrections twice per step, the contact law of each pair, normals and "
       "detection. History gets contact_nodes, contact_active and the force on each field pair.",
       "[contact]\n"
       "mode = \"material\"\n"
       "law = \"coulomb\"\n"
       "friction = 0.2\n"
       "normal = \"lr\"\n"
       "detection = \"lr\"\n"},
      {"contact_pair", "[[contact_pair]]",
       "The contact law of one pair of fields, overriding the [contact] default.",
       "[[contact_pair]]\n"
       "first = \"steel\"\n"
       "second = \"rock\"\n"
       "law = \"perfect\"\n"},
      {"fem", "[fem]",
       "The reference explicit FEM of seed 001 Appendix A on linear triangles (docs/fem.md). With "
       "[fem] the run has no grid and no particles: no [grid], [[body]], [[traction]], [[wall]], "
       "[contact] or [thermal]. [boundary] faces apply to the nodes on the faces of the mesh's "
       "bounding box, [[velocity]] selects nodes by face, box or plane, [body_force] acts on the "
       "nodes (expressions of X, Y, x, y, t).",
       "[fem]\n"
       "material = \"steel\"\n"
       "shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\n"
       "hole_center = [0.0, 0.0]\n"
       "hole_radius = 0.5\n"
       "size = 0.02\n"},
      {"output", "[output]",
       "What is written, where and how often.",
       "[output]\n"
       "directory = \"out/two_blocks\"\n"
       "every = 1.0e-4\n"
       "grid_snapshots = false\n"},
  };
  return docs;
}

std::string md_cell(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|' || c == '<') out += '\\';  // table separator; '<' would start an HTML tag
    out += c;
  }
  return out;
}

std::string md_code(const std::string& s) { return s.empty() ? "" : "`" + s + "`"; }

/// Range or choices for markdown: choices each in backticks.
std::string md_range(const KeyDecl& d) {
  if (d.type == KeyType::string && d.choices) {
    std::vector<std::string> c = d.choices();
    for (auto& s : c) s = "`" + s + "`";
    return join(c, ", ");
  }
  return md_cell(range_text(d));
}

/// Default cell: TOML defaults as code, "required" / "none" / computed defaults as text.
std::string md_default(const KeyDecl& d) {
  if (d.required || d.default_value.empty()) return md_cell(default_text(d));
  return md_code(d.default_value);
}

void md_header(std::string& out) {
  out += "| key | type | default | range / choices | doc |\n";
  out += "|---|---|---|---|---|\n";
}

/// Rows of a key table; `prefix` is prepended to the key names ("circle." for shape parameters).
void md_rows(std::string& out, const std::vector<KeyDecl>& keys, const std::string& prefix = "") {
  for (const auto& d : keys)
    out += fmt::format("| `{}{}` | {} | {} | {} | {} |\n", prefix, d.name, md_cell(type_text(d)),
                       md_default(d), md_range(d), md_cell(d.doc));
}

void md_table(std::string& out, const std::vector<KeyDecl>& keys) {
  md_header(out);
  md_rows(out, keys);
}

std::vector<KeyDecl> copy_section(std::string_view section) {
  std::vector<KeyDecl> out;
  for (const auto* d : section_keys(section)) out.push_back(*d);
  return out;
}

/// The source papers that docs cite as "seed 00N" (README.md, "seed" table), for the headers of
/// `cairn keys` and docs/input.md.
constexpr const char* seeds_cited =
    "Docs cite the five source papers as \"seed 00N\" (README.md lists them): seed 000 = Nairn and "
    "Hammerquist, full mass matrix MPM (FMPM, XPIC, boundary conditions); seed 001 = Wallstedt and "
    "Guilkey, weighted least squares PIC (WLS); seed 002 = Nairn, notes on MPM extrapolations "
    "(particle updates); seed 003 = Steffen, Wallstedt, Guilkey, Kirby and Berzins, MPM "
    "implementation choices (shape functions, time integration); seed 004 = Nairn, Hammerquist and "
    "Smith, MPM contact algorithms.";

std::string markdown_text() {
  std::string out;
  out +=
      "# Cairn input reference\n"
      "\n"
      "<!-- Generated from src/cairn/io/schema.cpp by `cairn keys --markdown > docs/input.md`; "
      "do not edit by hand. -->\n"
      "\n"
      "A Cairn input file is [TOML](https://toml.io). Every key is declared once, with its type, "
      "default, allowed range or choices and a one-line doc; this page is generated from those "
      "declarations. Unknown keys, misspelled sections, values of the wrong type or out of "
      "range are errors that name the file, the line and the key, what was expected and what "
      "was found; every independent error of a file is reported in one run (up to 20), and a "
      "key written in the wrong section says which section declares it.\n"
      "\n";
  out += seeds_cited;
  out +=
      "\n"
      "\n"
      "- `D` is `simulation.dimension`; `real[D]` is an array with one number per axis.\n"
      "- Integers are accepted wherever a real is expected.\n"
      "- `expr[D]` entries are numbers or expression strings such as `\"A*sin(2*_pi*X)\"`; "
      "they may use the names of `[constants]`. An empty string is an error. Each is checked "
      "when the input is read: one expression (a `,` outside a function's arguments, as in "
      "`\"-9,81\"`, is an error), no assignment (`=`, `+=`, ...), only the variables its key "
      "allows: initial values (`[[body]]` velocity and displacement) the positions `x y z X Y Z` "
      "up to the dimension but not `t`; time functions (traction scale, `[[velocity]]` and "
      "`[[wall]]` velocity and gradient) only `t`; the body force both.\n"
      "- A number beyond 1e30 in magnitude (or nonzero below 1e-30) is accepted with a warning: "
      "no unit system needs it, and energies or stresses may overflow.\n"
      "- Before anything is allocated, the grid's node count is checked against the 32-bit node "
      "index (at most 1e9 cells per axis), and the memory of grid, particles and transfer caches "
      "is estimated against `simulation.memory_limit`; a run whose `end_time` / first time step "
      "exceeds `simulation.max_estimated_steps` is refused naming what sets the step. A body must "
      "lie inside the grid (`clip = true` keeps the part inside) and may not share space with "
      "another (`simulation.body_overlap`). docs/robustness.md lists every guard.\n"
      "- Any key can be overridden on the command line: `cairn run case.toml --set "
      "method.order=4 --set material[0].density=1100`. The value is read as a TOML value "
      "(`--set grid.origin=[0,0]`), or as a plain string when it is not one "
      "(`--set method.update=fmpm`). Entries of `[[material]]` and `[[body]]` are addressed by "
      "their index from 0: `material.0.density` or `material[0].density`.\n"
      "- `cairn check case.toml` validates an input and prints it with every default filled "
      "in.\n"
      "- Exit codes of `cairn`: 0 success; 2 bad input (this page's errors, a bad command line, "
      "a damaged or edited checkpoint); 3 the simulation failed; 1 any other error (a full disk "
      "says \"no space left on device\").\n"
      "\n"
      "Sections: ";
  std::vector<std::string> links;
  for (const auto& s : section_docs()) links.push_back(fmt::format("[`{}`](#{})", s.heading, s.name));
  out += join(links, " · ") + "\n";

  for (const auto& s : section_docs()) {
    out += fmt::format("\n## {}\n\n{}\n\n", s.heading, s.intro);
    if (s.name == "constants") {
      md_header(out);
      out += "| *any identifier* | real | none |  | A named number for expressions. |\n";
    } else {
      md_table(out, copy_section(s.name));
    }
    out += fmt::format("\n```toml\n{}```\n", s.example);

    if (s.name == "material") {
      for (const auto& model : material_model_names()) {
        out += fmt::format("\n### model `{}`\n\n", model);
        auto it = material_model_info().find(model);
        if (it == material_model_info().end() || it->second.keys.empty()) {
          if (it != material_model_info().end() && !it->second.doc.empty())
            out += it->second.doc + "\n\n";
          out += "No keys of its own.\n";
          continue;
        }
        if (!it->second.doc.empty()) out += it->second.doc + "\n\n";
        md_table(out, it->second.keys);
      }
    }
    if (s.name == "body") {
      out +=
          "\n### shape kinds\n\n"
          "`shape` holds exactly one of these kinds, each an inline table of its parameters "
          "(required unless a default is shown).\n\n"
          "| kind | dimensions | doc |\n|---|---|---|\n";
      for (const auto& kind : body_shape_kinds()) {
        std::vector<std::string> dims;
        for (int d = 0; d < 3; ++d)
          if (kind.valid_in[d]) dims.push_back(fmt::format("{}D", d + 1));
        out += fmt::format("| `{}` | {} | {} |\n", kind.name, join(dims, ", "), md_cell(kind.doc));
      }
      out += "\n";
      md_header(out);
      for (const auto& kind : body_shape_kinds())
        md_rows(out, copy_section("body.shape." + kind.name), kind.name + ".");
      out +=
          "\nAn `image` body is drawn as a picture (seed 004 Sec. 4.2): a particle position X "
          "belongs to it when the pixel under X has a grey level in `levels`. Pixel (col, row) of "
          "a W x H picture covers x in [x0 + col s, x0 + (col + 1) s), y in [y0 + (H - 1 - row) s, "
          "y0 + (H - row) s), with s = pixel_size and [x0, y0] = origin: row 0, the first row of "
          "the file, is the top of the picture, at the highest y. Positions outside the picture "
          "are outside the body, and a position on a pixel edge (to 1e-6 pixel) belongs to the pixel "
          "on its +x / +y side. A picture whose shades mark several materials becomes one "
          "[[body]] per shade (or range of shades), each with its own material:\n\n"
          "```toml\n"
          "[[body]]\n"
          "material = \"grain1\"\n"
          "shape = { image = { file = \"ellipses.png\", pixel_size = 3.5714e-6, levels = [10, 10] } }\n"
          "\n"
          "[[body]]\n"
          "material = \"grain2\"\n"
          "shape = { image = { file = \"ellipses.png\", pixel_size = 3.5714e-6, levels = [20, 20] } }\n"
          "```\n\n"
          "The picture is read once per file when the input is loaded (a missing or unreadable "
          "file is an input error at the `file` key); the resolved input (`cairn check`, "
          "checkpoints) names it by its absolute path, so a restart needs the file still there.\n"
          "\nA `mesh` body (3D) is the inside of a closed triangle surface read from a file, placed by "
          "x = R (scale x_file) + translate; the file is checked when the input is loaded (an open, "
          "non-manifold, self-intersecting or degenerate surface is an input error at `file`, an "
          "inward or inconsistent orientation is turned with a warning). Formats, the inside test, "
          "limits and recipes from CAD tools are in docs/geometry.md:\n\n"
          "```toml\n"
          "[[body]]\n"
          "material = \"steel\"\n"
          "shape = { mesh = { file = \"part.stl\", units = \"mm\", rotate = [90.0, 0.0, 0.0], "
          "translate = [0.1, 0.0, 0.05] } }\n"
          "```\n\n"
          "A `volume_mesh` body takes the 3-node triangles (2D) or 4-node tetrahedra (3D) of a Gmsh "
          "mesh (a `.geo` outline, holes and all, is meshed when read): one particle per element or per "
          "Gauss point, with its share of the element's area/volume, so the mass is density x mesh "
          "volume exactly. A `points` body takes one particle per row of a CSV file (x, y, z, volume, "
          "optional velocity and temperature).\n";
    }
  }
  return out;
}

/// One aligned block of rows (columns separated by two spaces, the last column not padded).
/// Width of `cairn keys` (a 100-column terminal).
constexpr std::size_t plain_width = 100;

/// Word-wrap `text` into lines of at most `width` characters (a longer word is cut).
std::vector<std::string> wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t space = text.find(' ', pos);
    std::string word = text.substr(pos, space == std::string::npos ? std::string::npos : space - pos);
    pos = space == std::string::npos ? text.size() : space + 1;
    if (word.empty()) continue;
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    while (word.size() > width) {
      if (!line.empty()) lines.push_back(line);
      lines.push_back(word.substr(0, width));
      word.erase(0, width);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty() || lines.empty()) lines.push_back(line);
  return lines;
}

/// A table indented by 2 with 2 spaces between columns, at most plain_width wide: the columns
/// before the last keep their natural width while the last (the doc) has at least 36; then the
/// widest of them but the first (the key names) gives way; every cell wraps within its column.
void plain_rows(std::string& out, const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows)
    for (std::size_t c = 0; c < r.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], r[c].size());
    }
  if (width.empty()) return;
  const std::size_t last = width.size() - 1;
  auto used = [&] {
    std::size_t u = 2;
    for (std::size_t c = 0; c < last; ++c) u += width[c] + 2;
    return u;
  };
  // The first column (key names) stays whole, no column gets narrower than its heading or 16.
  while (used() + 36 > plain_width) {
    std::size_t widest = 0;
    for (std::size_t c = 1; c < last; ++c)
      if (width[c] > std::max<std::size_t>(16, rows[0][c].size()) && (widest == 0 || width[c] > width[widest]))
        widest = c;
    if (widest == 0) break;
    --width[widest];
  }
  width[last] = plain_width > used() ? std::max<std::size_t>(plain_width - used(), 20) : 20;
  for (const auto& r : rows) {
    std::vector<std::vector<std::string>> cells;
    std::size_t height = 1;
    for (std::size_t c = 0; c < r.size(); ++c) {
      cells.push_back(wrap(r[c], width[c]));
      height = std::max(height, cells.back().size());
    }
    for (std::size_t k = 0; k < height; ++k) {
      std::string line = "  ";
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const std::string cell = k < cells[c].size() ? cells[c][k] : "";
        line += c + 1 < cells.size() ? fmt::format("{:<{}}  ", cell, width[c]) : cell;
      }
      while (!line.empty() && line.back() == ' ') line.pop_back();
      out += line + "\n";
    }
  }
}

std::vector<std::vector<std::string>> plain_table(const std::vector<KeyDecl>& keys) {
  std::vector<std::vector<std::string>> rows{{"key", "type", "default", "range/choices", "doc"}};
  for (const auto& d : keys)
    rows.push_back({d.name, type_text(d), default_text(d), range_text(d), d.doc});
  return rows;
}

std::string plain_text() {
  std::string out =
      "Cairn input keys; D = simulation.dimension. `cairn keys --markdown` gives the full "
      "reference.\n"
      "Override any key with --set section.key=value; [[material]] and [[body]] entries by\n"
      "index: --set material.0.density=1100\n";
  for (const auto& line : wrap(seeds_cited, plain_width))
    out += line + "\n";
  for (const auto& s : section_docs()) {
    out += fmt::format("\n{}\n", s.heading);
    if (s.name == "constants") {
      plain_rows(out, {{"key", "type", "doc"}, {"<identifier>", "real", "A named number for expressions."}});
      continue;
    }
    plain_rows(out, plain_table(copy_section(s.name)));
    if (s.name == "material") {
      for (const auto& model : material_model_names()) {
        out += fmt::format("\n[[material]] model = \"{}\"\n", model);
        auto it = material_model_info().find(model);
        if (it == material_model_info().end() || it->second.keys.empty()) {
          out += "  (no keys of its own)\n";
          continue;
        }
        plain_rows(out, plain_table(it->second.keys));
      }
    }
    if (s.name == "body") {
      for (const auto& kind : body_shape_kinds()) {
        out += "\n";
        for (const auto& line : wrap(fmt::format("[[body]] shape = {{ {} = {{ ... }} }}: {}", kind.name, kind.doc), plain_width))
          out += line + "\n";
        plain_rows(out, plain_table(copy_section("body.shape." + kind.name)));
      }
    }
  }
  return out;
}

}  // namespace

const std::vector<KeyDecl>& declared_keys() {
  static const std::vector<KeyDecl> keys = make_declarations();
  return keys;
}

std::vector<const KeyDecl*> section_keys(std::string_view section) {
  std::vector<const KeyDecl*> out;
  for (const auto& d : declared_keys())
    if (d.section == section) out.push_back(&d);
  return out;
}

const std::vector<std::string>& section_names() {
  static const std::vector<std::string> names{"simulation", "grid",     "method",
                                              "constants",  "material", "body",
                                              "boundary",   "thermal",    "body_force", "traction",
                                              "velocity",   "wall",       "contact",    "contact_pair",
                                              "fem",        "output"};
  return names;
}

const std::vector<BodyShapeKind>& body_shape_kinds() {
  static const std::vector<BodyShapeKind> kinds{
      {"box", {true, true, true}, "Axis-aligned box (a segment in 1D, a rectangle in 2D)."},
      {"circle", {false, true, false}, "Disc."},
      {"ellipse", {false, true, true}, "Axis-aligned ellipse (2D) or ellipsoid (3D)."},
      {"annulus", {false, true, false}, "Ring between two concentric circles."},
      {"polygon", {false, true, false}, "Simple polygon."},
      {"sphere", {false, false, true}, "Ball."},
      {"cylinder", {false, false, true}, "Circular cylinder along z (e.g. a Taylor bar)."},
      {"image", {false, true, false},
       "Pixels of a grey-level PNG picture whose level lies in a range (one body per "
       "material shade)."},
  };
  static const std::vector<BodyShapeKind> all = [] {
    std::vector<BodyShapeKind> out = kinds;
    for (const auto& g : geometry::shape_kinds())
      out.push_back({g.name, {g.valid_in[0], g.valid_in[1], g.valid_in[2]}, g.doc});
    return out;
  }();
  return all;
}

std::vector<KeyDecl> material_keys(const std::string& model) {
  std::vector<KeyDecl> out = copy_section("material");
  auto it = material_model_info().find(model);
  if (it != material_model_info().end())
    for (KeyDecl d : it->second.keys) {
      d.section = "material";
      out.push_back(std::move(d));
    }
  return out;
}

std::string expected_value_text(const KeyDecl& d) {
  const std::string range = range_phrase(d);
  switch (d.type) {
    case KeyType::boolean: return "true or false";
    case KeyType::integer: return "an integer" + range;
    case KeyType::real: return "a number" + range;
    case KeyType::string:
      if (d.choices) return "one of " + join(d.choices(), ", ");
      return "a string";
    case KeyType::integer_array: return "an array of integers" + (range.empty() ? "" : ", each" + range);
    case KeyType::real_array: return "an array of numbers" + (range.empty() ? "" : ", each" + range);
    case KeyType::expression_array: return "an array of numbers or expression strings";
    case KeyType::expression: return "a number or an expression string";
    case KeyType::string_array: return "an array of strings";
    case KeyType::table: return "a table";
  }
  return "a value";
}

std::string type_text(const KeyDecl& d) {
  auto it = type_overrides().find(d.section + "." + d.name);
  if (it != type_overrides().end()) return it->second;
  switch (d.type) {
    case KeyType::boolean: return "boolean";
    case KeyType::integer: return "integer";
    case KeyType::real: return "real";
    case KeyType::string: return "string";
    case KeyType::integer_array: return "integer[D]";
    case KeyType::real_array: return "real[D]";
    case KeyType::expression_array: return "expr[D]";
    case KeyType::expression: return "expr";
    case KeyType::string_array: return "string[]";
    case KeyType::table: return "table";
  }
  return "?";
}

std::string range_text(const KeyDecl& d) {
  if (d.type == KeyType::string && d.choices) return join(d.choices(), ", ");
  std::string r = range_phrase(d);
  if (r.rfind(" in ", 0) == 0) return r.substr(4);
  return r.empty() ? "" : r.substr(1);
}

std::string default_text(const KeyDecl& d) {
  if (d.required) return "required";
  auto it = computed_defaults().find(d.section + "." + d.name);
  if (it != computed_defaults().end()) return it->second;
  return d.default_value.empty() ? "none" : d.default_value;
}

std::string keys_text(bool markdown) { return markdown ? markdown_text() : plain_text(); }

}  // namespace cairn
