// One-dimensional grid functions N(s) in cell units (s = x / h - node) and the pieces every family
// builds from them:
//   - the linear tent (seed 003 Eq. 17) and the node-centred quadratic B-spline (seed 003 Eq. 21),
//     each with its derivative and its antiderivative from -infinity;
//   - their convolution with a particle box of half-width a (cells): the GIMP weight
//         S(xi) = [Phi(xi - j + a) - Phi(xi - j - a)] / (2a),  S' = [N(xi - j + a) - N(xi - j - a)] / (2a)
//     (seed 000 Sec. 2.1, S_pi = (1/V_p) int_{V_p} N_i dx; seed 003 Eq. 26-29), exact for any a;
//   - the uniform quadratic and cubic B-spline weights of the nodes around a point.
// Everything here is per axis; multi-D families take tensor products (seed 003 Eq. 18).
#pragma once

#include <algorithm>
#include <cmath>

namespace cairn {

/// Hat function N(s) = max(0, 1 - |s|) (seed 003 Eq. 17) and its antiderivative from -inf.
inline double hat(double s) { return std::max(0.0, 1.0 - std::abs(s)); }
/// Right derivative of hat (so that the gradients of the two nodes of a cell sum to zero even for
/// a point exactly on a node).
inline double hat_derivative(double s) {
  if (s >= -1.0 && s < 0.0) return 1.0;
  if (s >= 0.0 && s < 1.0) return -1.0;
  return 0.0;
}
inline double hat_integral(double s) {
  if (s <= -1.0) return 0.0;
  if (s <= 0.0) return 0.5 * (s + 1.0) * (s + 1.0);
  if (s <= 1.0) return 1.0 - 0.5 * (1.0 - s) * (1.0 - s);
  return 1.0;
}

/// Node-centred quadratic B-spline (seed 003 Eq. 21 with h = 1), support |s| < 3/2.
inline double quadratic_spline(double s) {
  const double r = std::abs(s);
  if (r < 0.5) return 0.75 - r * r;
  if (r < 1.5) return 0.5 * (1.5 - r) * (1.5 - r);
  return 0.0;
}
inline double quadratic_spline_derivative(double s) {
  const double r = std::abs(s);
  const double sign = s < 0.0 ? -1.0 : 1.0;
  if (r < 0.5) return -2.0 * s;
  if (r < 1.5) return -sign * (1.5 - r);
  return 0.0;
}
/// Antiderivative of quadratic_spline from -inf (a piecewise cubic from 0 to 1).
inline double quadratic_spline_integral(double s) {
  if (s <= -1.5) return 0.0;
  if (s <= -0.5) return (s + 1.5) * (s + 1.5) * (s + 1.5) / 6.0;
  if (s <= 0.5) return 1.0 / 6.0 + 0.75 * (s + 0.5) - (s * s * s + 0.125) / 3.0;
  if (s <= 1.5) return 1.0 - (1.5 - s) * (1.5 - s) * (1.5 - s) / 6.0;
  return 1.0;
}

/// The linear grid function as a type, for families written once for both grid functions.
struct LinearGridFunction {
  static constexpr double support = 1.0;  ///< N(s) = 0 for |s| >= support
  static double value(double s) { return hat(s); }
  static double derivative(double s) { return hat_derivative(s); }
  static double integral(double s) { return hat_integral(s); }
  /// First node with a possibly non-zero N at xi, and the number of such nodes (2).
  static int first_node(double xi) { return static_cast<int>(std::floor(xi)); }
  static constexpr int n_nodes = 2;
  /// Values at the n_nodes nodes from first_node(xi); returns first_node(xi).
  static int weights(double xi, double* w) {
    const double f = std::floor(xi);
    weights_from(xi, static_cast<int>(f), w);
    return static_cast<int>(f);
  }
  /// weights(xi, w) when first_node(xi) is already known (the same values to the last bit).
  static void weights_from(double xi, int first, double* w) {
    w[1] = xi - first;
    w[0] = 1.0 - w[1];
  }
};

/// The quadratic B-spline grid function (B2GIMP, B2CPDI of seed 000 Sec. 2.1).
struct QuadraticGridFunction {
  static constexpr double support = 1.5;
  static double value(double s) { return quadratic_spline(s); }
  static double derivative(double s) { return quadratic_spline_derivative(s); }
  static double integral(double s) { return quadratic_spline_integral(s); }
  static int first_node(double xi) { return static_cast<int>(std::floor(xi + 0.5)) - 1; }
  static constexpr int n_nodes = 3;
  static int weights(double xi, double* w) {
    const int first = first_node(xi);
    weights_from(xi, first, w);
    return first;
  }
  /// weights(xi, w) when first_node(xi) is already known (the same values to the last bit).
  static void weights_from(double xi, int first, double* w) {
    const double d = xi - (first + 1);
    w[0] = 0.5 * (0.5 - d) * (0.5 - d);
    w[1] = 0.75 - d * d;
    w[2] = 0.5 * (0.5 + d) * (0.5 + d);
  }
};

/// Most nodes per axis a box of half-width a (cells) convolved with grid function Fn can touch.
template <class Fn>
int convolved_width(double a) {
  return static_cast<int>(std::floor(2.0 * Fn::support + 2.0 * a)) + 1;
}

/// GIMP weights of grid function Fn convolved with a box of half-width a (cells) centred at xi:
/// fills `cap` entries of w and dw (d/dxi, per cell) for nodes first, first+1, ... and returns
/// first. Entries beyond the support are zero. a < 1e-12 gives Fn itself (a point particle).
template <class Fn>
int convolved_weights(double xi, double a, int cap, double* w, double* dw) {
  const int first = static_cast<int>(std::ceil(xi - Fn::support - a));
  for (int k = 0; k < cap; ++k) {
    const double s = xi - (first + k);
    if (a < 1e-12) {
      w[k] = Fn::value(s);
      dw[k] = Fn::derivative(s);
    } else {
      // S depends on xi only through s = xi - node, so dS/dxi = dS/ds.
      w[k] = (Fn::integral(s + a) - Fn::integral(s - a)) / (2.0 * a);
      dw[k] = (Fn::value(s + a) - Fn::value(s - a)) / (2.0 * a);
    }
  }
  return first;
}

/// Uniform quadratic B-spline weights of the three nodes c-1, c, c+1 nearest xi (seed 003 Eq. 21);
/// returns c - 1.
inline int quadratic_spline_weights(double xi, double* w, double* dw) {
  const double c = std::floor(xi + 0.5);
  const double d = xi - c;  // in [-1/2, 1/2); distances to the nodes are d+1, d, d-1
  w[0] = 0.5 * (0.5 - d) * (0.5 - d);
  w[1] = 0.75 - d * d;
  w[2] = 0.5 * (0.5 + d) * (0.5 + d);
  dw[0] = d - 0.5;
  dw[1] = -2.0 * d;
  dw[2] = d + 0.5;
  return static_cast<int>(c) - 1;
}

/// Uniform cubic B-spline weights of the four nodes f-1 .. f+2 around xi (f = floor(xi));
/// returns f - 1.
inline int cubic_spline_weights(double xi, double* w, double* dw) {
  const double f = std::floor(xi);
  const double t = xi - f;
  const double u = 1.0 - t;
  w[0] = u * u * u / 6.0;
  w[1] = (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0;
  w[2] = (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0;
  w[3] = t * t * t / 6.0;
  dw[0] = -0.5 * u * u;
  dw[1] = (9.0 * t * t - 12.0 * t) / 6.0;
  dw[2] = (-9.0 * t * t + 6.0 * t + 3.0) / 6.0;
  dw[3] = 0.5 * t * t;
  return static_cast<int>(f) - 1;
}

}  // namespace cairn
