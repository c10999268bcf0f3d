// coulomb: stick while the tangential traction needed is at most mu_s N_c, otherwise slide with
// S_slide = mu_d N_c (seed 004 Sec. 2.2, S_slide = min(mu N_c, dp0.t / (A_c dt)) for mu_s = mu_d).
#include "cairn/config/plugin_keys.hpp"
#include "cairn/contact/law.hpp"

#include <cmath>

namespace cairn {
namespace {

class CoulombContact final : public ContactLaw {
 public:
  CoulombContact(const ContactLawConfig& c, const Constants&)
      : mu_static_(c.plugin.real("friction")),
        mu_dynamic_(c.plugin.real("dynamic_friction") < 0.0 ? mu_static_ : c.plugin.real("dynamic_friction")) {}
  [[nodiscard]] Vec3 momentum_change(const ContactInput& in) const override {
    const double dn = in.dp0.dot(in.normal);
    const double normal_impulse = -dn;  // N_c A_c dt >= 0 when approaching
    const double tangential = (in.dp0 - dn * in.normal).norm();
    if (tangential <= mu_static_ * normal_impulse) return in.dp0;  // sticks
    const double area_dt = in.area * in.dt;
    return sliding_change(in, area_dt > 0.0 ? mu_dynamic_ * normal_impulse / area_dt : 0.0);
  }

 private:
  double mu_static_, mu_dynamic_;
};

}  // namespace

// Keys of [contact] (every pair) and of a [[contact_pair]] (that pair).
CAIRN_DECLARE_KEYS(coulomb, {"coulomb", {"contact", "contact_pair"}, {
    Key("", "friction", KeyType::real,
      "Coulomb friction coefficient (static: the interface sticks while the tangential "
      "force needed is at most friction times the normal force).")
      .by_default("0.0")
      .min(0.0),
    Key("", "dynamic_friction", KeyType::real,
      "Coulomb sliding coefficient; negative = friction.")
      .by_default("-1.0")}, {}, "law"});

namespace {
CAIRN_REGISTER_CONTACT_LAW(CoulombContact, "coulomb",
                           "Coulomb friction: friction (static) and dynamic_friction (sliding)");

}  // namespace
}  // namespace cairn
