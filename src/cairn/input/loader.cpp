// Loader: `--set` overrides, the top-level checks, and the reading of the whole input with every
// independent error collected (remove_undeclared, removable_key).
#include "cairn/input/loader.hpp"

namespace cairn::input_detail {

// ---- overrides -----------------------------------------------------------------------------

/// "material[0].density" or "material.0.density" -> {"material", "0", "density"}; nullopt when
/// malformed (empty parts, unbalanced brackets, a non-index in brackets).
std::optional<Path> split_key(const std::string& text) {
  Path out;
  std::string part;
  bool after_bracket = false;  // just closed "[n]": only '.', '[' or the end may follow
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '.') {
      if (part.empty() && !after_bracket) return std::nullopt;
      if (!part.empty()) out.push_back(part);
      part.clear();
      after_bracket = false;
      if (i + 1 == text.size()) return std::nullopt;
    } else if (c == '[') {
      if (part.empty() && !after_bracket) return std::nullopt;
      if (!part.empty()) out.push_back(part);
      part.clear();
      const auto close = text.find(']', i);
      if (close == std::string::npos) return std::nullopt;
      const std::string index = trim(text.substr(i + 1, close - i - 1));
      if (!is_index(index)) return std::nullopt;
      out.push_back(index);
      i = close;
      after_bracket = true;
    } else if (c == ']' || c == ' ' || c == '\t' || c == '"' || c == '\'') {
      return std::nullopt;
    } else {
      if (after_bracket) return std::nullopt;
      part += c;
    }
  }
  if (!part.empty()) out.push_back(part);
  else if (!after_bracket) return std::nullopt;
  return out;
}

/// The override value: a TOML value if the text is one, else the text as a plain string.
toml::table parse_override_value(const std::string& text) {
  try {
    toml::table t = toml::parse("v = " + text);
    if (t.size() == 1 && t.contains("v")) return t;
  } catch (const toml::parse_error&) {
  }
  toml::table t;
  t.insert("v", text);
  return t;
}

void Loader::apply_override(toml::table& root, const std::string& text) {
  const std::string origin = "--set " + text;
  const std::string syntax =
      "section.key=value, e.g. method.order=4 or material[0].density=1100";
  const auto eq = text.find('=');
  if (eq == std::string::npos) throw InputError(origin, 0, "", syntax, toml_string(text) + " (no '=')");
  const std::string lhs = trim(text.substr(0, eq));
  const std::string rhs = trim(text.substr(eq + 1));
  auto parts = split_key(lhs);
  if (!parts || parts->size() < 2)
    throw InputError(origin, 0, "", syntax, fmt::format("key {}", toml_string(lhs)));
  const Path& p = *parts;
  auto unknown = [&](std::size_t n_shown, const std::string& expected) {
    throw InputError(origin, 0, display(Path(p.begin(), p.begin() + n_shown)), expected,
                     "an undeclared key");
  };

  const std::string& name = p[0];
  const auto& sections = section_names();
  if (std::find(sections.begin(), sections.end(), name) == sections.end())
    unknown(1, "a section, one of " + join(sections) + did_you_mean(name, sections));

  toml::table* target = nullptr;
  std::size_t first = 1;  // index in p of the first key inside `target`
  if (is_table_array(name)) {
    const std::string example = fmt::format("an entry index, as in {0}.0.name or {0}[0].name", name);
    if (!is_index(p[1])) throw InputError(origin, 0, display(p), example, toml_string(p[1]));
    if (p.size() < 3) throw InputError(origin, 0, "", syntax, fmt::format("key {}", toml_string(lhs)));
    toml::array* entries = root.get_as<toml::array>(name);
    const std::size_t count = entries ? entries->size() : 0;
    const std::size_t index = p[1].size() > 9 ? SIZE_MAX : std::stoul(p[1]);
    if (index >= count)
      throw InputError(origin, 0, display(Path(p.begin(), p.begin() + 2)),
                       count ? fmt::format("the index of an existing [[{}]] (0..{})", name, count - 1)
                             : fmt::format("the index of an existing [[{}]] (the input has none)", name),
                       p[1]);
    target = entries->get(index)->as_table();
    if (!target)
      throw InputError(origin, 0, display(Path(p.begin(), p.begin() + 2)), "a table",
                       typed_text(*entries->get(index)));
    first = 2;
  } else {
    if (!root.contains(name)) root.insert(name, toml::table{});
    target = root.get_as<toml::table>(name);
    if (!target)
      throw InputError(origin, 0, name, fmt::format("a table [{}] to set a key in", name),
                       typed_text(*root.get(name)));
  }

  const Path keys(p.begin() + static_cast<std::ptrdiff_t>(first), p.end());
  if (name == "constants") {
    if (keys.size() != 1) unknown(p.size(), "constants.NAME=number");
  } else {
    std::vector<KeyDecl> decls = name == "material"
                                     ? material_keys(target->get_as<std::string>("model")
                                                         ? target->get_as<std::string>("model")->get()
                                                         : "")
                                     : copy_section(name);
    std::vector<std::string> names;
    for (const auto& d : decls) names.push_back(d.name);
    const std::string where = first == 2 ? fmt::format("[[{}]]", name) : fmt::format("[{}]", name);
    auto d = std::find_if(decls.begin(), decls.end(), [&](const KeyDecl& k) { return k.name == keys[0]; });
    if (d == decls.end())
      unknown(first + 1, fmt::format("a key declared for {}{}", where, did_you_mean(keys[0], names)));
    if (keys.size() > 1) {
      if (!(name == "body" && keys[0] == "shape") || keys.size() > 3)
        unknown(p.size(), fmt::format("a key declared for {}", where));
      std::vector<std::string> kinds;
      for (const auto& k : body_shape_kinds()) kinds.push_back(k.name);
      if (std::find(kinds.begin(), kinds.end(), keys[1]) == kinds.end())
        unknown(first + 2, "a shape kind, one of " + join(kinds) + did_you_mean(keys[1], kinds));
      if (keys.size() == 3) {
        std::vector<std::string> params;
        for (const auto* k : section_keys("body.shape." + keys[1])) params.push_back(k->name);
        if (std::find(params.begin(), params.end(), keys[2]) == params.end())
          unknown(p.size(), fmt::format("a parameter of the {} shape, one of {}{}", keys[1],
                                        join(params), did_you_mean(keys[2], params)));
      }
    }
  }

  toml::table* table = target;
  for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
    if (!table->contains(keys[i])) table->insert(keys[i], toml::table{});
    toml::table* next = table->get_as<toml::table>(keys[i]);
    if (!next)
      throw InputError(origin, 0, display(Path(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(first + i + 1))),
                       "a table to set a key in", typed_text(*table->get(keys[i])));
    table = next;
  }
  toml::table value = parse_override_value(rhs);
  table->insert_or_assign(keys.back(), std::move(*value.get("v")));
  overrides_.emplace_back(p, origin);
}

Config Loader::load(toml::table& root, const std::vector<std::string>& overrides) {
  // Every independent error in one reading: a bad --set is skipped, an undeclared key taken out,
  // a bad value of a key with a default replaced by the default, until an error that leaves the
  // rest unreadable or max_reported errors.
  std::vector<InputError> errors;
  for (const auto& o : overrides) {
    try {
      apply_override(root, o);
    } catch (const InputError& e) {
      errors.push_back(e);
    }
  }
  if (remove_undeclared(root, errors)) {
    while (errors.size() < InputErrors::max_reported) {
      failed_path_.reset();
      try {
        Config cfg = read_all(root);
        if (errors.empty()) return cfg;
        break;
      } catch (const InputError& e) {
        errors.push_back(e);
        const auto key = removable_key(root);
        if (!key) break;
        toml::node* holder = root.get((*key)[0]);
        if (key->size() == 3) holder = holder->as_array()->get(std::stoul((*key)[1]));
        holder->as_table()->erase(key->back());
      }
    }
  }
  if (errors.size() == 1) throw errors.front();
  // In file order: the --set errors first, those without a line (a missing section) last.
  const auto order = [](const InputError& e) {
    return e.file().rfind("--set ", 0) == 0 ? -1 : e.line() > 0 ? e.line() : INT_MAX;
  };
  std::stable_sort(errors.begin(), errors.end(),
                   [&](const InputError& a, const InputError& b) { return order(a) < order(b); });
  const bool truncated = errors.size() >= InputErrors::max_reported;
  if (truncated) errors.erase(errors.begin() + static_cast<std::ptrdiff_t>(InputErrors::max_reported), errors.end());
  throw InputErrors(std::move(errors), truncated);
}

bool Loader::remove_undeclared(toml::table& root, std::vector<InputError>& errors) const {
  bool readable = true;
  // Takes every key that `decls` do not declare out of `table` (at `path`, named `what`).
  auto scan = [&](toml::table& table, const Path& path, const std::vector<KeyDecl>& decls, const std::string& what) {
    for (const auto& [key, node] : entries_in_file_order(table))
      if (std::none_of(decls.begin(), decls.end(), [&key = key](const KeyDecl& d) { return d.name == key; })) {
        errors.push_back(error(child(path, key), node, undeclared_key_expected(path, key, decls, what),
                               "an undeclared key"));
        table.erase(key);
      }
  };
  for (const auto& [key, node] : entries_in_file_order(root)) {
    try {
      check_top_level_entry(key, *node);
    } catch (const InputError& e) {
      // A misspelt section or a key above its section's header: the keys it holds are missing
      // from where they belong, and reading on would only report that again.
      errors.push_back(e);
      readable = false;
      continue;
    }
    if (key == "constants") continue;  // a free table
    if (!is_table_array(key)) {
      scan(*root.get_as<toml::table>(key), {key}, copy_section(key), "[" + key + "]");
      continue;
    }
    auto& entries = *root.get_as<toml::array>(key);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      auto& entry = *entries.get(i)->as_table();
      if (key != "material") {
        scan(entry, child(Path{key}, i), copy_section(key), "[[" + key + "]]");
        continue;
      }
      // A material's keys are those of its model; with no valid model the reading says so.
      const auto* model = entry.get_as<std::string>("model");
      if (!model || material_model_info().count(model->get()) == 0) continue;
      scan(entry, child(Path{key}, i), material_keys(model->get()),
           fmt::format("[[material]] with model '{}'", model->get()));
    }
  }
  return readable;
}

std::optional<Path> Loader::removable_key(const toml::table& root) const {
  if (!failed_path_ || failed_path_->empty() || (*failed_path_)[0] == "constants") return std::nullopt;
  const Path& p = *failed_path_;
  const std::size_t depth = is_table_array(p[0]) ? 3 : 2;
  if (p.size() < depth) return std::nullopt;
  const toml::node* holder = root.get(p[0]);
  if (holder && depth == 3)
    holder = holder->is_array() ? holder->as_array()->get(std::stoul(p[1])) : nullptr;
  const toml::table* table = holder ? holder->as_table() : nullptr;
  const std::string& name = p[depth - 1];
  if (!table || !table->contains(name)) return std::nullopt;
  const auto* model = table->get_as<std::string>("model");
  const std::vector<KeyDecl> decls =
      p[0] == "material" ? material_keys(model ? model->get() : "") : copy_section(p[0]);
  const auto d = std::find_if(decls.begin(), decls.end(), [&](const KeyDecl& k) { return k.name == name; });
  // Undeclared keys go; so does a declared key whose default stands in for it. Without a default
  // (a required key, a material constant) the error would only come back as another.
  if (d != decls.end() && (d->required || d->default_value.empty())) return std::nullopt;
  return Path(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(depth));
}

Config Loader::read_all(const toml::table& root) {
  warnings_.clear();
  condition_names_.clear();
  constants_ = {};
  dim_ = 0;
  check_top_level(root);
  Config cfg;
  cfg.source_file = file_;
  read_simulation(root, cfg);
  const bool fem = root.contains("fem");
  if (!fem) read_grid(root, cfg);
  read_method(root, cfg);
  read_constants(root, cfg);
  read_materials(root, cfg);
  if (!fem) read_bodies(root, cfg);
  read_boundary(root, cfg);
  if (fem) read_fem(root, cfg);
  read_body_force(root, cfg);
  read_thermal(root, cfg);
  read_tractions(root, cfg);
  read_velocity_conditions(root, cfg);
  read_walls(root, cfg);
  read_contact(root, cfg);
  read_parallel(root, cfg);
  read_output(root, cfg);
  cfg.resolved_toml = config_to_toml(cfg);
  cfg.warnings = std::move(warnings_);
  return cfg;
}


}  // namespace cairn::input_detail
