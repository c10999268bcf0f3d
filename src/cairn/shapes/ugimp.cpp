// uGIMP: the linear grid function convolved with one box of width l for every particle, the
// smoothing length left as a free parameter (seed 003 Sec. 4.1; seed 000 Sec. 2.1 integrates the
// undeformed domain translated to the particle). With a = l / (2h) the 1D weight is
//     S(xi) = [Phi(xi + a) - Phi(xi - a)] / (2a),   S'(xi) = [N(xi + a) - N(xi - a)] / (2a)
// where N is the hat function and Phi its integral. This is the exact integral for any a, so
// l = h reproduces the quadratic B-spline and l -> 0 the linear functions (seed 003 Sec. 4.1).
// method.smoothing_length = 0 takes each particle's initial size instead (then uGIMP = GIMP).
#include <algorithm>

#include "cairn/config/config.hpp"
#include "cairn/config/plugin_keys.hpp"
#include "cairn/shapes/gimp_kernel.hpp"

namespace cairn {
namespace {

template <int D>
class UGimp final : public ShapeFamily<D> {
 public:
  explicit UGimp(const ShapeContext& ctx) : smoothing_length_(ctx.method.plugin.real("smoothing_length")) {}
  int ghost_layers() const override { return 2; }
  void build(const Grid<D>& g, const Particles<D>& p, TransferCache<D>& c) const override {
    const Vec<D> h = g.cell_size();
    const double l = smoothing_length_;
    build_convolved<D, LinearGridFunction>(
        [h, l](const Particles<D>& parts, std::size_t q, int a) {
          return 0.5 * (l > 0.0 ? l : parts.size0[q][a]) / h[a];
        },
        g, p, c);
  }

 private:
  double smoothing_length_;
};

}  // namespace
/// uGIMP reaches l/2 + h beyond a particle; two ghost layers hold that for l <= 2h.
std::optional<KeyProblem> check_smoothing_length(const Config& c) {
  if (c.method.shape != "ugimp" || c.grid.cell_size.empty()) return std::nullopt;
  const double l = c.method.plugin.real("smoothing_length");
  const double h_min = *std::min_element(c.grid.cell_size.begin(), c.grid.cell_size.end());
  if (!(l > 2.0 * h_min * (1.0 + 1e-12))) return std::nullopt;
  return KeyProblem{"smoothing_length",
                    fmt::format("a uGIMP smoothing length of at most twice the smallest cell size ({})",
                                real_text(2.0 * h_min)),
                    real_text(l)};
}

CAIRN_DECLARE_KEYS(ugimp, {"ugimp", {"method"}, {
    Key("", "smoothing_length", KeyType::real,
      "uGIMP smoothing length l (full width of the particle function); 0 = the "
      "initial particle size. At most twice the smallest cell size.")
      .by_default("0.0")
      .min(0.0)}, check_smoothing_length, "stress_update"});
CAIRN_REGISTER_SHAPE(UGimp, "ugimp",
                     "uniform GIMP: linear functions integrated over a box of width "
                     "method.smoothing_length (0: the initial particle size) (seed 003 Sec. 4.1)");
}  // namespace cairn
