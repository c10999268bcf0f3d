// Names the input validator accepts for the method choices, read from the registries so that a
// new shape family or scheme is accepted as soon as its registration line is compiled in.
#pragma once

#include <string>
#include <vector>

namespace cairn {

std::vector<std::string> shape_family_names();
std::vector<std::string> update_scheme_names();
std::vector<std::string> stress_update_names();
std::vector<std::string> contact_law_names();

}  // namespace cairn
