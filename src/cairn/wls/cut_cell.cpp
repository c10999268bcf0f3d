#include "cairn/wls/cut_cell.hpp"

#include <cmath>

namespace cairn::wls {
namespace {

/// Where the surface crosses the edge from inside corner xi (d_i > 0) to outside corner xo
/// (d_o <= 0): the zero of the linear interpolant (seed 001 Eq. 18).
template <int D>
Vec<D> edge_cut(const Vec<D>& xi, double di, const Vec<D>& xo, double dout) {
  return xi - di * (xi - xo) / (di - dout);
}

// ---- 2D: marching squares -------------------------------------------------------------------

/// Area and centroid of a simple polygon (shoelace), vertices counter-clockwise or clockwise.
CellRegion<2> polygon(const Vec<2>* v, int n) {
  double a2 = 0.0;
  Vec<2> m = Vec<2>::Zero();
  for (int k = 0; k < n; ++k) {
    const Vec<2>& p = v[k];
    const Vec<2>& q = v[(k + 1) % n];
    const double c = p[0] * q[1] - q[0] * p[1];
    a2 += c;
    m += c * (p + q);
  }
  CellRegion<2> r;
  r.volume = 0.5 * std::abs(a2);
  r.centroid = a2 != 0.0 ? Vec<2>(m / (3.0 * a2)) : Vec<2>(v[0]);
  return r;
}

int cut_square(const std::array<double, 4>& d, const Vec<2>& lo, const Vec<2>& h,
               std::array<CellRegion<2>, 2>& out) {
  // Local coordinates (relative to lo) keep the shoelace sums free of cancellation.
  std::array<Vec<2>, 4> x;
  for (int k = 0; k < 4; ++k) x[k] = Vec<2>((k & 1) ? h[0] : 0.0, (k & 2) ? h[1] : 0.0);
  int mask = 0;
  for (int k = 0; k < 4; ++k)
    if (d[k] > 0.0) mask |= 1 << k;
  if (mask == 0) return 0;
  if (mask == 15) {
    out[0].volume = h[0] * h[1];
    out[0].centroid = lo + 0.5 * h;
    return 1;
  }
  static constexpr int walk[4] = {0, 1, 3, 2};  // counter-clockwise corners
  const bool saddle = mask == 9 || mask == 6;
  if (saddle && 0.25 * (d[0] + d[1] + d[2] + d[3]) <= 0.0) {
    // Two separate corner triangles (Fig. 2 (e) made unambiguous by the centre value).
    int n = 0;
    for (int k : {0, 1, 2, 3}) {
      if (!(mask >> k & 1)) continue;
      const int nx = k ^ 1, ny = k ^ 2;  // the two edge neighbours
      const Vec<2> tri[3] = {x[k], edge_cut<2>(x[k], d[k], x[nx], d[nx]), edge_cut<2>(x[k], d[k], x[ny], d[ny])};
      out[n] = polygon(tri, 3);
      out[n].centroid += lo;
      ++n;
    }
    return n;
  }
  Vec<2> poly[8];
  int n = 0;
  for (int e = 0; e < 4; ++e) {
    const int a = walk[e], b = walk[(e + 1) % 4];
    const bool ia = d[a] > 0.0, ib = d[b] > 0.0;
    if (ia) poly[n++] = x[a];
    if (ia != ib) poly[n++] = ia ? edge_cut<2>(x[a], d[a], x[b], d[b]) : edge_cut<2>(x[b], d[b], x[a], d[a]);
  }
  out[0] = polygon(poly, n);
  out[0].centroid += lo;
  return 1;
}

// ---- 3D: Kuhn tetrahedra ----------------------------------------------------------------------

/// Volume and first moment (volume times centroid) of a tetrahedron.
struct Moment {
  double volume = 0.0;
  Vec<3> first = Vec<3>::Zero();
  void add_tet(const Vec<3>& a, const Vec<3>& b, const Vec<3>& c, const Vec<3>& e) {
    const double v = std::abs((b - a).dot((c - a).cross(e - a))) / 6.0;
    volume += v;
    first += v * 0.25 * (a + b + c + e);
  }
  void subtract(const Moment& o) {
    volume -= o.volume;
    first -= o.first;
  }
};

/// The six tetrahedra of the Kuhn decomposition: corner 0, +e_a, +e_a+e_b, corner 7 for every
/// permutation (a, b, c) of the axes.
constexpr std::array<std::array<int, 4>, 6> kuhn_tets() {
  constexpr int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::array<std::array<int, 4>, 6> t{};
  for (int k = 0; k < 6; ++k) t[k] = {0, 1 << perms[k][0], (1 << perms[k][0]) | (1 << perms[k][1]), 7};
  return t;
}

/// Positive part of one tetrahedron with vertex values v (linear interpolation).
Moment clip_tet(const std::array<Vec<3>, 4>& p, const std::array<double, 4>& v) {
  Moment m;
  int in[4], out[4], n_in = 0, n_out = 0;
  for (int k = 0; k < 4; ++k) (v[k] > 0.0 ? in[n_in++] : out[n_out++]) = k;
  auto cut = [&](int i, int o) { return edge_cut<3>(p[i], v[i], p[o], v[o]); };
  switch (n_in) {
    case 0:
      break;
    case 4:
      m.add_tet(p[0], p[1], p[2], p[3]);
      break;
    case 1: {
      const int a = in[0];
      m.add_tet(p[a], cut(a, out[0]), cut(a, out[1]), cut(a, out[2]));
      break;
    }
    case 3: {
      m.add_tet(p[0], p[1], p[2], p[3]);
      Moment corner;
      const int o = out[0];
      corner.add_tet(p[o], cut(in[0], o), cut(in[1], o), cut(in[2], o));
      m.subtract(corner);
      break;
    }
    case 2: {
      // Prism with end triangles (A, AC, AD) and (B, BC, BD), split into three tetrahedra.
      const int A = in[0], B = in[1], C = out[0], E = out[1];
      const Vec<3> a0 = p[A], a1 = cut(A, C), a2 = cut(A, E);
      const Vec<3> b0 = p[B], b1 = cut(B, C), b2 = cut(B, E);
      m.add_tet(a0, a1, a2, b2);
      m.add_tet(a0, a1, b1, b2);
      m.add_tet(a0, b0, b1, b2);
      break;
    }
  }
  return m;
}

int cut_cube(const std::array<double, 8>& d, const Vec<3>& lo, const Vec<3>& h,
             std::array<CellRegion<3>, 6>& out) {
  int mask = 0;
  for (int k = 0; k < 8; ++k)
    if (d[k] > 0.0) mask |= 1 << k;
  if (mask == 0) return 0;
  if (mask == 255) {
    out[0].volume = h.prod();
    out[0].centroid = lo + 0.5 * h;
    return 1;
  }
  static constexpr auto tets = kuhn_tets();
  std::array<Vec<3>, 8> x;
  for (int k = 0; k < 8; ++k)
    x[k] = Vec<3>((k & 1) ? h[0] : 0.0, (k & 2) ? h[1] : 0.0, (k & 4) ? h[2] : 0.0);
  std::array<Moment, 6> piece;
  for (int t = 0; t < 6; ++t) {
    std::array<Vec<3>, 4> p;
    std::array<double, 4> v;
    for (int k = 0; k < 4; ++k) {
      p[k] = x[tets[t][k]];
      v[k] = d[tets[t][k]];
    }
    piece[t] = clip_tet(p, v);
  }
  // Connected pieces: tetrahedra sharing a face (three common corners) of which a corner is inside.
  std::array<int, 6> root{0, 1, 2, 3, 4, 5};
  auto find = [&](int a) {
    while (root[a] != a) a = root[a];
    return a;
  };
  for (int s = 0; s < 6; ++s)
    for (int t = s + 1; t < 6; ++t) {
      if (piece[s].volume <= 0.0 || piece[t].volume <= 0.0) continue;
      int common = 0;
      bool inside_corner = false;
      for (int a : tets[s])
        for (int b : tets[t])
          if (a == b) {
            ++common;
            inside_corner |= d[a] > 0.0;
          }
      if (common == 3 && inside_corner) root[find(t)] = find(s);
    }
  int n = 0;
  std::array<int, 6> region_of{-1, -1, -1, -1, -1, -1};
  std::array<Moment, 6> sum;
  for (int t = 0; t < 6; ++t) {
    if (piece[t].volume <= 0.0) continue;
    const int r = find(t);
    if (region_of[r] < 0) region_of[r] = n++;
    sum[region_of[r]].volume += piece[t].volume;
    sum[region_of[r]].first += piece[t].first;
  }
  for (int r = 0; r < n; ++r) {
    out[r].volume = sum[r].volume;
    out[r].centroid = lo + sum[r].first / sum[r].volume;
  }
  return n;
}

}  // namespace

template <>
int cut_cell<2>(const std::array<double, 4>& d, const Vec<2>& lo, const Vec<2>& h,
                std::array<CellRegion<2>, 2>& out) {
  return cut_square(d, lo, h, out);
}

template <>
int cut_cell<3>(const std::array<double, 8>& d, const Vec<3>& lo, const Vec<3>& h,
                std::array<CellRegion<3>, 6>& out) {
  return cut_cube(d, lo, h, out);
}

}  // namespace cairn::wls
