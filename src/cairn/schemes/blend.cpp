// FLIP/P blend, seed 002 Sec. 1.4.4 (Eq. 1.79-1.80, 1.91-1.92): a fraction beta of FLIP and
// (1 - beta) of an update with projection P. P V = S m~_k^-1 p is the XPIC(k) projector of
// seed 000 Sec. 2.2 (k = method.order; k = 1 gives P = S S+, i.e. PIC):
//     V^(n+1) = beta V + (1 - beta) P V + S a dt
//     VV = S v                              (blend_position = "grid")
//     VV = beta S v + (1 - beta) P V        (blend_position = "projected")
#include "cairn/config/plugin_keys.hpp"
#include "cairn/schemes/scheme.hpp"

namespace cairn {
namespace {

template <int D>
class Blend final : public UpdateScheme<D> {
 public:
  explicit Blend(const MethodConfig& m) : beta_(m.plugin.real("beta")), projected_(m.plugin.text("blend_position") == "projected") {}
  FullMass full_mass() const override { return FullMass::of_initial; }
  Effective<D> effective(const GridAtParticle<D>& g) const override {
    const Vec<D>& PV = g.Sv_full;
    const Vec<D> a_dt = (1.0 - beta_) * (PV - g.V) + (g.Sv_new - g.Sv);
    const Vec<D> vv = projected_ ? Vec<D>(beta_ * g.Sv + (1.0 - beta_) * PV) : g.Sv;
    return {a_dt, vv};
  }

 private:
  double beta_;
  bool projected_;
};

}  // namespace
CAIRN_DECLARE_KEYS(blend, {"blend", {"method"}, {
    Key("", "beta", KeyType::real,
      "FLIP fraction beta of the `blend` update (seed 002 Eq. 1.79).")
      .by_default("0.99")
      .min(0.0)
      .max(1.0),
    Key("", "blend_position", KeyType::string,
      "Effective velocity of the `blend` update: grid = S v, projected = "
      "beta S v + (1 - beta) P V (seed 002 Eq. 1.80).")
      .by_default("\"grid\"")
      .choices([] { return std::vector<std::string>{"grid", "projected"}; })}, {}, "cpdi_max_span"});
CAIRN_REGISTER_SCHEME(Blend, "blend", "beta FLIP + (1 - beta) XPIC(k)-projected update (seed 002 Eq. 1.79-1.80)");
}  // namespace cairn
