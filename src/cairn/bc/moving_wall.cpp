#include "cairn/bc/moving_wall.hpp"

#include <cmath>
#include <stdexcept>

#include "cairn/parallel/exact_sum.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {

template <int D>
MovingWall<D>::MovingWall(const WallConfig& config, const Grid<D>& grid, const Constants& constants)
    : config_(config), position_(config.position), position_end_(config.position) {
  const std::string what = config.where.str() + ": wall '" + config.name + "'";
  if (config.axis < 0 || config.axis >= D) throw std::invalid_argument(what + ": axis beyond the dimension");
  if (grid.periodic(config.axis)) throw std::invalid_argument(what + ": a wall cannot be normal to a periodic axis");
  velocity_ = TimeFunction(config.velocity, config.table, constants, what + " velocity");
  gradient_ = TimeFunction(config.gradient == WallGradient::given ? config.gradient_expression : "0", {},
                           constants, what + " gradient");
}

template <int D>
void MovingWall<D>::prepare(const Grid<D>& grid, const NodeField<D>& nodes, double small_mass, double t,
                            double dt, std::int32_t owner, std::vector<PrescribedVelocity<D>>& out,
                            const Comm& comm) {
  const int a = config_.axis;
  const double h = grid.cell_size()[a];
  const double lo = grid.origin()[a];
  const int n_a = grid.n_cells()[a];
  const int ghost = grid.ghost_layers();
  const double x_w = position_;
  if (!(x_w >= lo - 1e-12 * h && x_w <= lo + n_a * h + 1e-12 * h))
    throw SimulationFailure(-1, "wall",
                            "wall '" + config_.name + "' left the grid (position " + std::to_string(x_w) + ")");
  const double vb0 = velocity_(t), vb1 = velocity_(t + dt);
  position_end_ = x_w + 0.5 * (vb0 + vb1) * dt;
  const double x_w_end = position_end_;
  // Moving from the wall into the material is direction `into` along the axis.
  const double into = config_.inside_below ? -1.0 : 1.0;
  const double depth = config_.depth * h;
  auto node_x = [&](int j) { return lo + j * h; };
  auto depth_of = [&](int j) { return into * (node_x(j) - x_w); };
  const double tol = 1e-9 * h;

  // Nodes 1 and 2 of Eq. 4 along the axis: node 2 is the deepest controlled node inside (or the
  // shallowest inside node when none is controlled), node 1 the next one deeper.
  // Start from the inside node nearest the wall and step inwards while the next one is within d.
  const int step = into > 0 ? 1 : -1;
  int j2 = static_cast<int>(into > 0 ? std::ceil((x_w - lo) / h - 1e-9) : std::floor((x_w - lo) / h + 1e-9));
  while (depth_of(j2 + step) <= depth + tol) j2 += step;
  const int j1 = j2 + step;

  // Transverse lines: odometer over the other axes' stored nodes.
  IVec<D> first = IVec<D>::Zero(), count = IVec<D>::Ones();
  for (int b = 0; b < D; ++b) {
    if (b == a) continue;
    first[b] = grid.first_node(b);
    count[b] = grid.stored_nodes(b);
  }
  long long n_lines = 1;
  for (int b = 0; b < D; ++b) n_lines *= count[b];
  auto line_node = [&](long long line, int j) {
    IVec<D> m;
    long long rem = line;
    for (int b = 0; b < D; ++b) {
      if (b == a) {
        m[b] = j;
        continue;
      }
      m[b] = first[b] + static_cast<int>(rem % count[b]);
      rem /= count[b];
    }
    return grid.node_index(m);
  };

  double g0 = 0.0, g1 = 0.0;
  if (config_.gradient == WallGradient::given) {
    g0 = gradient_(t);
    g1 = gradient_(t + dt);
  } else if (config_.gradient == WallGradient::estimate) {
    // seed 000 Eq. 4, per line, lines weighted by m1 + m2. Summed exactly over the lines this
    // rank owns (by node 1), then over the ranks: the same for every partition.
    const double dx1 = node_x(j1) - x_w, dx2 = node_x(j2) - x_w;
    ExactSum sums[2];
    ExactSum& num = sums[0];
    ExactSum& den = sums[1];
    for (long long line = 0; line < n_lines; ++line) {
      const std::int32_t i1 = line_node(line, j1), i2 = line_node(line, j2);
      if (i1 < 0 || i2 < 0 || !grid.owns(i1)) continue;
      const double m1 = nodes.mass[i1], m2 = nodes.mass[i2];
      if (m1 <= small_mass || m2 <= small_mass) continue;
      const double dv1 = nodes.momentum[i1][a] / m1 - vb0, dv2 = nodes.momentum[i2][a] / m2 - vb0;
      num.add((m1 + m2) * (dv1 * dx1 + dv2 * dx2));
      den.add((m1 + m2) * (dx1 * dx1 + dx2 * dx2));
    }
    sum_across(comm, sums, 2);
    g0 = g1 = den.value() > 0.0 ? num.value() / den.value() : 0.0;
  }
  velocity_start_ = vb0;
  gradient_start_ = g0;

  Vec<D> e = Vec<D>::Zero();
  e[a] = 1.0;
  for (int j = -ghost; j <= n_a + ghost; ++j) {
    const double dj = depth_of(j);
    const bool inside = dj >= -tol && dj <= depth + tol;
    const bool outside = dj < -tol;
    if (!inside && !outside) continue;
    const double xj = node_x(j);
    const double start = vb0 + g0 * (xj - x_w), end = vb1 + g1 * (xj - x_w_end);
    for (long long line = 0; line < n_lines; ++line) {
      const std::int32_t i = line_node(line, j);
      if (i < 0) continue;
      if (!(nodes.mass[i] > small_mass)) continue;  // no material at the node: nothing to control
      out.push_back({i, owner, e, start, end});
    }
  }
}

template class MovingWall<1>;
template class MovingWall<2>;
template class MovingWall<3>;

}  // namespace cairn
