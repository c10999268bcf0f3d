// The input schema: every key of a Cairn input file, declared once (input/schema.cpp, and the
// plug-ins' own keys beside their code: config/plugin_keys.hpp).
//
// The validator (input/), `cairn keys`, `cairn check` and docs/input.md all read these
// declarations. A [[material]] table has, besides the keys declared here, the keys its model
// declares in material_model_info() (materials/material.hpp).
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "cairn/config/plugin_keys.hpp"

namespace cairn {


/// A kind of [[body]] shape (`shape = { box = { ... } }`) and the dimensions it is valid in.
/// Its parameters are the keys of section "body.shape.<name>".
struct BodyShapeKind {
  std::string name;
  bool valid_in[3];  ///< valid_in[D - 1]
  std::string doc;
};

/// Every declared key of every section, in documentation order. Sections are "simulation",
/// "grid", "method", "material", "body", "body.shape.<kind>", "boundary", "body_force",
/// "output" ([constants] is a free table with no declared keys). The per-model keys of
/// [[material]] are not in this list: see material_model_info().
const std::vector<KeyDecl>& declared_keys();

/// The declared keys of one section (e.g. "method", "body.shape.circle"), in declaration order.
std::vector<const KeyDecl*> section_keys(std::string_view section);

/// The top-level tables an input file may have, in documentation order:
/// simulation, grid, method, constants, material, body, boundary, body_force, output.
const std::vector<std::string>& section_names();

/// The [[body]] shape kinds: box, circle, ellipse, annulus, polygon, sphere.
const std::vector<BodyShapeKind>& body_shape_kinds();

/// The declared keys of a [[material]] table whose model is `model`: name, model, density, then
/// the model's own keys. Unknown models give just the three common keys.
std::vector<KeyDecl> material_keys(const std::string& model);

/// What a valid value of `decl` looks like, for error messages and docs, e.g.
/// "a number in (0, 2]", "an integer in 1..3", "one of usl, usf", "true or false".
std::string expected_value_text(const KeyDecl& decl);

/// The range of a numeric key as a phrase to append to "a number": " > 0", " >= 0",
/// " in 1..3", " in (0, 2]", " in [-1, 0.5]"; "" when unbounded or not numeric.
std::string range_phrase(const KeyDecl& decl);

/// Short type name for tables: "real", "integer", "string", "real[D]", ...
std::string type_text(const KeyDecl& decl);

/// Allowed range or choices, e.g. "(0, 2]", "1..64", "linear, ugimp"; "" when unrestricted.
std::string range_text(const KeyDecl& decl);

/// Default as shown to users: the TOML default text, "required", or a description of a computed
/// default ("by dimension", "out/<input stem>", ...); "none" when the key is optional.
std::string default_text(const KeyDecl& decl);

/// Every key with type, default, range and doc. markdown = true gives the full docs/input.md
/// (intro, one section per input table with a key table and a TOML example, a sub-table per
/// material model); false gives aligned plain text for the terminal (`cairn keys`).
std::string keys_text(bool markdown);

}  // namespace cairn
