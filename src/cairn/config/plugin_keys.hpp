// Keys that plug-ins declare beside their code: a shape family, an update scheme, a contact law or
// the WLS method states its own input keys with one registration line, and reads their values
// from PluginValues; the validator, `cairn keys`, docs/input.md and the resolved input that
// outputs store pick them up from the registry, so adding such a key touches neither input/ nor
// the Config structs (docs/architecture.md, "How to add a key").
#pragma once

#include <fmt/format.h>

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cairn/config/keys.hpp"

namespace cairn {

struct Config;

/// Use as KeyDecl::min to say "strictly greater than zero": for doubles, x >= above_zero holds
/// exactly when x > 0. Shown as "> 0" in docs and error messages.
inline constexpr double above_zero = std::numeric_limits<double>::denorm_min();

/// A number as TOML text that reads back to the same double ("2.0", "0.1", "1e-05").
inline std::string real_text(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

/// Fluent construction of a KeyDecl (designated initializers that skip members warn under -Wextra).
class Key {
 public:
  Key(std::string section, std::string name, KeyType type, std::string doc) {
    decl_.section = std::move(section);
    decl_.name = std::move(name);
    decl_.type = type;
    decl_.doc = std::move(doc);
  }
  Key& by_default(std::string toml_text) {
    decl_.default_value = std::move(toml_text);
    return *this;
  }
  Key& required() {
    decl_.required = true;
    return *this;
  }
  Key& min(double v) {
    decl_.min = v;
    return *this;
  }
  Key& max(double v) {
    decl_.max = v;
    return *this;
  }
  Key& choices(std::function<std::vector<std::string>()> f) {
    decl_.choices = std::move(f);
    return *this;
  }
  /// An expression key (KeyType::expression) in these variables and [constants].
  Key& variables(std::vector<std::string> names) {
    decl_.variables = std::move(names);
    return *this;
  }
  operator KeyDecl() const { return decl_; }  // NOLINT(google-explicit-constructor)

 private:
  KeyDecl decl_;
};

/// The values one input table gives the plug-in keys of its section, by key name (the given value
/// or the default): numbers as doubles, booleans as 0 or 1, strings and expressions as text.
class PluginValues {
 public:
  /// The value read for `name`, or (a Config built in code) the key's declared default. Throws
  /// std::out_of_range for a key no plug-in declares. Read them when a plug-in is set up, not
  /// per particle.
  [[nodiscard]] double real(std::string_view name) const;
  [[nodiscard]] bool boolean(std::string_view name) const { return real(name) != 0.0; }
  [[nodiscard]] std::string text(std::string_view name) const;
  void set(const std::string& name, double value) { numbers_[name] = value; }
  void set(const std::string& name, std::string value) { texts_[name] = std::move(value); }
  bool operator==(const PluginValues&) const = default;

 private:
  std::map<std::string, double, std::less<>> numbers_;
  std::map<std::string, std::string, std::less<>> texts_;
};

/// A problem a plug-in finds in the input (KeyOwner::check): the key of its section, what was
/// expected and what was found.
struct KeyProblem {
  std::string key, expected, found;
};

/// The keys of one plug-in: declared for each of `sections` (e.g. a contact law's keys hold for
/// [contact] and [[contact_pair]]). `check`, when set, runs when its section has been read (the
/// sections before it too: [simulation], [grid], [method], ... in input order of docs/input.md),
/// for the conditions that involve other keys (a length against the cell size, say).
struct KeyOwner {
  std::string name;  ///< the plug-in: "ugimp", "coulomb", "wls", ...
  std::vector<std::string> sections;
  std::vector<KeyDecl> keys;
  std::function<std::optional<KeyProblem>(const Config&)> check;
  /// Where the keys stand in their section (docs, messages, the resolved input): after this
  /// key; empty or not declared = at the section's end.
  std::string after;
};

/// Every registered plug-in's keys, in registration order (which the link decides: the schema
/// orders them by `after` and name).
std::vector<KeyOwner>& key_owners();

inline bool declare_keys(KeyOwner owner) {
  for (auto& k : owner.keys) k.owner = owner.name;
  key_owners().push_back(std::move(owner));
  return true;
}

/// `CAIRN_DECLARE_KEYS(ugimp, {"ugimp", {"method"}, {Key(...), ...}, check})` beside the plug-in.
#define CAIRN_DECLARE_KEYS(id, ...) static const bool cairn_keys_##id = ::cairn::declare_keys(::cairn::KeyOwner __VA_ARGS__)

}  // namespace cairn
