// frictionless: only the normal part of the stick change, dp = (dp0.n) n (S_slide = 0 in
// seed 004 Eq. 8-10).
#include "cairn/contact/law.hpp"

namespace cairn {
namespace {

class FrictionlessContact final : public ContactLaw {
 public:
  FrictionlessContact(const ContactLawConfig&, const Constants&) {}
  [[nodiscard]] Vec3 momentum_change(const ContactInput& in) const override {
    return in.dp0.dot(in.normal) * in.normal;
  }
};

CAIRN_REGISTER_CONTACT_LAW(FrictionlessContact, "frictionless", "normal contact only, free sliding");

}  // namespace
}  // namespace cairn
