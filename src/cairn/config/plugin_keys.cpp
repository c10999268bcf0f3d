#include "cairn/config/plugin_keys.hpp"

#include <toml++/toml.h>

#include <stdexcept>

namespace cairn {

std::vector<KeyOwner>& key_owners() {
  static std::vector<KeyOwner> owners;
  return owners;
}

namespace {

/// The declaration of plug-in key `name` (the first section that declares it), or null.
const KeyDecl* declared(std::string_view name) {
  for (const auto& owner : key_owners())
    for (const auto& k : owner.keys)
      if (k.name == name) return &k;
  return nullptr;
}

/// The default of plug-in key `name` as a TOML value (a Config built in code, not read from a
/// file, holds no values: its plug-ins see the declared defaults).
toml::table default_of(std::string_view name) {
  const KeyDecl* d = declared(name);
  if (!d || d->default_value.empty())
    throw std::out_of_range("no plug-in key '" + std::string(name) + "' with a default is declared");
  return toml::parse("v = " + d->default_value);
}

}  // namespace

double PluginValues::real(std::string_view name) const {
  if (const auto it = numbers_.find(name); it != numbers_.end()) return it->second;
  const toml::table t = default_of(name);
  if (const auto b = t["v"].value<bool>()) return *b ? 1.0 : 0.0;
  if (const auto v = t["v"].value<double>()) return *v;
  throw std::out_of_range("plug-in key '" + std::string(name) + "' is not a number");
}

std::string PluginValues::text(std::string_view name) const {
  if (const auto it = texts_.find(name); it != texts_.end()) return it->second;
  const toml::table t = default_of(name);
  if (const auto v = t["v"].value<std::string>()) return *v;
  throw std::out_of_range("plug-in key '" + std::string(name) + "' is not a string");
}

}  // namespace cairn
