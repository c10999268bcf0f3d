// cairn_rolling_probe: runs a rolling_cylinder input (2D, contact mode "material", field 0 the
// floor, field 1 the disk) and measures, step by step, what the contact corrections do to the
// disk (issue 38 item 2). Used by verification/rolling_cylinder/run --probe.
//
//   cairn_rolling_probe INPUT.toml [--set key=value ...] [--from T0] [--to T1]
//
// Over the window [T0, T1] it sums, per row of contact nodes (the node's height above the
// floor's top in cells), the contact force on the disk along the slope (F_t) and normal to it
// (N), its torque about the disk's centroid, the interactions in each state (stick, slip, gap
// open, separating) and the energy the second correction took from the pair; then prints the
// time averages, the friction coefficient used (F_t / N), the effective rolling radius
// -torque / F_t (R when the friction acts at the contact point) and the torque of the normal
// forces (rolling resistance).
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "cairn/contact/contact.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

struct Row {
  double ft = 0.0, fn = 0.0, torque_t = 0.0, torque_n = 0.0, energy = 0.0;
  long long count[6] = {};
};

int probe(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: cairn_rolling_probe INPUT.toml [--set key=value ...] [--from T0] [--to T1]\n");
    return 2;
  }
  std::vector<std::string> sets;
  double t0 = 0.04, t1 = 0.12;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--set") sets.emplace_back(argv[i + 1]);
    else if (flag == "--from") t0 = std::stod(argv[i + 1]);
    else if (flag == "--to") t1 = std::stod(argv[i + 1]);
  }
  sets.emplace_back("simulation.end_time=" + std::to_string(t1));
  const Config cfg = load_config(argv[1], sets);
  Simulation<2> sim(cfg);
  Contact<2>* contact = sim.contact();
  if (!contact || contact->n_fields() != 2) {
    std::fprintf(stderr, "cairn_rolling_probe: needs contact with two fields (floor, disk)\n");
    return 2;
  }
  contact->trace(true);
  const double h = sim.grid().cell_size()[0];
  double floor_top = 0.0;  // top of the floor body: its highest particle plus half a spacing
  const auto& P = sim.particles();
  for (std::size_t p = 0; p < P.n(); ++p)
    if (P.body[p] == 0) floor_top = std::max(floor_top, P.position[p][1] + 0.5 * P.size0[p][1]);
  std::map<int, Row> rows;
  double window = 0.0, mass = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p)
    if (P.body[p] == 1) mass += P.mass[p];
  double dissipated0 = 0.0;
  bool started = false;
  while (sim.time() < t1 - 1e-12) {
    const double dt = sim.next_dt();
    sim.step(dt);
    if (sim.time() < t0) continue;
    if (!started) {
      dissipated0 = contact->dissipated();
      started = true;
    }
    Vec<2> xc = Vec<2>::Zero();
    for (std::size_t p = 0; p < P.n(); ++p)
      if (P.body[p] == 1) xc += P.mass[p] * P.position[p];
    xc /= mass;
    window += dt;
    for (const auto& e : contact->last_trace()) {
      // force on the disk (field 1): alpha gets dp, beta -dp
      const double sign = e.a == 1 ? 1.0 : (e.b == 1 || e.b < 0 ? -1.0 : 0.0);
      if (sign == 0.0) continue;
      const Vec3 f = sign * e.dp / dt;
      const Vec<2> xn = sim.grid().node_position(e.node);
      const Vec<2> r = xn - xc;
      const int row = static_cast<int>(std::lround((xn[1] - floor_top) / h));
      Row& w = rows[row];
      w.ft += f[0] * dt;
      w.fn += f[1] * dt;
      w.torque_t += (r[0] * 0.0 - r[1] * f[0]) * dt;  // z torque of the tangential part
      w.torque_n += (r[0] * f[1]) * dt;               // z torque of the normal part
      ++w.count[e.state];
    }
  }
  const double dissipated = contact->dissipated() - dissipated0;
  Row total;
  std::printf("row  F_t(N/m)  N(N/m)  torque_t  torque_n  stick  slip  gap_open  separating\n");
  for (const auto& [row, w] : rows) {
    std::printf("%+d  %.5g  %.5g  %.5g  %.5g  %lld  %lld  %lld  %lld\n", row, w.ft / window, w.fn / window,
                w.torque_t / window, w.torque_n / window, w.count[4], w.count[5], w.count[3], w.count[2]);
    total.ft += w.ft;
    total.fn += w.fn;
    total.torque_t += w.torque_t;
    total.torque_n += w.torque_n;
  }
  const double ft = total.ft / window, fn = total.fn / window;
  std::printf("F_t %.6g N/m, N %.6g N/m, F_t/N %.4f\n", ft, fn, ft / fn);
  std::printf("torque: friction %.6g, normal %.6g, total %.6g N\n", total.torque_t / window, total.torque_n / window,
              (total.torque_t + total.torque_n) / window);
  std::printf("effective rolling radius -torque_t/F_t %.6g m, -total torque / F_t %.6g m\n",
              -total.torque_t / total.ft, -(total.torque_t + total.torque_n) / total.ft);
  std::printf("contact dissipation over the window %.6g J/m (%.6g W/m)\n", dissipated, dissipated / window);
  std::printf("disk mass %.6g kg/m, floor top %.6g m, h %.6g m\n", mass, floor_top, h);
  return 0;
}

}  // namespace
}  // namespace cairn

int main(int argc, char** argv) {
  try {
    return cairn::probe(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cairn_rolling_probe: %s\n", e.what());
    return 1;
  }
}
