// Declarations of input keys: every key of the input file is declared exactly once, with its
// type, default, allowed range or choices and a one-line doc. The validator, `cairn keys`,
// `cairn check` and docs/input.md are all generated from these declarations.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cairn {

enum class KeyType {
  boolean,
  integer,
  real,
  string,
  integer_array,   ///< array of integers (e.g. particles_per_cell)
  real_array,      ///< array of numbers (e.g. origin)
  expression_array,///< array whose entries are numbers or expression strings in x,y,z,X,Y,Z,t
  expression,      ///< one number or expression string (e.g. a time function in t)
  string_array,
  table,           ///< an inline table (e.g. a body's shape)
};

struct KeyDecl {
  std::string section;        ///< "simulation", "grid", "material", "body", ...
  std::string name;           ///< key within the section
  KeyType type = KeyType::real;
  std::string default_value;  ///< as TOML text; empty = required (if `required`) or unset
  bool required = false;
  std::optional<double> min;  ///< inclusive lower bound for numbers
  std::optional<double> max;  ///< inclusive upper bound for numbers
  /// Allowed values for strings, computed on demand (registries fill up at static-init time).
  std::function<std::vector<std::string>()> choices;
  std::string doc;
  /// An expression key's variables (besides [constants]); empty: those its reader states.
  std::vector<std::string> variables;
  /// The plug-in that declared the key beside its code (config/plugin_keys.hpp); empty for the
  /// keys of input/schema.cpp.
  std::string owner;
};

}  // namespace cairn
