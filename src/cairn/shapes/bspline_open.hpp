// Open-knot boundary B-splines (seed 003 Sec. 3.2, Eq. 22-23): along each non-periodic axis the
// knots are the grid nodes x_0 .. x_n, with the end knots repeated so that they appear P + 1 times
// (P = degree, order k = P + 1):
//     t = [x_0 (P+1 times), x_1, ..., x_{n-1}, x_n (P+1 times)],
// which gives n + P basis functions per axis, computed with the Cox-de Boor recursion of Eq. 22
// (0/0 terms dropped) from the indicator functions of Eq. 23. The first and the last function
// equal 1 on their face and every other function vanishes there, so a velocity condition on that
// one value holds exactly on the face: no ghost nodes take part (seed 003 Sec. 6.2, Fig. 3).
//
// Note on the knot multiplicity: seed 003 says the end knots are repeated k - 1 times but counts
// N + k - 2 functions for N knots and requires them to be 1 on the boundary; both the count and
// the boundary value need the end knots repeated k = P + 1 times (the usual open, or clamped,
// knot vector), which is what is implemented here.
//
// Storage: the n + P values of an axis live in the grid's node slots. Function 0 (value 1 on the
// lower face) sits at node 0, the last function (1 on the upper face) at node n, and the interior
// functions in the other slots; the P - 1 functions that have no node of their own go to ghost
// slots:
//     P = 2 (n + 2 functions, Greville points 0, 1/2, 3/2, ..., n - 1/2, n):
//         node 0 <- f_0, node j <- f_j (j = 1 .. n-1, centre j - 1/2), node n+1 <- f_n, node n <- f_{n+1}
//     P = 3 (n + 3 functions, Greville points 0, 1/3, 1, 2, ..., n - 1, n - 1/3, n):
//         node 0 <- f_0, node -1 <- f_1, node j <- f_{j+1} (j = 1 .. n-1, centre j),
//         node n+1 <- f_{n+1}, node n <- f_{n+2}
// dof_position() gives each slot's Greville point. Along a periodic axis the family is the
// uniform B-spline of the same degree.
#pragma once

#include <algorithm>
#include <array>
#include <climits>

#include "cairn/shapes/tensor_product.hpp"

namespace cairn {

/// Open-knot B-splines of degree P on n cells (cell units, domain [0, n]).
template <int P>
struct OpenKnotAxis {
  int n = 1;

  [[nodiscard]] double knot(int i) const { return static_cast<double>(std::clamp(i - P, 0, n)); }

  /// Values and derivatives of the P + 1 functions non-zero at xi in [0, n]; returns the index of
  /// the first one. Eq. 22 applied degree by degree from the indicator of the knot span (Eq. 23).
  int eval(double xi, double* w, double* dw) const {
    const int c = std::clamp(static_cast<int>(std::floor(xi)), 0, n - 1);
    const int mu = c + P;  // knot span: t_mu <= xi < t_mu+1 (xi = n uses the last span)
    // val[k][m]: degree-k function with index mu - P + m, m = 0 .. P.
    std::array<std::array<double, P + 1>, P + 1> val{};
    val[0][P] = 1.0;
    for (int k = 1; k <= P; ++k) {
      for (int i = mu - k; i <= mu; ++i) {
        const int m = i - (mu - P);
        double v = 0.0;
        const double dl = knot(i + k) - knot(i);
        if (i >= mu - (k - 1) && dl > 0.0) v += (xi - knot(i)) / dl * val[k - 1][m];
        const double dr = knot(i + k + 1) - knot(i + 1);
        if (i + 1 <= mu && dr > 0.0) v += (knot(i + k + 1) - xi) / dr * val[k - 1][m + 1];
        val[k][m] = v;
      }
    }
    for (int m = 0; m <= P; ++m) {
      const int i = mu - P + m;
      double d = 0.0;
      const double dl = knot(i + P) - knot(i);
      if (m >= 1 && dl > 0.0) d += val[P - 1][m] / dl;
      const double dr = knot(i + P + 1) - knot(i + 1);
      if (m + 1 <= P && dr > 0.0) d -= val[P - 1][m + 1] / dr;
      w[m] = val[P][m];
      dw[m] = P * d;
    }
    return mu - P;
  }

  /// Node slot (multi-index along the axis) that stores function d.
  [[nodiscard]] int slot_of(int d) const {
    if (d == 0) return 0;
    if constexpr (P == 2) {
      if (d <= n - 1) return d;
      return d == n ? n + 1 : n;
    } else {
      static_assert(P == 3, "open-knot splines are implemented for degrees 2 and 3");
      if (d == 1) return -1;
      if (d <= n) return d - 1;
      return d == n + 1 ? n + 1 : n;
    }
  }
  /// Function stored at node slot j (inverse of slot_of); -1 if the slot is unused.
  [[nodiscard]] int function_at(int j) const {
    for (int d = 0; d < n + P; ++d)
      if (slot_of(d) == j) return d;
    return -1;
  }
  /// Greville abscissa (knot average) of function d: sum_d N_d(xi) greville(d) = xi.
  [[nodiscard]] double greville(int d) const {
    double s = 0.0;
    for (int m = 1; m <= P; ++m) s += knot(d + m);
    return s / P;
  }
};

template <int D, int P>
struct OpenKnotKernel {
  std::array<OpenKnotAxis<P>, D> axis{};
  std::array<bool, D> periodic{};

  int width(const Particles<D>&) const { return P + 1; }
  int eval(const Particles<D>&, std::size_t, int a, double xi, double* w, double* dw) const {
    if (periodic[a]) return P == 2 ? quadratic_spline_weights(xi, w, dw) : cubic_spline_weights(xi, w, dw);
    const int first = axis[a].eval(xi, w, dw);
    // Beyond a face there is no basis: report the particle as outside the grid.
    if (xi < 0.0 || xi > axis[a].n) return outside;
    return first;
  }
  int node_of(int a, int first, int k) const {
    if (periodic[a]) return first + k;
    if (first == outside) return outside;
    return axis[a].slot_of(first + k);
  }
  static constexpr int outside = INT_MIN / 4;
};

template <int D, int P>
class OpenKnotSpline : public ShapeFamily<D> {
 public:
  int ghost_layers() const override { return 1; }
  FaceBasis face_basis() const override { return FaceBasis::open_knot; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    build_tensor_product(kernel(g), g, p, c);
  }
  Vec<D> dof_position(const Grid<D>& g, std::int32_t index) const override {
    const auto k = kernel(g);
    const IVec<D> j = g.multi_index(index);
    Vec<D> x = g.node_position(index);
    for (int a = 0; a < D; ++a) {
      if (k.periodic[a]) continue;
      const int d = k.axis[a].function_at(j[a]);
      if (d >= 0) x[a] = g.origin()[a] + k.axis[a].greville(d) * g.cell_size()[a];
    }
    return x;
  }

 private:
  static OpenKnotKernel<D, P> kernel(const Grid<D>& g) {
    OpenKnotKernel<D, P> k;
    for (int a = 0; a < D; ++a) {
      k.axis[a].n = g.n_cells()[a];
      k.periodic[a] = g.periodic(a);
    }
    return k;
  }
};

}  // namespace cairn
