// perfect: a bonded interface. Every node that sees both fields moves them with the centre-of-
// mass velocity, without detection (seed 004 Sec. 3.2: with perfect interfaces multimaterial
// MPM must revert to single-material MPM).
#include "cairn/contact/law.hpp"

namespace cairn {
namespace {

class PerfectContact final : public ContactLaw {
 public:
  PerfectContact(const ContactLawConfig&, const Constants&) {}
  [[nodiscard]] bool bonded() const override { return true; }
  [[nodiscard]] Vec3 momentum_change(const ContactInput& in) const override { return in.dp0; }
};

CAIRN_REGISTER_CONTACT_LAW(PerfectContact, "perfect",
                           "bonded interface: centre-of-mass velocity at every shared node, no detection");

}  // namespace
}  // namespace cairn
