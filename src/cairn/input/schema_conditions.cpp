// The core keys of loads, conditions and couplings: [boundary], [thermal], [contact] and
// [[contact_pair]], [body_force], [[traction]], [[velocity]], [[wall]], [fem], [output].
#include "cairn/input/schema_detail.hpp"

#include "cairn/config/plugin_keys.hpp"
#include "cairn/config/units.hpp"
#include "cairn/geometry/shape_keys.hpp"
#include "cairn/input/names.hpp"
#include "cairn/materials/material.hpp"

namespace cairn::schema_detail {

void declare_condition_keys(std::vector<KeyDecl>& k) {
  using T = KeyType;
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
  k.push_back(Key("contact", "release", T::string,
                 "When a node in contact leaves it: gap (seed 004: contact needs approach and "
                 "touching at every step) or separation (a field pair that the last step's second "
                 "correction held in contact at a node stays in contact there, whatever the "
                 "separation, until its fields no longer approach; the separation only decides "
                 "when contact begins, so that a gap of a fraction of a percent of a cell that the "
                 "particles' discreteness opens under load does not drop it; docs/contact.md, "
                 "\"Rolling\").")
                .by_default("\"gap\"")
                .choices([] { return std::vector<std::string>{"gap", "separation"}; }));
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
}

}  // namespace cairn::schema_detail
