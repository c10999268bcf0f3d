// uGIMP: the linear grid function convolved with the undeformed particle domain translated to the
// particle (seed 000 Sec. 2.1, S_pi = (1/V_p) int_{V_p} N_i dx; seed 003 Eq. 26-29 with l fixed).
// With smoothing length l the 1D weight is
//     S(xi) = [Phi(xi + a) - Phi(xi - a)] / (2a),   S'(xi) = [N(xi + a) - N(xi - a)] / (2a)
// where a = l / (2h), N is the hat function and Phi its integral. This is the exact integral for
// any a, so l = h reproduces the quadratic B-spline and l -> 0 the linear functions (seed 003 4.1).
#include "cairn/shapes/tensor_product.hpp"

namespace cairn {
namespace {

template <int D>
struct GimpKernel {
  double smoothing_length = 0.0;  // 0: each particle's own initial size
  Vec<D> h;
  int cap = 0;  // slots per axis for this step, set by max_width() before the build

  double half_width(const Particles<D>& parts, std::size_t p, int a) const {
    const double l = smoothing_length > 0.0 ? smoothing_length : parts.size0[p][a];
    return 0.5 * l / h[a];
  }
  int width(const Particles<D>&) const { return cap; }
  int max_width(const Particles<D>& parts) const {
    double amax = 0.0;
    if (smoothing_length > 0.0) {
      amax = 0.5 * smoothing_length / h.minCoeff();
    } else {
      for (std::size_t p = 0; p < parts.n(); ++p)
        for (int a = 0; a < D; ++a) amax = std::max(amax, half_width(parts, p, a));
    }
    return static_cast<int>(std::floor(2.0 + 2.0 * amax)) + 1;
  }
  int eval(const Particles<D>& parts, std::size_t p, int a, double xi, double* w, double* dw) const {
    const double hw = half_width(parts, p, a);
    const int first = static_cast<int>(std::ceil(xi - 1.0 - hw));
    const int last = static_cast<int>(std::floor(xi + 1.0 + hw));
    const int n = last - first + 1;
    for (int k = 0; k < cap; ++k) {
      w[k] = 0.0;
      dw[k] = 0.0;
    }
    for (int k = 0; k < n && k < cap; ++k) {
      const double s = xi - (first + k);
      if (hw < 1e-12) {  // point particle: the linear function
        w[k] = hat(s);
        dw[k] = (std::abs(s) < 1.0) ? (s > 0 ? -1.0 : 1.0) : 0.0;
      } else {
        w[k] = (hat_integral(s + hw) - hat_integral(s - hw)) / (2.0 * hw);
        // S depends on xi only through s = xi - node, so dS/dxi = dS/ds.
        dw[k] = (hat(s + hw) - hat(s - hw)) / (2.0 * hw);
      }
    }
    return first;
  }
};

template <int D>
class UGimp final : public ShapeFamily<D> {
 public:
  explicit UGimp(const ShapeContext& ctx) : smoothing_length_(ctx.method.smoothing_length) {}
  int ghost_layers() const override { return 2; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    GimpKernel<D> kernel{smoothing_length_, g.cell_size()};
    kernel.cap = kernel.max_width(p);
    build_tensor_product(kernel, g, p, c);
  }

 private:
  double smoothing_length_;
};

}  // namespace
CAIRN_REGISTER_SHAPE(UGimp, "ugimp",
                     "undeformed GIMP: linear functions integrated over the initial particle "
                     "domain, smoothing length method.smoothing_length (seed 003 Sec. 4.1)");
}  // namespace cairn
