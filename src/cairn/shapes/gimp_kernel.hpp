// The GIMP family of tensor-product kernels: a grid function (linear or quadratic B-spline)
// convolved with each particle's box, whose half-width per axis is chosen by a policy:
//   ugimp   one smoothing length l for every particle (seed 003 Sec. 4.1)
//   gimp    the particle's initial size l_p0 (seed 003 Sec. 3.3, "standard GIMP")
//   cpgimp  l_p0 * |F_aa|, the size stretched by the diagonal of F (seed 003 Sec. 3.3)
//   b2gimp  l_p0 with the quadratic B-spline grid function (seed 000 Sec. 2.1)
// The weights are the exact integrals of seed 000 Sec. 2.1 over the (axis-aligned) box.
#pragma once

#include <algorithm>
#include <cmath>

#include "cairn/shapes/tensor_product.hpp"

namespace cairn {

/// 1D kernel for build_tensor_product. HalfWidth: double operator()(particles, p, axis) giving the
/// box half-width in cells.
template <int D, class Fn, class HalfWidth>
struct ConvolvedKernel {
  HalfWidth half_width;
  int cap = 0;  ///< nodes per axis for this step, from prepare()

  /// Widest stencil over the particles of this step.
  void prepare(const Particles<D>& parts) {
    double amax = 0.0;
    const auto n = static_cast<std::int64_t>(parts.n());
#pragma omp parallel for reduction(max : amax) schedule(static)
    for (std::int64_t p = 0; p < n; ++p)
      for (int a = 0; a < D; ++a) amax = std::max(amax, half_width(parts, static_cast<std::size_t>(p), a));
    cap = convolved_width<Fn>(amax);
  }
  int width(const Particles<D>&) const { return cap; }
  int eval(const Particles<D>& parts, std::size_t p, int a, double xi, double* w, double* dw) const {
    return convolved_weights<Fn>(xi, half_width(parts, p, a), cap, w, dw);
  }
};

/// Build the stencils of a convolved family in one call.
template <int D, class Fn, class HalfWidth>
void build_convolved(HalfWidth half_width, const Grid<D>& grid, const Particles<D>& particles,
                     TransferCache<D>& cache) {
  ConvolvedKernel<D, Fn, HalfWidth> kernel{half_width};
  kernel.prepare(particles);
  build_tensor_product(kernel, grid, particles, cache);
}

}  // namespace cairn
