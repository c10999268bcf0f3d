#include "cairn/input/names.hpp"

#include "cairn/contact/law.hpp"
#include "cairn/schemes/scheme.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/sim/stress_timing.hpp"

namespace cairn {

std::vector<std::string> shape_family_names() { return ShapeRegistry<2>::instance().names(); }
std::vector<std::string> update_scheme_names() { return SchemeRegistry<2>::instance().names(); }
std::vector<std::string> stress_update_names() {
  std::vector<std::string> names;
  for (const auto& [name, timing] : stress_timings()) names.push_back(name);
  return names;
}

std::vector<std::string> contact_law_names() { return ContactLawRegistry::instance().names(); }

}  // namespace cairn
