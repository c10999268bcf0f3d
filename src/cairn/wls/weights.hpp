// The two grid functions of the weighted-least-squares PIC method (seed 001 Sec. 3.1), "see
// wide, apply narrow": the wide quadratic weight W collects particle data into the node fits,
// the narrow linear shape S and its gradient G apply node values to particles and quadrature
// points. All are 1D functions of r = x - x_i (node i at x_i); D-dimensional values are tensor
// products. h is the cell size along the axis.
#pragma once

#include <cmath>

namespace cairn::wls {

/// Wide weight W_i(r), 3 nodes of support per axis (seed 001 Eq. 4).
inline double wide_weight(double r, double h) {
  const double a = std::abs(r);
  if (a < 0.5 * h) return 0.75 - (r * r) / (h * h);
  if (a < 1.5 * h) return (1.5 * h - a) * (1.5 * h - a) / (2.0 * h * h);
  return 0.0;
}

/// Narrow shape S_i(r) = 1 - |r|/h inside one cell of the node (seed 001 Eq. 5).
inline double narrow_shape(double r, double h) {
  const double a = std::abs(r);
  return a < h ? 1.0 - a / h : 0.0;
}

/// Gradient of the narrow shape, G_i(r) = -sign(r)/h with sign(0) = 1 (seed 001 Eq. 6).
inline double narrow_gradient(double r, double h) {
  if (std::abs(r) >= h) return 0.0;
  return r < 0.0 ? 1.0 / h : -1.0 / h;
}

}  // namespace cairn::wls
