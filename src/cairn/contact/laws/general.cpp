// general: any sliding traction S_slide(N_c, v_slip, t) given as an expression (seed 004 Eq. 9-10
// with the corrected sign of Eq. 10): dp = (dp0.n) n + min(S_slide A_c dt, |dp0_t|) t, where
// N_c = -dp0.n / (A_c dt) and v_slip = |dp0_t| / m_red is the tangential speed of beta relative
// to alpha before the correction.
#include <muParser.h>
#include <omp.h>

#include <memory>
#include <stdexcept>
#include <vector>

#include "cairn/config/plugin_keys.hpp"
#include "cairn/contact/law.hpp"

namespace cairn {
namespace {

class GeneralContact final : public ContactLaw {
 public:
  GeneralContact(const ContactLawConfig& c, const Constants& constants) {
    const std::string slide = c.plugin.text("slide");
    const int n = std::max(1, omp_get_max_threads());
    for (int k = 0; k < n; ++k) {
      auto e = std::make_unique<Evaluator>();
      try {
        e->parser.DefineVar("Nc", &e->nc);
        e->parser.DefineVar("vslip", &e->vslip);
        e->parser.DefineVar("t", &e->t);
        e->parser.DefineConst("pi", 3.141592653589793238462643383279502884);
        for (const auto& [name, value] : constants) e->parser.DefineConst(name, value);
        e->parser.SetExpr(slide);
        e->parser.Eval();
      } catch (const mu::Parser::exception_type& err) {
        throw std::invalid_argument("contact law general: slide expression \"" + slide + "\": " + err.GetMsg() +
                                    " (variables: Nc, vslip, t)");
      }
      evaluators_.push_back(std::move(e));
    }
  }
  [[nodiscard]] Vec3 momentum_change(const ContactInput& in) const override {
    const double dn = in.dp0.dot(in.normal);
    const double area_dt = in.area * in.dt;
    Evaluator& e = *evaluators_[static_cast<std::size_t>(omp_get_thread_num()) % evaluators_.size()];
    e.nc = area_dt > 0.0 ? -dn / area_dt : 0.0;
    e.vslip = in.reduced_mass > 0.0 ? (in.dp0 - dn * in.normal).norm() / in.reduced_mass : 0.0;
    e.t = in.time;
    return sliding_change(in, std::max(0.0, e.parser.Eval()));
  }

 private:
  struct Evaluator {
    mu::Parser parser;
    double nc = 0.0, vslip = 0.0, t = 0.0;
  };
  std::vector<std::unique_ptr<Evaluator>> evaluators_;
};

}  // namespace

CAIRN_DECLARE_KEYS(general, {"general", {"contact", "contact_pair"}, {
    Key("", "slide", KeyType::expression,
      "general: sliding traction S_slide as an expression in Nc (normal traction), "
      "vslip (tangential slip speed), t and [constants]; capped at the stick value.")
      .by_default("\"0\"")
      .variables({"Nc", "vslip", "t"})}, {}, "dynamic_friction"});

namespace {
CAIRN_REGISTER_CONTACT_LAW(GeneralContact, "general",
                           "sliding traction from the slide expression in Nc, vslip, t");

}  // namespace
}  // namespace cairn
