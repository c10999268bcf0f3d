// The pieces of the input schema that its files share (input/schema*.cpp): not for other folders.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cairn/input/schema.hpp"

namespace cairn::schema_detail {

inline std::vector<std::string> face_conditions() { return {"free", "fixed", "symmetry", "periodic"}; }
inline std::vector<std::string> boundary_acceleration_names() { return {"zero", "velocity_change"}; }
inline std::vector<std::string> face_names_list() { return {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"}; }
inline std::vector<std::string> axis_names() { return {"x", "y", "z"}; }
inline std::vector<std::string> mode_names() { return {"plane_strain", "plane_stress", "3d", "uniaxial"}; }

/// The keys of [simulation], [grid], [method], [[material]], [[body]] and the body shapes
/// (schema_model.cpp), and those of the loads, conditions, contact, [fem] and [output]
/// (schema_conditions.cpp), appended to `k` in documentation order.
void declare_model_keys(std::vector<KeyDecl>& k);
void declare_condition_keys(std::vector<KeyDecl>& k);

/// `cairn keys` and docs/input.md (schema_docs.cpp).
std::string markdown_text();
std::string plain_text();

std::string join(const std::vector<std::string>& items, const std::string& sep = ", ");
/// Copies of the declared keys of one section.
std::vector<KeyDecl> copy_section(std::string_view section);

}  // namespace cairn::schema_detail
