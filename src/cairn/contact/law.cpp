#include "cairn/contact/law.hpp"

namespace cairn {

std::unique_ptr<ContactLaw> make_contact_law(const ContactLawConfig& config, const Constants& constants) {
  return ContactLawRegistry::instance().create("contact law", config.law, config, constants);
}

}  // namespace cairn
