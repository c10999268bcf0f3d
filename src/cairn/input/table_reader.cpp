// TableReader: one table against its declared keys (defaults, types, ranges, choices, array
// lengths, expressions).
#include "cairn/input/loader.hpp"

namespace cairn::input_detail {

// ---- TableReader ---------------------------------------------------------------------------

const KeyDecl& TableReader::decl(const std::string& name) const {
  for (const auto& d : decls_)
    if (d.name == name) return d;
  throw std::logic_error("input: key '" + display(path_of(name)) + "' read but not declared");
}

void TableReader::fail(const std::string& name, const toml::node* node, const std::string& expected,
                       const std::string& found) const {
  loader_.fail(path_of(name), node ? node : table_, expected, found);
}

void TableReader::reject_unknown_keys() const {
  if (!table_) return;
  for (const auto& [key, node] : entries_in_file_order(*table_))
    if (std::none_of(decls_.begin(), decls_.end(), [&key = key](const KeyDecl& d) { return d.name == key; }))
      loader_.fail(path_of(key), node, undeclared_key_expected(path_, key, decls_, what_), "an undeclared key");
}

TableReader::Value TableReader::value(const std::string& name) {
  Value v;
  v.decl = &decl(name);
  v.node = given(name);
  if (!v.node && !v.decl->default_value.empty()) {
    v.node = loader_.default_node(*v.decl);
    v.is_default = true;
  }
  return v;
}

TableReader::Value TableReader::required_value(const std::string& name) {
  Value v = value(name);
  if (!v.node) fail(name, nullptr, expected_value_text(*v.decl) + " (required key)", "nothing");
  return v;
}

double TableReader::number(const Value& v, const Path& path, const std::string& expected) {
  double x = 0.0;
  if (auto i = v.node->as_integer()) x = static_cast<double>(i->get());
  else if (auto f = v.node->as_floating_point()) x = f->get();
  else loader_.fail(path, v.node, expected, found(v, true));
  if (!std::isfinite(x)) loader_.fail(path, v.node, expected + " (finite)", found(v, false));
  if (!v.is_default && x != 0.0 && !(std::abs(x) <= max_magnitude && std::abs(x) >= 1.0 / max_magnitude))
    loader_.warn(path, v.node,
                 fmt::format("{} is beyond 1e{:.0f} in magnitude (or, nonzero, below 1e-{:.0f}), which no "
                             "unit system needs; energies and stresses may overflow",
                             node_text(*v.node), std::log10(max_magnitude), std::log10(max_magnitude)));
  return x;
}

void TableReader::check_range(const Value& v, double x, const Path& path, const std::string& expected) {
  if ((v.decl->min && x < *v.decl->min) || (v.decl->max && x > *v.decl->max))
    loader_.fail(path, v.node, expected, found(v, false));
}

double TableReader::real(const std::string& name) {
  Value v = required_value(name);
  const std::string expected = expected_value_text(*v.decl);
  const double x = number(v, path_of(name), expected);
  check_range(v, x, path_of(name), expected);
  return x;
}

long long TableReader::integer(const std::string& name) {
  Value v = required_value(name);
  const std::string expected = expected_value_text(*v.decl);
  auto i = v.node->as_integer();
  if (!i) fail(name, v.node, expected, found(v, true));
  check_range(v, static_cast<double>(i->get()), path_of(name), expected);
  return i->get();
}

int TableReader::small_integer(const std::string& name) {
  const long long x = integer(name);
  if (x > INT_MAX || x < INT_MIN)
    fail(name, given(name), expected_value_text(decl(name)) + fmt::format(" (at most {})", INT_MAX),
         fmt::format("{}", x));
  return static_cast<int>(x);
}

bool TableReader::boolean(const std::string& name) {
  Value v = required_value(name);
  auto b = v.node->as_boolean();
  if (!b) fail(name, v.node, expected_value_text(*v.decl), found(v, true));
  return b->get();
}

std::string TableReader::string(const std::string& name) {
  Value v = required_value(name);
  auto s = v.node->as_string();
  if (!s) {
    const std::string expected =
        v.decl->choices ? expected_value_text(*v.decl) + " (a string)" : "a string";
    fail(name, v.node, expected, found(v, true));
  }
  if (v.decl->choices) {
    const auto choices = v.decl->choices();
    if (std::find(choices.begin(), choices.end(), s->get()) == choices.end())
      fail(name, v.node, expected_value_text(*v.decl) + did_you_mean(s->get(), choices),
           found(v, false));
  }
  return s->get();
}

const toml::array& TableReader::array_of(const Value& v, const std::string& name, std::size_t n,
                                         const std::string& expected) {
  auto a = v.node->as_array();
  if (!a) fail(name, v.node, expected, found(v, true));
  if (n > 0 && a->size() != n)
    fail(name, v.node, expected,
         fmt::format("{} ({} {})", found(v, false), a->size(), a->size() == 1 ? "entry" : "entries"));
  return *a;
}

std::vector<double> TableReader::reals(const std::string& name, std::size_t n, bool allow_scalar) {
  Value v = value(name);
  const std::string range = range_phrase(*v.decl);
  const std::string each = range.empty() ? "" : ", each" + range;
  std::string expected = fmt::format("an array of {} numbers{}{}", n, each,
                                     per_axis(n, loader_.dimension()));
  if (allow_scalar) expected = fmt::format("a number{} or {}", range, expected);
  if (!v.node) fail(name, nullptr, expected + " (required key)", "nothing");
  if (allow_scalar && !v.node->is_array()) {
    const double x = number(v, path_of(name), expected);
    check_range(v, x, path_of(name), fmt::format("a number{}", range));
    return std::vector<double>(n, x);
  }
  const toml::array& a = array_of(v, name, n, expected);
  std::vector<double> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    Value e{a.get(i), v.is_default, v.decl};
    const Path p = child(path_of(name), i);
    const double x = number(e, p, "a number" + range);
    check_range(e, x, p, "a number" + range);
    out.push_back(x);
  }
  return out;
}

std::vector<int> TableReader::integers(const std::string& name, std::size_t n, bool allow_scalar) {
  Value v = value(name);
  const std::string range = range_phrase(*v.decl);
  const std::string each = range.empty() ? "" : ", each" + range;
  std::string expected = fmt::format("an array of {} integers{}{}", n, each,
                                     per_axis(n, loader_.dimension()));
  if (allow_scalar) expected = fmt::format("an integer{} or {}", range, expected);
  if (!v.node) fail(name, nullptr, expected + " (required key)", "nothing");
  auto one = [&](const Value& e, const Path& p, const std::string& what) {
    auto i = e.node->as_integer();
    if (!i) loader_.fail(p, e.node, what, found(e, true));
    check_range(e, static_cast<double>(i->get()), p, "an integer" + range);
    if (i->get() > INT_MAX || i->get() < INT_MIN) loader_.fail(p, e.node, "a 32-bit integer", found(e, false));
    return static_cast<int>(i->get());
  };
  if (allow_scalar && !v.node->is_array())
    return std::vector<int>(n, one(v, path_of(name), expected));
  const toml::array& a = array_of(v, name, n, expected);
  std::vector<int> out;
  for (std::size_t i = 0; i < a.size(); ++i)
    out.push_back(one(Value{a.get(i), v.is_default, v.decl}, child(path_of(name), i), "an integer" + range));
  return out;
}

std::vector<std::string> TableReader::expressions(const std::string& name, std::size_t n,
                                                  ExpressionVars vars) {
  Value v = value(name);
  if (!v.node) return {};
  const std::string entry = "a number or a non-empty expression string";
  const std::string expected = fmt::format(
      "an array of {} entries{}, each a number or an expression string", n,
      per_axis(n, loader_.dimension()));
  const toml::array& a = array_of(v, name, n, expected);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const toml::node* e = a.get(i);
    const Path p = child(path_of(name), i);
    if (auto s = e->as_string()) {
      if (trim(s->get()).empty()) loader_.fail(p, e, entry, "an empty string");
      loader_.check_expression(p, e, s->get(), vars);
      out.push_back(s->get());
    } else if (e->is_number()) {
      out.push_back(expression_number(number(Value{e, v.is_default, v.decl}, p, entry)));
    } else {
      loader_.fail(p, e, entry, typed_text(*e));
    }
  }
  return out;
}

std::string TableReader::expression(const std::string& name, ExpressionVars vars) {
  Value v = required_value(name);
  const std::string expected = expected_value_text(*v.decl);
  if (auto s = v.node->as_string()) {
    if (trim(s->get()).empty()) fail(name, v.node, expected, "an empty string");
    if (vars == ExpressionVars::declared)
      loader_.check_expression_in(path_of(name), v.node, s->get(), v.decl->variables);
    else
      loader_.check_expression(path_of(name), v.node, s->get(), vars);
    return s->get();
  }
  if (v.node->is_number()) return expression_number(number(v, path_of(name), expected));
  fail(name, v.node, expected, found(v, true));
}

std::vector<std::vector<double>> TableReader::points(const std::string& name, std::size_t n,
                                                     std::size_t min_count) {
  Value v = value(name);
  const std::string expected =
      fmt::format("an array of at least {} points, each an array of {} numbers", min_count, n);
  if (!v.node) fail(name, nullptr, expected + " (required key)", "nothing");
  const toml::array& a = array_of(v, name, 0, expected);
  if (a.size() < min_count)
    fail(name, v.node, expected, fmt::format("{} ({} points)", node_text(*v.node), a.size()));
  std::vector<std::vector<double>> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Path p = child(path_of(name), i);
    const toml::node* e = a.get(i);
    auto pa = e->as_array();
    const std::string point = fmt::format("an array of {} numbers", n);
    if (!pa) loader_.fail(p, e, point, typed_text(*e));
    if (pa->size() != n)
      loader_.fail(p, e, point, fmt::format("{} ({} entries)", node_text(*e), pa->size()));
    std::vector<double> xs;
    for (std::size_t j = 0; j < n; ++j)
      xs.push_back(number(Value{pa->get(j), v.is_default, v.decl}, child(p, j), "a number"));
    out.push_back(std::move(xs));
  }
  return out;
}

// ---- expressions ---------------------------------------------------------------------------

void Loader::check_expression_in(const Path& path, const toml::node* node, const std::string& text,
                                 const std::vector<std::string>& variables) const {
  try {
    Expression::check(text, variables, constants_);
  } catch (const std::invalid_argument& err) {
    fail(path, node, fmt::format("one expression in {} and [constants]", join(variables)), err.what());
  }
}

void Loader::read_plugin_keys(TableReader& r, const std::string& section, PluginValues& values, const Config& cfg) {
  for (const KeyDecl* k : section_keys(section)) {
    if (k->owner.empty()) continue;
    switch (k->type) {
      case KeyType::real: values.set(k->name, r.real(k->name)); break;
      case KeyType::integer: values.set(k->name, static_cast<double>(r.integer(k->name))); break;
      case KeyType::boolean: values.set(k->name, r.boolean(k->name) ? 1.0 : 0.0); break;
      case KeyType::string: values.set(k->name, r.string(k->name)); break;
      case KeyType::expression: values.set(k->name, r.expression(k->name, ExpressionVars::declared)); break;
      default: throw std::logic_error("plug-in key '" + k->name + "': a type plug-ins cannot declare");
    }
  }
  for (const auto& owner : key_owners())
    if (owner.check && std::find(owner.sections.begin(), owner.sections.end(), section) != owner.sections.end())
      if (const auto problem = owner.check(cfg)) r.fail(problem->key, r.given(problem->key), problem->expected, problem->found);
}

void Loader::check_expression(const Path& path, const toml::node* node, const std::string& text,
                              ExpressionVars vars) const {
  if (vars == ExpressionVars::unchecked) return;
  std::vector<std::string> allowed;
  if (vars != ExpressionVars::time) {
    for (int a = 0; a < dim_; ++a) allowed.emplace_back(1, "xyz"[a]);
    for (int a = 0; a < dim_; ++a) allowed.emplace_back(1, "XYZ"[a]);
  }
  if (vars != ExpressionVars::initial) allowed.emplace_back("t");
  std::string expected = fmt::format("one expression in {} and [constants]", join(allowed));
  if (vars == ExpressionVars::initial) expected += " (evaluated once, at t = 0)";
  std::unique_ptr<Expression> e;
  try {
    e = std::make_unique<Expression>(text, constants_);
  } catch (const std::invalid_argument& err) {
    fail(path, node, expected, err.what());
  }
  for (const auto& v : e->used_variables()) {
    if (std::find(allowed.begin(), allowed.end(), v) != allowed.end()) continue;
    std::string why;
    if (v == "t") why = "an initial value does not depend on time";
    else if (vars == ExpressionVars::time) why = "a function of time has no position";
    else why = fmt::format("a {}D input has no {} axis", dim_, v);
    fail(path, node, expected, fmt::format("{}, which uses {} ({})", toml_string(text), v, why));
  }
  if (e->is_constant()) {
    const double value = (*e)(Vec3::Zero(), Vec3::Zero(), 0.0);
    if (!std::isfinite(value))
      fail(path, node, expected + " with a finite value",
           fmt::format("{} = {}", toml_string(text), value));
  }
}


}  // namespace cairn::input_detail
