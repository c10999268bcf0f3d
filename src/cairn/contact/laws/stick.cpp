// stick: no slip while in contact (dp = dp0, seed 004 Eq. 8 with k = 0); the fields separate
// freely when detection finds them apart or moving apart.
#include "cairn/contact/law.hpp"

namespace cairn {
namespace {

class StickContact final : public ContactLaw {
 public:
  StickContact(const ContactLawConfig&, const Constants&) {}
  [[nodiscard]] Vec3 momentum_change(const ContactInput& in) const override { return in.dp0; }
};

CAIRN_REGISTER_CONTACT_LAW(StickContact, "stick", "no slip in contact, free separation");

}  // namespace
}  // namespace cairn
