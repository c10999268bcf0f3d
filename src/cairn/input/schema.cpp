// The single list of input-key declarations, and the key reference generated from it
// (`cairn keys`, docs/input.md).
#include "cairn/input/schema.hpp"
#include "cairn/input/schema_detail.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "cairn/geometry/shape_keys.hpp"
#include "cairn/config/units.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/input/names.hpp"

namespace cairn {

namespace schema_detail {

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

}  // namespace schema_detail

using namespace schema_detail;

namespace {

std::vector<KeyDecl> make_declarations() {
  std::vector<KeyDecl> k;
  declare_model_keys(k);
  declare_condition_keys(k);
  // The plug-ins' own keys (config/plugin_keys.hpp): each owner's after its `after` key (an
  // owner whose anchor is another owner's key waits for it), else at its section's end; owners
  // by name, so that the order does not depend on the link.
  std::vector<const KeyOwner*> pending;
  for (const auto& owner : key_owners()) pending.push_back(&owner);
  std::sort(pending.begin(), pending.end(), [](const KeyOwner* a, const KeyOwner* b) { return a->name < b->name; });
  const auto anchor = [&](const std::string& section, const std::string& after) {
    return std::find_if(k.begin(), k.end(), [&](const KeyDecl& d) { return d.section == section && d.name == after; });
  };
  const auto place = [&](const KeyOwner& owner, bool at_end) {
    for (const auto& section : owner.sections)
      if (!at_end && anchor(section, owner.after) == k.end()) return false;
    for (const auto& section : owner.sections) {
      auto at = anchor(section, owner.after);
      if (at == k.end())
        at = std::find_if(k.rbegin(), k.rend(), [&](const KeyDecl& d) { return d.section == section; }).base();
      else
        ++at;
      for (KeyDecl decl : owner.keys) {
        decl.section = section;
        at = k.insert(at, std::move(decl)) + 1;
      }
    }
    return true;
  };
  for (bool progress = true; progress && !pending.empty();) {
    progress = false;
    for (auto it = pending.begin(); it != pending.end();)
      if (place(**it, (*it)->after.empty())) {
        it = pending.erase(it);
        progress = true;
      } else {
        ++it;
      }
  }
  for (const KeyOwner* owner : pending) place(*owner, true);
  return k;
}

/// Computed defaults, shown instead of the (empty) TOML default.
const std::map<std::string, std::string>& computed_defaults() {
  static const std::map<std::string, std::string> m{
      {"simulation.mode", "by dimension"},
      {"body.name", "body<N>"},
      {"body.velocity", "zeros"},
      {"traction.name", "traction<N>"},
      {"velocity.name", "velocity<N>"},
      {"wall.name", "wall<N>"},
  };
  return m;
}

/// Type names that "real[D]"-style generic text would get wrong.
const std::map<std::string, std::string>& type_overrides() {
  static const std::map<std::string, std::string> m{
      {"grid.cell_size", "real or real[D]"},
      {"body.particles_per_cell", "integer or integer[D]"},
      {"body.shape", "inline table"},
      {"body.shape.circle.center", "real[2]"},
      {"body.shape.annulus.center", "real[D]"},
      {"body.shape.sphere.center", "real[3]"},
      {"body.shape.cylinder.center", "real[3]"},
      {"body.shape.polygon.vertices", "real[2][n]"},
      {"body.shape.image.origin", "real[2]"},
      {"body.shape.image.levels", "integer[2]"},
      {"body.shape.image_stack.origin", "real[3]"},
      {"body.shape.image_stack.levels", "integer[2]"},
      {"body.shape.mesh.rotate", "real[3]"},
      {"body.shape.mesh.translate", "real[3]"},
      {"body.shape.outline.translate", "real[2]"},
      {"body.shape.volume_mesh.rotate", "real[3]"},
      {"body.shape.volume_mesh.translate", "real[3]"},
      {"traction.table", "real[2][n]"},
      {"velocity.table", "real[2][n]"},
      {"wall.table", "real[2][n]"},
  };
  return m;
}

std::string number_text(double v) { return v == above_zero ? "0" : fmt::format("{}", v); }

bool is_numeric(KeyType t) {
  return t == KeyType::integer || t == KeyType::real || t == KeyType::integer_array ||
         t == KeyType::real_array;
}
bool is_integer(KeyType t) { return t == KeyType::integer || t == KeyType::integer_array; }

}  // namespace

std::string range_phrase(const KeyDecl& d) {
  if (!is_numeric(d.type)) return "";
  const bool positive = d.min && *d.min == above_zero;
  if (d.min && d.max) {
    if (positive) return fmt::format(" in (0, {}]", number_text(*d.max));
    if (is_integer(d.type)) return fmt::format(" in {}..{}", number_text(*d.min), number_text(*d.max));
    return fmt::format(" in [{}, {}]", number_text(*d.min), number_text(*d.max));
  }
  if (d.min) return positive ? " > 0" : fmt::format(" >= {}", number_text(*d.min));
  if (d.max) return fmt::format(" <= {}", number_text(*d.max));
  return "";
}


const std::vector<KeyDecl>& declared_keys() {
  static const std::vector<KeyDecl> keys = make_declarations();
  return keys;
}

std::vector<const KeyDecl*> section_keys(std::string_view section) {
  std::vector<const KeyDecl*> out;
  for (const auto& d : declared_keys())
    if (d.section == section) out.push_back(&d);
  return out;
}

const std::vector<std::string>& section_names() {
  static const std::vector<std::string> names{"simulation", "parallel", "grid",     "method",
                                              "constants",  "material", "body",
                                              "boundary",   "thermal",    "body_force", "traction",
                                              "velocity",   "wall",       "contact",    "contact_pair",
                                              "fem",        "output"};
  return names;
}

const std::vector<BodyShapeKind>& body_shape_kinds() {
  static const std::vector<BodyShapeKind> kinds{
      {"box", {true, true, true}, "Axis-aligned box (a segment in 1D, a rectangle in 2D)."},
      {"circle", {false, true, false}, "Disc."},
      {"ellipse", {false, true, true}, "Axis-aligned ellipse (2D) or ellipsoid (3D)."},
      {"annulus", {false, true, true},
       "Ring between two concentric circles (2D); hollow ball between two concentric spheres (3D)."},
      {"polygon", {false, true, false}, "Simple polygon."},
      {"sphere", {false, false, true}, "Ball."},
      {"cylinder", {false, false, true}, "Circular cylinder along z (e.g. a Taylor bar)."},
      {"image", {false, true, false},
       "Pixels of a grey-level PNG picture whose level lies in a range (one body per "
       "material shade)."},
  };
  static const std::vector<BodyShapeKind> all = [] {
    std::vector<BodyShapeKind> out = kinds;
    for (const auto& g : geometry::shape_kinds())
      out.push_back({g.name, {g.valid_in[0], g.valid_in[1], g.valid_in[2]}, g.doc});
    return out;
  }();
  return all;
}

std::vector<KeyDecl> material_keys(const std::string& model) {
  std::vector<KeyDecl> out = copy_section("material");
  auto it = material_model_info().find(model);
  if (it != material_model_info().end())
    for (KeyDecl d : it->second.keys) {
      d.section = "material";
      out.push_back(std::move(d));
    }
  return out;
}

std::string expected_value_text(const KeyDecl& d) {
  const std::string range = range_phrase(d);
  switch (d.type) {
    case KeyType::boolean: return "true or false";
    case KeyType::integer: return "an integer" + range;
    case KeyType::real: return "a number" + range;
    case KeyType::string:
      if (d.choices) return "one of " + join(d.choices(), ", ");
      return "a string";
    case KeyType::integer_array: return "an array of integers" + (range.empty() ? "" : ", each" + range);
    case KeyType::real_array: return "an array of numbers" + (range.empty() ? "" : ", each" + range);
    case KeyType::expression_array: return "an array of numbers or expression strings";
    case KeyType::expression: return "a number or an expression string";
    case KeyType::string_array: return "an array of strings";
    case KeyType::table: return "a table";
  }
  return "a value";
}

std::string type_text(const KeyDecl& d) {
  auto it = type_overrides().find(d.section + "." + d.name);
  if (it != type_overrides().end()) return it->second;
  switch (d.type) {
    case KeyType::boolean: return "boolean";
    case KeyType::integer: return "integer";
    case KeyType::real: return "real";
    case KeyType::string: return "string";
    case KeyType::integer_array: return "integer[D]";
    case KeyType::real_array: return "real[D]";
    case KeyType::expression_array: return "expr[D]";
    case KeyType::expression: return "expr";
    case KeyType::string_array: return "string[]";
    case KeyType::table: return "table";
  }
  return "?";
}

std::string range_text(const KeyDecl& d) {
  if (d.type == KeyType::string && d.choices) return join(d.choices(), ", ");
  std::string r = range_phrase(d);
  if (r.rfind(" in ", 0) == 0) return r.substr(4);
  return r.empty() ? "" : r.substr(1);
}

std::string default_text(const KeyDecl& d) {
  if (d.required) return "required";
  auto it = computed_defaults().find(d.section + "." + d.name);
  if (it != computed_defaults().end()) return it->second;
  return d.default_value.empty() ? "none" : d.default_value;
}

std::string keys_text(bool markdown) { return markdown ? markdown_text() : plain_text(); }

}  // namespace cairn
