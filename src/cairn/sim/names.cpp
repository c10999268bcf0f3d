#include "cairn/sim/names.hpp"

#include "cairn/contact/law.hpp"
#include "cairn/schemes/scheme.hpp"
#include "cairn/shapes/shape_family.hpp"

namespace cairn {

std::vector<std::string> shape_family_names() { return ShapeRegistry<2>::instance().names(); }
std::vector<std::string> update_scheme_names() { return SchemeRegistry<2>::instance().names(); }
std::vector<std::string> stress_update_names() { return {"usl", "usf", "usavg", "usl+", "usavg+"}; }

std::vector<std::string> contact_law_names() { return ContactLawRegistry::instance().names(); }

}  // namespace cairn
