// The core keys of the model's sections: [simulation], [grid], [method], [[material]], [[body]] and
// the body shapes (the plug-ins' keys are declared beside them, config/plugin_keys.hpp).
#include "cairn/input/schema_detail.hpp"

#include "cairn/config/plugin_keys.hpp"
#include "cairn/config/units.hpp"
#include "cairn/geometry/shape_keys.hpp"
#include "cairn/input/names.hpp"
#include "cairn/materials/material.hpp"

namespace cairn::schema_detail {

void declare_model_keys(std::vector<KeyDecl>& k) {
  using T = KeyType;
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
                 "Keep the particles of a run of 32768 or more particles (WLS: 8192) in memory in the order "
                 "of the grid's cell blocks, sorted again when they have moved out of it (the "
                 "particle-to-grid transfers then read memory in order; docs/performance.md). "
                 "Results are bit-identical either way and output lists particles in id order. "
                 "Runs on one MPI rank only.")
                .by_default("true"));
  k.push_back(Key("simulation", "rebalance_threshold", T::real,
                 "Runs on several MPI ranks (docs/parallel.md): repartition the domain when the "
                 "largest particle count of a rank (its cost with [parallel] balance = \"cost\") "
                 "exceeds the mean by more than this fraction (history column `imbalance` = "
                 "largest / mean); checked every step. A repartition moves only the cuts out of "
                 "balance. A large value (e.g. 1e9) keeps the start-up partition. Unused on one rank.")
                .by_default("0.25")
                .min(0.0));
  k.push_back(Key("simulation", "memory_limit", T::real,
                 "GiB of memory the setup may need (grid nodes, particles, transfer caches, "
                 "estimated before anything is allocated); 0 = the machine's memory (its cgroup "
                 "limit when lower). A larger estimate is refused, naming the keys that drive it.")
                .by_default("0.0")
                .min(0.0));
  k.push_back(Key("simulation", "mpi_timeout", T::real,
                 "Seconds a distributed run waits for a step to complete before it stops, naming "
                 "the rank that stopped answering (stopped, hung, or lost with its node; a killed "
                 "or failing rank stops the run at once); exit code 1. 0 = wait for ever. Counted "
                 "from the first step (set-up and the final output are not timed). Unused on one "
                 "rank. docs/robustness.md.")
                .by_default("300.0")
                .min(0.0));
  k.push_back(Key("parallel", "halo", T::string,
                 "Runs on several MPI ranks (docs/parallel.md): nodes = each rank scatters its own "
                 "particles and the node sums shared with its neighbours are exchanged (one stencil "
                 "wide; results equal a serial run's to round-off, and are the same bits run to run "
                 "on the same ranks); particles = each rank also holds ghost copies of its "
                 "neighbours' particles and sums nodes in serial order (bit-identical to a serial "
                 "run, more work and memory per rank); auto = nodes. With [contact] the node halo "
                 "also sends each neighbour the particles whose stencils reach the contact nodes "
                 "they share (for the point clouds of the normals). Unused on one rank.")
                .by_default("\"auto\"")
                .choices([] { return std::vector<std::string>{"auto", "nodes", "particles"}; }));
  k.push_back(Key("parallel", "balance", T::string,
                 "Runs on several MPI ranks (docs/parallel.md, \"Load balance\"): what the domain "
                 "bisection shares out equally among the ranks. count = particles; cost = the "
                 "particles' cost per step, measured per material model (bench/material_cost.py) "
                 "or set by the material's balance_cost. The history column `imbalance` and "
                 "simulation.rebalance_threshold then measure the same. Unused on one rank.")
                .by_default("\"count\"")
                .choices([] { return std::vector<std::string>{"count", "cost"}; }));
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
                 "Order k of FMPM(k) and XPIC(k), and of WLS's particle_velocity = \"xpic\"; unused "
                 "by other updates.")
                .by_default("1")
                .min(1)
                .max(64));
  k.push_back(Key("method", "stress_update", T::string,
                 "When in the step the stress is updated.")
                .by_default("\"usl\"")
                .choices(stress_update_names));
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
                 "shape, update and stress_update are then unused, order too unless WLS's "
                 "particle_velocity is \"xpic\"; docs/wls.md).")
                .by_default("\"mpm\"")
                .choices([] { return std::vector<std::string>{"mpm", "wls"}; }));

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
  k.push_back(Key("material", "balance_cost", T::real,
                 "With [parallel] balance = \"cost\" on several MPI ranks: the cost of a step of "
                 "one of its particles relative to one of a corotational linear_elastic material; "
                 "0 = the figure measured for its model (docs/parallel.md, \"Load balance\").")
                .by_default("0.0")
                .min(0.0)
                .max(1000.0));

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
                 "Centre [x, y] (2D) or [x, y, z] (3D).")
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

}

}  // namespace cairn::schema_detail
