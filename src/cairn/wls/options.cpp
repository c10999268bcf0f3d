// The WLS method's own input keys (seed 001; docs/wls.md), declared beside it, and the Options
// they give the Integrator.
#include "cairn/config/config.hpp"
#include "cairn/config/plugin_keys.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

Options options(const MethodConfig& method) {
  Options o;
  o.trigger_weight = method.plugin.real("trigger_weight");
  o.projected_distance = method.plugin.text("surface_distance") == "projection";
  o.average_per_mass = method.plugin.text("spurious_force") == "per_mass";
  o.integrated_spurious_force = method.plugin.text("spurious_force") == "integrated";
  o.fitted_point_values = method.plugin.text("point_values") == "fit";
  o.adjoint_point_stress = method.plugin.text("point_values") == "adjoint";
  o.extrapolated_spurious_velocity = method.plugin.text("spurious_velocity") == "neighbours";
  o.quadrature_gradient = method.plugin.text("velocity_gradient") == "quadrature";
  o.transpose_gradient = method.plugin.text("velocity_gradient") == "transpose";
  o.filter_acceleration = method.plugin.boolean("filter_acceleration");
  o.hourglass_damping = method.plugin.real("hourglass_damping");
  const std::string velocity = method.plugin.text("particle_velocity");
  o.pic_velocity = velocity == "pic";
  if (velocity == "xpic") o.xpic_order = method.order;
  o.fitted_surface_velocity = method.plugin.text("surface_velocity") == "fit";
  o.massless_corners_included = method.plugin.text("empty_corners") == "zero";
  o.every_symmetry_face_mirrors = method.plugin.text("mirror_planes") == "all";
  o.energy_budget = method.plugin.boolean("energy_budget");
  return o;
}

CAIRN_DECLARE_KEYS(wls, {"wls", {"method"}, {
    Key("", "trigger_weight", KeyType::real,
      "WLS trigger weight TW (seed 001 Sec. 3.5): a node whose particles all have a "
      "wide weight W below TW is spurious (constant fit, averaged internal force).")
      .by_default("0.12")
      .min(above_zero)
      .max(1.0),
    Key("", "surface_distance", KeyType::string,
      "WLS signed distance of near-surface nodes (seed 001 Sec. 3.3): projection of "
      "x_surf - x_i on the unit normal (the text) or distance |x_surf - x_i| with the "
      "normal's sign (Eq. 17 as printed).")
      .by_default("\"distance\"")
      .choices([] { return std::vector<std::string>{"projection", "distance"}; }),
    Key("", "spurious_force", KeyType::string,
      "WLS internal force of spurious nodes (seed 001 Sec. 4.5): per_mass = the node "
      "mass times the mean f_int / m of its well-conditioned neighbours; force = the "
      "mean f_int of those neighbours; integrated = the node's own Eq. 24 like every "
      "node (docs/wls.md).")
      .by_default("\"per_mass\"")
      .choices([] { return std::vector<std::string>{"per_mass", "force", "integrated"}; }),
    Key("", "point_values", KeyType::string,
      "WLS density, body force and stress at the integration points (seed 001 Eq. 19-21): "
      "node = the well-conditioned corners' node values c0 (as printed); fit = their "
      "planar fits (Eq. 10) evaluated at the point, exact for linear fields; adjoint = "
      "the stress as the transpose of the quadrature gradient's transfer (particles to "
      "nodes to points), so the internal force takes from the grid the power the "
      "particles store (docs/wls.md).")
      .by_default("\"node\"")
      .choices([] { return std::vector<std::string>{"node", "fit", "adjoint"}; }),
    Key("", "spurious_velocity", KeyType::string,
      "WLS velocity of spurious nodes (seed 001 Sec. 3.5): constant = the reduced fit c0 "
      "(as printed); neighbours = the mean of the well-conditioned neighbours' planar "
      "velocity fits at the node, exact for linear fields (docs/wls.md).")
      .by_default("\"constant\"")
      .choices([] { return std::vector<std::string>{"constant", "neighbours"}; }),
    Key("", "velocity_gradient", KeyType::string,
      "WLS particle velocity gradient: quadrature = the gradients at the integration "
      "points (the strain rate conjugate to Eq. 24), averaged to the nodes and "
      "interpolated with S; narrow = sum v_i (x) G_ip (seed 001 Eq. 29 as printed; its "
      "strain rate is not the power conjugate of Eq. 24, and a free body gains energy at "
      "small steps; docs/wls.md, departure 4); transpose = the transpose of the stress "
      "transfer of Eq. 19-21, normalised, so that the particles store the power the "
      "internal force takes from the grid (surface particles: quadrature; docs/wls.md, "
      "departure 17).")
      .by_default("\"quadrature\"")
      .choices([] { return std::vector<std::string>{"quadrature", "narrow", "transpose"}; }),
    Key("", "filter_acceleration", KeyType::boolean,
      "WLS: replace each node's velocity increment a dt by the planar least-squares "
      "fit over it and its neighbours with mass (weights W m), so linear fields pass "
      "and the node-to-node zig-zag of small cut cells does not (docs/wls.md; not "
      "energy conserving); false = seed 001 as printed.")
      .by_default("false"),
    Key("", "hourglass_damping", KeyType::real,
      "WLS hourglass damping: the fraction of a node-scale checkerboard of the grid "
      "velocity removed each step, applied in every cell whose corners all carry mass to the "
      "corner patterns orthogonal to linear fields, momentum kept; 0 = seed 001 as printed, "
      "whose one-point cell integration leaves that mode unresisted (docs/wls.md).")
      .by_default("0.0")
      .min(0.0)
      .max(1.0),
    Key("", "mirror_planes", KeyType::string,
      "WLS symmetry faces whose nodes count the body's mirror image in the surface flags "
      "and distances: all = every symmetry face, so that a body that lands on a frictionless "
      "wall meets its mirror image there and the wall's reaction reaches it; reached = only "
      "the faces the body reaches at the start (a quarter model), a wall's nodes are then "
      "held while the body is still up to a cell away (docs/wls.md).")
      .by_default("\"all\"")
      .choices([] { return std::vector<std::string>{"reached", "all"}; }),
    Key("", "particle_velocity", KeyType::string,
      "WLS particle velocity update: flip = V_p += sum S_ip (v+_i - v_i) (seed 001 Eq. 27 "
      "as printed); pic = V_p = sum S_ip v+_i (seed 002 Eq. 1.66), which keeps the "
      "particles' velocity noise that the node fits cannot see out of the next fits "
      "(docs/wls.md); xpic = Eq. 27's increment started from the XPIC(k) projection "
      "sum S_ip u_i instead of V_p (k = method.order; seed 000's XPIC(k) with the "
      "least-squares fit F for the lumped mass: u_1 = v, u_(j+1) = v + u_j - F(S u_j)), which "
      "removes that noise with little of PIC's dissipation (docs/wls.md).")
      .by_default("\"flip\"")
      .choices([] { return std::vector<std::string>{"flip", "pic", "xpic"}; }),
    Key("", "surface_velocity", KeyType::string,
      "WLS velocity of the surface particles (zero mass) before the increment of Eq. 27: "
      "own = the particle's own velocity (as printed); fit = the planar velocity fits of the "
      "well-conditioned corners of its cell at its position, S-weighted, so that a massless "
      "point carries no velocity of its own into the next fits (docs/wls.md, departure 16).")
      .by_default("\"own\"")
      .choices([] { return std::vector<std::string>{"own", "fit"}; }),
    Key("", "empty_corners", KeyType::string,
      "WLS particle update at corners of the particle's cell that carry no mass (no "
      "integration region reaches them: the particle lies on or beyond the cut surface): "
      "mean = such a corner takes the S-weighted mean of the corners with mass in Eq. "
      "27-28, so a rigid motion moves the particle rigidly (docs/wls.md); zero = its zero "
      "velocity and acceleration enter Eq. 27-28 (as printed).")
      .by_default("\"mean\"")
      .choices([] { return std::vector<std::string>{"mean", "zero"}; }),
    Key("", "energy_budget", KeyType::boolean,
      "WLS: add the history columns wls_grid_work (the work of the node forces on the "
      "grid) and wls_transfer_energy (the particles' kinetic energy change in the particle "
      "update beyond the grid's), which split energy_error into the forces' and the "
      "velocity transfer's parts (docs/wls.md, \"Energy budget\"); two exact sums per "
      "step, about 2 % of the step.")
      .by_default("false")}, {}, ""});  // no cross-key check; the keys at the section's end

}  // namespace cairn::wls
