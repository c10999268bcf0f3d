// cairn_energy_audit: a per-stage kinetic-energy audit of a rolling_cylinder run (2D, contact
// mode "material", field 0 the floor, field 1 the disk; quadratic B-splines, FLIP, USL) that
// finds where the energy the history does not tally goes (issue 38 item 3; README "Where the
// rolling error goes").
//
//   cairn_energy_audit INPUT.toml [--set key=value ...] [--from T0] [--to T1] [--theta DEG]
//
// Every step it recomputes the particles' projection p0 = S^T M V (the step's stencils, from the
// positions and velocities at the start of the step) and reads the grid after the step: p after
// the first correction (nodes().momentum), v (after the start conditions), v+ before the second
// correction ((p + f dt) / m), after it (from Contact::trace) and after the end conditions
// (nodes().velocity_new). With Delta = v+ - v, the FLIP increment, and q = S^T M dV_p (the
// particles' own increments projected back), the particles' kinetic energy changes by, exactly,
//     dKE = sum_i p0_i . Delta_i + 1/2 Delta_i . q_i                                   (1)
// and the tallies (external work of body forces, contact dissipation) weigh each node's impulse
// m Delta at the step's mean velocity (v + v+)/2:
//     T = sum_i m Delta_i . (v_i + v+_i) / 2.
// Their difference is exactly
//     dKE - T = sum_i [1/2 Delta . q - 1/2 m |Delta|^2]   (the FLIP projection, <= 0)
//             + sum_i [-m Delta . dv1]                    (the first correction dv1 = (p - p0)/m,
//                                                           which the particles never see).
// USL's stress update takes grad v+, so the strain energy grows by -f_int . v+ dt to first
// order (f_int = f - m b, b the gravity of the incline at angle --theta, 30 by default, after its
// ramp), half an impulse more than T counts: the column "usl", -f_int . Delta dt / 2.
// Printed per node class (contact nodes: both fields have mass; neighbours: within two nodes of
// one; the rest) and field, summed over [T0, T1] and in % of the work the body forces and
// conditions did over it (history's external_work), with the grid's kinetic energy changes per
// stage and the energy balance's drift split into these terms.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cairn/contact/contact.hpp"
#include "cairn/input/input.hpp"
#include "cairn/shapes/grid_functions.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

constexpr int kClasses = 3;  // contact, neighbour, rest
const char* const kClassName[kClasses] = {"contact", "neighbour", "rest"};
// Stages of the grid's kinetic energy: p0 (projection) -> p (first correction) -> v (start
// conditions) -> v+ (forces) -> v+ (second correction) -> v+ (end conditions).
constexpr int kStages = 5;
const char* const kStageName[kStages] = {"1st correction", "start conditions", "forces", "2nd correction",
                                         "end conditions"};

struct Sums {
  double stage[kStages] = {};  ///< grid kinetic energy change per stage
  double gain = 0.0;           ///< particles' kinetic energy change, (1)
  double tallied = 0.0;        ///< T
  double projection = 0.0;     ///< 1/2 Delta . q - 1/2 m |Delta|^2
  double cross = 0.0;          ///< -m Delta . dv1
  double usl = 0.0;            ///< -f_int . Delta dt / 2: USL's strain increment beyond T
  double strain_grid = 0.0;    ///< -f_int . v+ dt: the strain increment to first order
};

int audit(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: cairn_energy_audit INPUT.toml [--set key=value ...] [--from T0] [--to T1]\n");
    return 2;
  }
  std::vector<std::string> sets;
  double t0 = 0.04, t1 = 0.12, theta = 30.0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--set") sets.emplace_back(argv[i + 1]);
    else if (flag == "--from") t0 = std::stod(argv[i + 1]);
    else if (flag == "--to") t1 = std::stod(argv[i + 1]);
    else if (flag == "--theta") theta = std::stod(argv[i + 1]);
  }
  const double rad = theta * std::acos(-1.0) / 180.0;
  const Vec<2> gravity(9.81 * std::sin(rad), -9.81 * std::cos(rad));
  if (t0 < 0.02) std::fprintf(stderr, "cairn_energy_audit: the usl column assumes the gravity ramp (20 ms) is over\n");
  sets.emplace_back("simulation.end_time=" + std::to_string(t1));
  sets.emplace_back("simulation.threads=1");
  const Config cfg = load_config(argv[1], sets);
  Simulation<2> sim(cfg);
  Contact<2>* contact = sim.contact();
  if (!contact || contact->n_fields() != 2) {
    std::fprintf(stderr, "cairn_energy_audit: needs contact with two fields (floor, disk)\n");
    return 2;
  }
  contact->trace(true);
  const Grid<2>& grid = sim.grid();
  const auto& P = sim.particles();
  const std::int32_t nn = grid.n_nodes();
  const std::size_t np = P.n();
  std::int64_t max_id = 0;
  for (std::size_t p = 0; p < np; ++p) max_id = std::max(max_id, P.id[p]);
  // Start-of-step state by particle id.
  std::vector<Vec<2>> x_old(max_id + 1), v_old(max_id + 1);
  std::vector<int> field_of(max_id + 1);
  std::vector<double> mass_of(max_id + 1);
  std::vector<Vec<2>> p0(2 * nn), q(2 * nn), v_post(2 * nn);
  std::vector<double> m0(2 * nn);
  std::vector<int> cls(nn);
  Sums sums[kClasses][2];
  // Contact nodes by the second correction's verdict (Contact::NodeTrace::State): node-steps,
  // m |Delta|^2 / 2 along the normal and across it, projection, usl (both fields).
  constexpr int kStates = 6;
  const char* const kStateName[kStates] = {"bonded", "no normal", "separating", "gap open", "stick", "slip"};
  double by_state[kStates][5] = {};
  std::vector<int> state_of(nn, -1);
  // Where the uncorrected contact nodes lose it: projection + usl of both fields by the node's
  // row above the floor's top and its column from the disk's centroid (cells, ahead positive).
  constexpr int kRows = 5, kCols = 13;  // rows -2..2, columns -6..6
  double where[2][kRows][kCols] = {}, where_steps[2][kRows][kCols] = {};
  double floor_top = -1e300;
  for (std::size_t p = 0; p < np; ++p)
    if (P.body[p] == 0) floor_top = std::max(floor_top, P.position[p][1] + 0.5 * P.size0[p][1]);
  const double h = grid.cell_size()[0];
  double disk_mass = 0.0;
  for (std::size_t p = 0; p < np; ++p)
    if (P.body[p] == 1) disk_mass += P.mass[p];
  std::vector<Vec<2>> normal_of(nn, Vec<2>::Zero());
  std::vector<double> sep_of(nn, 0.0);
  std::vector<double> gap_sep[3], gap_close[3];  // gap-open nodes in column 0, rows -1..1: separation, approach dt (cells)
  double cm_stage[kStages] = {};  // contact nodes: the centre-of-mass velocity's kinetic energy
  double ke_direct = 0.0, p2g_loss = 0.0, p2g_steps = 0.0, check_p0 = 0.0, check_dv = 0.0;
  double w0 = 0.0, u0 = 0.0, dc0 = 0.0, du0 = 0.0, ke0 = 0.0;
  bool started = false;
  auto kinetic = [&] {
    double e = 0.0;
    for (std::size_t p = 0; p < np; ++p) e += 0.5 * P.mass[p] * P.velocity[p].squaredNorm();
    return e;
  };
  // Quadratic B-spline stencil of a position: calls fn(slot-free node index, S).
  auto stencil = [&](const Vec<2>& x, auto&& fn) {
    const Vec<2> xi = grid.to_cell_units(x);
    double w[2][3], dw[2][3];
    int first[2];
    for (int a = 0; a < 2; ++a) first[a] = quadratic_spline_weights(xi[a], w[a], dw[a]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const std::int32_t node = grid.node_index(IVec<2>(first[0] + i, first[1] + j));
        if (node >= 0) fn(node, w[0][i] * w[1][j]);
      }
  };
  while (sim.time() < t1 - 1e-12) {
    const double dt = sim.next_dt();
    const bool in_window = sim.time() >= t0 - 1e-12;
    if (in_window && !started) {
      started = true;
      w0 = sim.external_work();
      u0 = sim.totals().strain_energy;
      dc0 = sim.contact_dissipated_energy();
      du0 = sim.update_dissipated_energy();
      ke0 = kinetic();
    }
    if (in_window)
      for (std::size_t p = 0; p < np; ++p) {
        const auto id = P.id[p];
        x_old[id] = P.position[p];
        v_old[id] = P.velocity[p];
        field_of[id] = contact->field_of(P, p);
        mass_of[id] = P.mass[p];
      }
    const double ke_before = in_window ? kinetic() : 0.0;
    sim.step(dt);
    if (!in_window) continue;
    ke_direct += kinetic() - ke_before;
    const auto& N = sim.nodes();
    std::fill(p0.begin(), p0.end(), Vec<2>::Zero());
    std::fill(q.begin(), q.end(), Vec<2>::Zero());
    std::fill(m0.begin(), m0.end(), 0.0);
    std::vector<Vec<2>> dV(max_id + 1, Vec<2>::Zero());
    for (std::size_t p = 0; p < np; ++p) dV[P.id[p]] = P.velocity[p] - v_old[P.id[p]];
    for (std::int64_t id = 0; id <= max_id; ++id) {
      const std::int32_t off = field_of[id] * nn;
      stencil(x_old[id], [&](std::int32_t node, double S) {
        m0[off + node] += S * mass_of[id];
        p0[off + node] += S * mass_of[id] * v_old[id];
        q[off + node] += S * mass_of[id] * dV[id];
      });
    }
    // Node classes.
    std::fill(cls.begin(), cls.end(), 2);
    for (std::int32_t i = 0; i < nn; ++i)
      if (N.mass[i] > 0.0 && N.mass[nn + i] > 0.0) {
        const IVec<2> j = grid.multi_index(i);
        for (int a = -2; a <= 2; ++a)
          for (int b = -2; b <= 2; ++b) {
            const std::int32_t k = grid.node_index(IVec<2>(j[0] + a, j[1] + b));
            if (k >= 0 && cls[k] == 2) cls[k] = 1;
          }
      }
    for (std::int32_t i = 0; i < nn; ++i)
      if (N.mass[i] > 0.0 && N.mass[nn + i] > 0.0) cls[i] = 0;
    // v+ after the second correction: (p + f dt)/m plus the traced changes.
    for (std::int32_t s = 0; s < 2 * nn; ++s)
      v_post[s] = N.mass[s] > 0.0 ? Vec<2>((N.momentum[s] + N.force[s] * dt) / N.mass[s]) : Vec<2>::Zero();
    for (const auto& e : contact->last_trace()) {
      state_of[e.node] = e.state;
      sep_of[e.node] = e.separation;
      normal_of[e.node] = Vec<2>(e.normal[0], e.normal[1]);
      if (e.b < 0) continue;
      const Vec<2> d(e.dp[0], e.dp[1]);
      v_post[e.a * nn + e.node] += d / N.mass[e.a * nn + e.node];
      v_post[e.b * nn + e.node] -= d / N.mass[e.b * nn + e.node];
    }
    double xc = 0.0;
    for (std::int64_t id = 0; id <= max_id; ++id)
      if (field_of[id] == 1) xc += mass_of[id] * x_old[id][0] / disk_mass;
    for (std::int32_t i = 0; i < nn; ++i) {
      double mt = 0.0;
      Vec<2> cm[kStages + 1];
      for (auto& c : cm) c.setZero();
      for (int f = 0; f < 2; ++f) {
        const std::int32_t s = f * nn + i;
        const double m = N.mass[s];
        if (!(m > 0.0)) continue;
        check_p0 = std::max(check_p0, std::abs(m0[s] - m) / m);
        const Vec<2> pc = N.momentum[s];
        const Vec<2> v = N.velocity[s], vf = N.velocity_new[s];
        const Vec<2> v_pre = (pc + N.force[s] * dt) / m;
        const Vec<2> dv1 = (pc - p0[s]) / m;
        if (cls[i] != 0) check_dv = std::max(check_dv, dv1.norm());
        const Vec<2> delta = vf - v;
        const double e[kStages + 1] = {0.5 * p0[s].squaredNorm() / m, 0.5 * pc.squaredNorm() / m,
                                       0.5 * m * v.squaredNorm(),     0.5 * m * v_pre.squaredNorm(),
                                       0.5 * m * v_post[s].squaredNorm(), 0.5 * m * vf.squaredNorm()};
        const Vec<2> mom[kStages + 1] = {p0[s], pc, m * v, m * v_pre, m * v_post[s], m * vf};
        Sums& S = sums[cls[i]][f];
        for (int k = 0; k < kStages; ++k) S.stage[k] += e[k + 1] - e[k];
        S.gain += p0[s].dot(delta) + 0.5 * delta.dot(q[s]);
        S.tallied += m * delta.dot(0.5 * (v + vf));
        S.projection += 0.5 * delta.dot(q[s]) - 0.5 * m * delta.squaredNorm();
        S.cross += -m * delta.dot(dv1);
        const Vec<2> f_int = N.force[s] - m * gravity;
        S.usl += -0.5 * f_int.dot(delta) * dt;
        S.strain_grid += -f_int.dot(vf) * dt;
        if (cls[i] == 0 && state_of[i] >= 0) {
          double* b = by_state[state_of[i]];
          const Vec<2> n = normal_of[i];
          const double dn = delta.dot(n);
          b[0] += 0.5;  // two fields
          b[1] += 0.5 * m * dn * dn;
          b[2] += 0.5 * m * (delta - dn * n).squaredNorm();
          b[3] += 0.5 * delta.dot(q[s]) - 0.5 * m * delta.squaredNorm();
          b[4] += -0.5 * f_int.dot(delta) * dt;
          const Vec<2> xn = grid.node_position(i);
          const long row = std::lround((xn[1] - floor_top) / h) + 2, col = std::lround((xn[0] - xc) / h) + 6;
          if (row >= 0 && row < kRows && col >= 0 && col < kCols &&
              (state_of[i] == Contact<2>::NodeTrace::separating || state_of[i] == Contact<2>::NodeTrace::gap_open)) {
            const int g = state_of[i] == Contact<2>::NodeTrace::gap_open;
            if (g && col == 6 && f == 1 && row >= 1 && row <= 3) {
              const Vec<2> rel = v_pre - (N.momentum[i] + N.force[i] * dt) / N.mass[i];  // disk - floor
              gap_sep[row - 1].push_back(sep_of[i] / h);
              gap_close[row - 1].push_back(rel.dot(normal_of[i]) * dt / h);  // > 0: approach (normal floor -> disk... sign below)
            }
            where[g][row][col] += 0.5 * delta.dot(q[s]) - 0.5 * m * delta.squaredNorm() - 0.5 * f_int.dot(delta) * dt;
            where_steps[g][row][col] += 0.5;
          }
        }
        mt += m;
        for (int k = 0; k <= kStages; ++k) cm[k] += mom[k];
      }
      if (cls[i] == 0)
        for (int k = 0; k < kStages; ++k) cm_stage[k] += 0.5 * (cm[k + 1].squaredNorm() - cm[k].squaredNorm()) / mt;
    }
    for (const auto& e : contact->last_trace()) state_of[e.node] = -1;
    double ke_p = 0.0;
    for (std::int64_t id = 0; id <= max_id; ++id) ke_p += 0.5 * mass_of[id] * v_old[id].squaredNorm();
    double ke_g = 0.0;
    for (std::int32_t s = 0; s < 2 * nn; ++s)
      if (N.mass[s] > 0.0) ke_g += 0.5 * p0[s].squaredNorm() / N.mass[s];
    p2g_loss += ke_p - ke_g;
    p2g_steps += 1.0;
  }
  const double work = sim.external_work() - w0;
  const double du = sim.totals().strain_energy - u0;
  const double ddc = sim.contact_dissipated_energy() - dc0;
  const double ddu = sim.update_dissipated_energy() - du0;
  const double dke = kinetic() - ke0;
  const double drift = dke + du + ddc + ddu - work;
  auto pc = [&](double x) { return 100.0 * x / work; };
  std::printf("window %.3f-%.3f s: external work %.6g J/m; checks: max |m0 - m|/m %.2e, max |dv1| off contact %.2e m/s\n",
              t0, t1, work, check_p0, check_dv);
  std::printf("particles: dKE %.4f %% (direct sum over steps %.4f %%), strain %.4f %%, contact dissipated %.4f %%, "
              "update dissipated %.4f %%, drift (KE + U + D - W) %.4f %%\n",
              pc(dke), pc(ke_direct), pc(du), pc(ddc), pc(ddu), pc(drift));
  std::printf("mean P2G loss (particle KE - grid KE of p0) %.4g J/m\n", p2g_loss / p2g_steps);
  std::printf("\n%% of external work      class field |");
  for (const char* s : kStageName) std::printf(" %16s", s);
  std::printf(" | %9s %9s %10s %9s %9s\n", "particle", "tallied", "projection", "cross", "usl");
  Sums total;
  for (int c = 0; c < kClasses; ++c)
    for (int f = 0; f < 2; ++f) {
      const Sums& S = sums[c][f];
      std::printf("%33s %5s |", kClassName[c], f == 0 ? "floor" : "disk");
      for (int k = 0; k < kStages; ++k) std::printf(" %16.4f", pc(S.stage[k]));
      std::printf(" | %9.4f %9.4f %10.4f %9.4f %9.4f\n", pc(S.gain), pc(S.tallied), pc(S.projection), pc(S.cross),
                  pc(S.usl));
      for (int k = 0; k < kStages; ++k) total.stage[k] += S.stage[k];
      total.gain += S.gain;
      total.tallied += S.tallied;
      total.projection += S.projection;
      total.cross += S.cross;
      total.usl += S.usl;
      total.strain_grid += S.strain_grid;
    }
  std::printf("%33s %5s |", "contact, centre of mass", "");
  for (int k = 0; k < kStages; ++k) std::printf(" %16.4f", pc(cm_stage[k]));
  std::printf(" |\n%33s %5s |", "all", "");
  for (int k = 0; k < kStages; ++k) std::printf(" %16.4f", pc(total.stage[k]));
  std::printf(" | %9.4f %9.4f %10.4f %9.4f %9.4f\n", pc(total.gain), pc(total.tallied), pc(total.projection),
              pc(total.cross), pc(total.usl));
  std::printf("\ncontact nodes by the second correction's verdict (%% of external work; both fields)\n"
              "%12s %10s %14s %14s %10s %9s\n", "state", "node-steps", "m|Delta_n|^2/2", "m|Delta_t|^2/2",
              "projection", "usl");
  for (int k = 0; k < kStates; ++k)
    if (by_state[k][0] > 0.0)
      std::printf("%12s %10.0f %14.4f %14.4f %10.4f %9.4f\n", kStateName[k], by_state[k][0], pc(by_state[k][1]),
                  pc(by_state[k][2]), pc(by_state[k][3]), pc(by_state[k][4]));
  const double steps = p2g_steps;
  for (int g = 0; g < 2; ++g) {
    std::printf("\n%s contact nodes: projection + usl (%% of external work) [share of the steps]\nrow\\column",
                g ? "gap-open" : "separating");
    for (int c = 0; c < kCols; ++c) std::printf(" %8d", c - 6);
    std::printf("\n");
    for (int r = kRows - 2; r >= 1; --r) {
      std::printf("%+10d", r - 2);
      for (int c = 0; c < kCols; ++c) std::printf(" %8.4f", pc(where[g][r][c]));
      std::printf("\n%10s", "");
      for (int c = 0; c < kCols; ++c) std::printf(" [%6.2f]", where_steps[g][r][c] / steps);
      std::printf("\n");
    }
  }
  for (int r = 0; r < 3; ++r) {
    auto q3 = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      const auto at = [&](double f) { return v.empty() ? 0.0 : v[static_cast<std::size_t>(f * (v.size() - 1))]; };
      return std::array<double, 5>{at(0.0), at(0.1), at(0.5), at(0.9), at(1.0)};
    };
    const auto a = q3(gap_sep[r]), b = q3(gap_close[r]);
    std::printf("column 0, row %+d, gap open (%zu): separation/h min %.4g p10 %.4g median %.4g p90 %.4g max %.4g; "
                "(v_disk - v_floor).n dt / h %.4g %.4g %.4g %.4g %.4g\n",
                r - 1, gap_sep[r].size(), a[0], a[1], a[2], a[3], a[4], b[0], b[1], b[2], b[3], b[4]);
  }
  // drift = dKE + dU + D - W = (T - W + dU + D_contact) + projection + cross + D_update, where
  // T - W - (contact's tallied change) is the internal forces' work at the mean velocity
  // and the conditions' work.
  const double forces_residual = total.tallied + ddc - work + du;
  std::printf("\ndrift %.4f %% = projection %.4f %% + cross (first correction) %.4f %% + update dissipated %.4f %% "
              "+ internal-force work vs strain energy and conditions %.4f %%\n"
              "  (of which usl %.4f %% and strain energy beyond -f_int . v+ dt %.4f %%)\n",
              pc(drift), pc(total.projection), pc(total.cross), pc(ddu), pc(forces_residual), pc(total.usl),
              pc(du - total.strain_grid));
  return 0;
}

}  // namespace
}  // namespace cairn

int main(int argc, char** argv) {
  try {
    return cairn::audit(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cairn_energy_audit: %s\n", e.what());
    return 1;
  }
}
