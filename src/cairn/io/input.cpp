// The input validator: TOML (toml++) + `--set` overrides -> Config, checking every key against its
// declaration in io/schema.cpp. Errors name file:line (toml++ source positions) or the `--set`
// text, the key, what was expected and what was found.
#include "cairn/io/input.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "cairn/bc/expression.hpp"
#include "cairn/geometry/outline.hpp"
#include "cairn/geometry/point_set.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/geometry/volume_mesh.hpp"
#include "cairn/io/image.hpp"
#include "cairn/io/schema.hpp"
#include "cairn/io/units.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/wls/arrangement.hpp"

namespace cairn {

namespace {

/// A key's position in the input tree: {"material", "0", "density"}.
using Path = std::vector<std::string>;

/// extent / cell_size must be this close (relative) to a whole number; quoted in the message.
constexpr double ratio_tolerance = 1e-9;

/// Input numbers beyond this magnitude (or nonzero below its inverse) get a warning.
constexpr double max_magnitude = 1e30;

/// Most cells along one grid axis (see Grid::max_cell_units: indices stay far from int overflow).
constexpr long long max_cells_per_axis = 1000000000;

/// The variables an expression key may use (checked when the input is read).
enum class ExpressionVars {
  initial,   ///< x, y, z, X, Y, Z up to the dimension: evaluated once, at t = 0 (body velocity)
  field,     ///< positions and t (body force)
  time,      ///< t only (time functions of loads, velocity conditions and walls)
  slide,     ///< Nc, vslip, t: the general contact law's slide expression
  unchecked, ///< read as text: the caller checks it (a wall gradient may be a word)
};

Path child(Path p, std::string part) {
  p.push_back(std::move(part));
  return p;
}
Path child(Path p, std::size_t index) { return child(std::move(p), std::to_string(index)); }

bool is_index(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

/// Dotted key as users see it: {"material", "0", "density"} -> "material[0].density".
std::string display(const Path& p) {
  std::string out;
  for (const auto& part : p) {
    if (is_index(part) && !out.empty()) out += "[" + part + "]";
    else out += (out.empty() ? "" : ".") + part;
  }
  return out;
}

std::string join(const std::vector<std::string>& items, const std::string& sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// The candidate closest to `name` when it is plausibly a misspelling of it.
std::optional<std::string> closest(const std::string& name, const std::vector<std::string>& candidates) {
  std::optional<std::string> best;
  std::size_t best_distance = std::max<std::size_t>(2, name.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance && d < std::max(name.size(), c.size())) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates) {
  auto c = closest(name, candidates);
  return c ? fmt::format(" (did you mean '{}'?)", *c) : "";
}

// ---- TOML text ---------------------------------------------------------------------------

std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      default:
        if (c < 0x20 || c == 0x7f) out += fmt::format("\\u{:04X}", static_cast<unsigned>(c));
        else out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string toml_key(const std::string& k) {
  const bool bare = !k.empty() && std::all_of(k.begin(), k.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
  return bare ? k : toml_string(k);
}

/// Shortest text that reads back as the same double, always with a '.' or exponent so that
/// TOML reads it as a real.
std::string real_text(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

/// Full-precision text of a number stored in an expression (Config keeps expressions as text).
std::string expression_number(double v) { return fmt::format("{:.17g}", v); }

std::string node_text(const toml::node& node) {
  std::string out;
  if (auto s = node.as_string()) out = toml_string(s->get());
  else if (auto i = node.as_integer()) out = fmt::format("{}", i->get());
  else if (auto f = node.as_floating_point()) out = real_text(f->get());
  else if (auto b = node.as_boolean()) out = b->get() ? "true" : "false";
  else if (auto a = node.as_array()) {
    out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) out += (i ? ", " : "") + node_text(*a->get(i));
    out += "]";
  } else if (auto t = node.as_table()) {
    out = "{";
    bool first = true;
    for (auto&& [k, v] : *t) {
      out += fmt::format("{} {} = {}", first ? "" : ",", toml_key(std::string(k.str())), node_text(v));
      first = false;
    }
    out += first ? "}" : " }";
  } else {
    std::ostringstream os;
    node.visit([&](auto&& v) { os << v; });
    out = os.str();
  }
  if (out.size() > 120) out = out.substr(0, 117) + "...";
  return out;
}

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a real";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

/// "value (its type)", for type errors.
std::string typed_text(const toml::node& node) {
  return fmt::format("{} ({})", node_text(node), type_name(node));
}

int line_of(const toml::node* node) {
  return node ? static_cast<int>(node->source().begin.line) : 0;
}

/// Entries of a table sorted by their position in the file (toml++ keeps them sorted by key).
std::vector<std::pair<std::string, const toml::node*>> entries_in_file_order(const toml::table& t) {
  std::vector<std::pair<std::string, const toml::node*>> out;
  for (auto&& [k, v] : t) out.emplace_back(std::string(k.str()), &v);
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    const auto& sa = a.second->source().begin;
    const auto& sb = b.second->source().begin;
    return sa.line != sb.line ? sa.line < sb.line : sa.column < sb.column;
  });
  return out;
}

std::string mode_name(Mode m) {
  switch (m) {
    case Mode::uniaxial_strain_1d: return "uniaxial";
    case Mode::plane_strain: return "plane_strain";
    case Mode::plane_stress: return "plane_stress";
    case Mode::three_d: return "3d";
  }
  return "?";
}

const char* const face_names[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};

/// The sections written as arrays of tables ([[material]], ...), addressed by index in --set.
bool is_table_array(const std::string& section) {
  return section == "material" || section == "body" || section == "traction" ||
         section == "velocity" || section == "wall" || section == "contact_pair";
}
const char* const face_condition_names[4] = {"free", "fixed", "symmetry", "periodic"};

/// " (one per axis, dimension 2)" when n is the dimension.
std::string per_axis(std::size_t n, int dim) {
  return n == static_cast<std::size_t>(dim) ? fmt::format(" (one per axis, dimension {})", dim) : "";
}

std::vector<KeyDecl> copy_section(std::string_view section) {
  std::vector<KeyDecl> out;
  for (const auto* d : section_keys(section)) out.push_back(*d);
  return out;
}

/// Where else a key named `key` is declared, as a hint for one found in the table at `path`:
/// " ('cfl' is a key of [simulation]: did you mean simulation.cfl?)", or "" when nowhere else.
std::string declared_elsewhere(const Path& path, const std::string& key) {
  std::vector<std::string> places;
  for (const auto& d : declared_keys())
    if (d.name == key && d.section != path[0] && d.section.find('.') == std::string::npos &&
        std::find(places.begin(), places.end(), d.section) == places.end())
      places.push_back(d.section);
  std::vector<std::string> models;  // a material model's own key
  for (const auto& [model, info] : material_model_info())
    for (const auto& d : info.keys)
      if (d.name == key && std::find(models.begin(), models.end(), model) == models.end()) models.push_back(model);
  if (!models.empty() && path[0] != "material") places.push_back("material");
  if (places.empty()) return "";
  std::vector<std::string> shown;
  for (const auto& section : places)
    shown.push_back(is_table_array(section) ? "[[" + section + "]]" : "[" + section + "]");
  std::string text = fmt::format(" ('{}' is a key of {}", key, join(shown, " and "));
  if (!models.empty() && path[0] != "material") text += fmt::format(" (model {})", join(models, ", "));
  if (places.size() == 1 && !is_table_array(places[0])) text += fmt::format(": did you mean {}.{}?", places[0], key);
  return text + ")";
}

/// The `expected` text for a key `key` that `decls` (the keys of the table at `path`, named
/// `what` in messages) do not declare: where it belongs if another section declares it, else the
/// closest declared name, else the list of keys.
std::string undeclared_key_expected(const Path& path, const std::string& key, const std::vector<KeyDecl>& decls,
                                    const std::string& what) {
  std::vector<std::string> names;
  for (const auto& d : decls) names.push_back(d.name);
  if (const std::string elsewhere = declared_elsewhere(path, key); !elsewhere.empty())
    return fmt::format("a key declared for {}{}", what, elsewhere);
  const auto suggestion = closest(key, names);
  return suggestion ? fmt::format("a key declared for {} (did you mean '{}'?)", what, *suggestion)
                    : fmt::format("one of the keys of {}: {}", what, join(names));
}

// ---- the validator -----------------------------------------------------------------------

class Loader;

/// Reads one table against its declared keys: defaults, types, ranges, choices, array lengths.
class TableReader {
 public:
  /// `table` may be null (section absent: every key takes its default). `what` names the table
  /// in messages about unknown keys, e.g. "[simulation]".
  TableReader(Loader& loader, const toml::table* table, Path path, std::vector<KeyDecl> decls,
              std::string what)
      : loader_(loader), table_(table), path_(std::move(path)), decls_(std::move(decls)),
        what_(std::move(what)) {}

  void reject_unknown_keys() const;

  /// The node given in the input for `name`, or null.
  [[nodiscard]] const toml::node* given(const std::string& name) const {
    return table_ ? table_->get(name) : nullptr;
  }
  [[nodiscard]] bool present(const std::string& name) const { return given(name) != nullptr; }
  [[nodiscard]] Path path_of(const std::string& name) const { return child(path_, name); }

  [[nodiscard]] double real(const std::string& name);
  [[nodiscard]] long long integer(const std::string& name);
  [[nodiscard]] int small_integer(const std::string& name);
  [[nodiscard]] bool boolean(const std::string& name);
  [[nodiscard]] std::string string(const std::string& name);
  /// n numbers; with allow_scalar one number stands for all n.
  [[nodiscard]] std::vector<double> reals(const std::string& name, std::size_t n, bool allow_scalar);
  [[nodiscard]] std::vector<int> integers(const std::string& name, std::size_t n, bool allow_scalar);
  /// n entries, numbers or non-empty strings, as expression text; empty when absent. Each is
  /// compiled and may use only the variables `vars` allows.
  [[nodiscard]] std::vector<std::string> expressions(const std::string& name, std::size_t n,
                                                     ExpressionVars vars);
  /// One number or non-empty expression string, as expression text (checked as above).
  [[nodiscard]] std::string expression(const std::string& name, ExpressionVars vars);
  /// At least min_count points of n coordinates each ([[x, y], ...]).
  [[nodiscard]] std::vector<std::vector<double>> points(const std::string& name, std::size_t n,
                                                        std::size_t min_count);

  [[noreturn]] void fail(const std::string& name, const toml::node* node, const std::string& expected,
                         const std::string& found) const;

 private:
  struct Value {
    const toml::node* node = nullptr;
    bool is_default = false;
    const KeyDecl* decl = nullptr;
  };
  [[nodiscard]] const KeyDecl& decl(const std::string& name) const;
  /// The given value or the default; node is null for an optional key without default.
  Value value(const std::string& name);
  Value required_value(const std::string& name);
  /// Found text for a value; defaults are marked, since the user did not write them.
  static std::string found(const Value& v, bool typed) {
    std::string s = typed ? typed_text(*v.node) : node_text(*v.node);
    return v.is_default ? s + " (the default)" : s;
  }
  double number(const Value& v, const Path& path, const std::string& expected);
  void check_range(const Value& v, double x, const Path& path, const std::string& expected);
  const toml::array& array_of(const Value& v, const std::string& name, std::size_t n,
                              const std::string& expected);

  Loader& loader_;
  const toml::table* table_;
  Path path_;
  std::vector<KeyDecl> decls_;
  std::string what_;
};

/// Applies overrides, validates the whole input and builds the Config.
class Loader {
 public:
  explicit Loader(std::string file) : file_(std::move(file)) {}

  Config load(toml::table& root, const std::vector<std::string>& overrides);

  /// Where the value at `path` came from: the `--set` that wrote it, else the node's line.
  [[nodiscard]] SourceLocation locate(const Path& path, const toml::node* node) const {
    const Path* best = nullptr;
    const std::string* origin = nullptr;
    for (const auto& [p, text] : overrides_)
      if (p.size() <= path.size() && std::equal(p.begin(), p.end(), path.begin()) &&
          (!best || p.size() >= best->size())) {
        best = &p;
        origin = &text;
      }
    if (origin) return {*origin, 0};
    return {file_, line_of(node)};
  }

  [[noreturn]] void fail(const Path& path, const toml::node* node, const std::string& expected,
                         const std::string& found) const {
    failed_path_ = path;
    throw error(path, node, expected, found);
  }

  [[nodiscard]] InputError error(const Path& path, const toml::node* node, const std::string& expected,
                                 const std::string& found) const {
    const SourceLocation where = locate(path, node);
    return InputError(where.file, where.line, display(path), expected, found);
  }

  /// Record a warning about the value at `path` ("file:line: key 'k': what"); load() hands them
  /// to Config::warnings.
  void warn(const Path& path, const toml::node* node, const std::string& what) {
    warnings_.push_back(fmt::format("{}: key '{}': {}", locate(path, node).str(), display(path), what));
  }

  /// Parsed default value (kept alive for the loader's lifetime).
  const toml::node* default_node(const KeyDecl& decl) {
    defaults_.push_back(toml::parse("v = " + decl.default_value));
    return defaults_.back().get("v");
  }

  [[nodiscard]] int dimension() const { return dim_; }

  /// Compile `text` (the value of the key at `path`) with the [constants] and check it: valid
  /// syntax, no ',' between expressions, no assignment, only the variables `vars` allows, a
  /// finite value when it uses no variable.
  void check_expression(const Path& path, const toml::node* node, const std::string& text,
                        ExpressionVars vars) const;

 private:
  void apply_override(toml::table& root, const std::string& text);
  /// One reading of the whole (overridden) tree; throws at its first error.
  Config read_all(const toml::table& root);
  /// Every key that its table does not declare, recorded in `errors` and removed from the tree,
  /// so that the reading goes on past them; also every top-level entry that is not a section, or
  /// not of its form: then it returns false (what it holds is missing where it belongs, so the
  /// rest is not read).
  bool remove_undeclared(toml::table& root, std::vector<InputError>& errors) const;
  /// After an error at `failed_path_`: the key to take out of the tree so that reading can go on
  /// past it with the key's default (an undeclared key, or a declared one with a default), or
  /// nothing when the error leaves the rest unreadable (a required key, a cross-key error).
  std::optional<Path> removable_key(const toml::table& root) const;
  void check_top_level(const toml::table& root) const;
  /// One top-level entry: a known section, in the form it must have.
  void check_top_level_entry(const std::string& key, const toml::node& entry) const;
  void read_simulation(const toml::table& root, Config& cfg);
  void read_grid(const toml::table& root, Config& cfg);
  void read_method(const toml::table& root, Config& cfg);
  void read_constants(const toml::table& root, Config& cfg);
  void read_materials(const toml::table& root, Config& cfg);
  void read_bodies(const toml::table& root, Config& cfg);
  /// `earlier`: the bodies read so far (an image named again is shared, not read again).
  BodyShapeConfig read_shape(TableReader& body, const std::vector<BodyConfig>& earlier);
  /// shape = { mesh = {...} }: reads and checks the surface (geometry/surface_mesh.hpp) once per
  /// file and placement; shape = { volume_mesh = {...} }: the particles of a Gmsh mesh's elements.
  void read_mesh_shape(TableReader& r, BodyShapeConfig& s, const std::vector<BodyConfig>& earlier);
  /// file, units, scale, rotate, translate of a mesh shape (into `s`) as a placement.
  geometry::MeshPlacement read_placement(TableReader& r, BodyShapeConfig& s);
  /// The `file` key of a shape read from a file: non-empty, resolved against the input's folder.
  std::string file_key(TableReader& r) {
    const std::string file = r.string("file");
    if (file.empty()) r.fail("file", r.given("file"), "a non-empty file name", "\"\"");
    return resolve_input_relative(file, file_);
  }
  /// What `read` returns, its std::invalid_argument an input error at the `file` key.
  template <class Read>
  auto read_file_key(TableReader& r, const std::string& expected, Read&& read) -> decltype(read()) {
    try {
      return read();
    } catch (const std::invalid_argument& e) {
      r.fail("file", r.given("file"), expected + ", relative to the input file's directory", e.what());
    }
  }
  void read_boundary(const toml::table& root, Config& cfg);
  void read_body_force(const toml::table& root, Config& cfg);
  void read_thermal(const toml::table& root, Config& cfg);
  void read_tractions(const toml::table& root, Config& cfg);
  void read_velocity_conditions(const toml::table& root, Config& cfg);
  void read_walls(const toml::table& root, Config& cfg);
  void read_contact(const toml::table& root, Config& cfg);
  /// [fem] (docs/fem.md): a mesh instead of [grid] and [[body]]; rejects the MPM-only sections.
  void read_fem(const toml::table& root, Config& cfg);
  /// box_min/box_max of a selection: both or neither, max >= min on every axis.
  void read_box(TableReader& r, std::vector<double>& lo, std::vector<double>& hi);
  TimeTable read_table(TableReader& r);
  /// A name for the N-th entry of an array of tables: the given one or <prefix><N>; unique
  /// among `used`.
  std::string entry_name(TableReader& r, const std::string& prefix, std::size_t index,
                         std::vector<std::string>& used);
  void read_output(const toml::table& root, Config& cfg);

  const toml::table* section(const toml::table& root, const std::string& name) const {
    return root.get_as<toml::table>(name);
  }

  std::string file_;
  std::vector<std::pair<Path, std::string>> overrides_;  ///< path -> "--set <text>"
  std::deque<toml::table> defaults_;
  std::vector<std::string> condition_names_;  ///< [[velocity]] and [[wall]] names (history columns)
  Constants constants_;  ///< [constants], for compiling expressions
  std::vector<std::string> warnings_;
  int dim_ = 0;
  std::string length_unit_ = "m";  ///< the model's length unit (simulation.units), for mesh files' units
  mutable std::optional<Path> failed_path_;  ///< where the last fail() was
};

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
    if (std::none_of(decls_.begin(), decls_.end(), [&](const KeyDecl& d) { return d.name == key; }))
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

void Loader::check_expression(const Path& path, const toml::node* node, const std::string& text,
                              ExpressionVars vars) const {
  if (vars == ExpressionVars::unchecked) return;
  if (vars == ExpressionVars::slide) {
    const std::vector<std::string> slide_vars{"Nc", "vslip", "t"};
    try {
      Expression::check(text, slide_vars, constants_);
    } catch (const std::invalid_argument& err) {
      fail(path, node, "one expression in Nc, vslip, t and [constants]", err.what());
    }
    return;
  }
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

// ---- sections ------------------------------------------------------------------------------

void Loader::check_top_level(const toml::table& root) const {
  for (const auto& [key, node] : entries_in_file_order(root)) check_top_level_entry(key, *node);
}

void Loader::check_top_level_entry(const std::string& key, const toml::node& entry) const {
  const auto& sections = section_names();
  const toml::node* node = &entry;
  if (std::find(sections.begin(), sections.end(), key) == sections.end()) {
    std::string expected;
    // A key written above its section header, e.g. `dimension = 2` before [simulation].
    for (const auto& d : declared_keys())
      if (d.name == key && d.section.find('.') == std::string::npos && expected.empty())
        expected = fmt::format("a section, one of {} ('{}' belongs in [{}])", join(sections), key,
                               d.section);
    if (expected.empty())
      expected = "a section, one of " + join(sections) + did_you_mean(key, sections);
    fail({key}, node, expected, node->is_table() ? "an unknown table" : "an undeclared key");
  }
  if (is_table_array(key)) {
    const auto* a = node->as_array();
    const bool tables = a && std::all_of(a->begin(), a->end(), [](const toml::node& n) { return n.is_table(); });
    if (!tables)
      fail({key}, node, fmt::format("an array of tables, written [[{}]]", key),
           node->is_table() ? fmt::format("a single table [{}]", key) : typed_text(*node));
  } else if (!node->is_table()) {
    fail({key}, node, fmt::format("a table, written [{}]", key), typed_text(*node));
  }
}

void Loader::read_simulation(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "simulation"), {"simulation"}, copy_section("simulation"),
                "[simulation]");
  r.reject_unknown_keys();
  auto& s = cfg.simulation;
  s.title = r.string("title");
  s.dimension = dim_ = r.small_integer("dimension");
  const Mode by_dimension[3] = {Mode::uniaxial_strain_1d, Mode::plane_strain, Mode::three_d};
  s.mode = by_dimension[dim_ - 1];
  if (r.present("mode")) {
    const std::string m = r.string("mode");
    const Mode modes[4] = {Mode::plane_strain, Mode::plane_stress, Mode::three_d, Mode::uniaxial_strain_1d};
    for (Mode candidate : modes)
      if (mode_name(candidate) == m) s.mode = candidate;
    const bool consistent = (dim_ == 1 && s.mode == Mode::uniaxial_strain_1d) ||
                            (dim_ == 2 && (s.mode == Mode::plane_strain || s.mode == Mode::plane_stress)) ||
                            (dim_ == 3 && s.mode == Mode::three_d);
    if (!consistent) {
      const char* valid[3] = {"uniaxial", "plane_strain or plane_stress", "3d"};
      r.fail("mode", r.given("mode"), fmt::format("{} for dimension {}", valid[dim_ - 1], dim_),
             toml_string(m));
    }
  }
  s.end_time = r.real("end_time");
  s.cfl = r.real("cfl");
  s.fixed_dt = r.real("dt");
  s.time_step = r.string("time_step");
  s.max_steps = r.integer("max_steps");
  s.thickness = r.real("thickness");
  s.threads = r.small_integer("threads");
  s.adapt_threads = r.boolean("adapt_threads");
  s.sort_particles = r.boolean("sort_particles");
  s.units = r.string("units");
  length_unit_ = unit_symbol(s.units, Quantity::length);
  s.memory_limit = r.real("memory_limit");
  s.rebalance_threshold = r.real("rebalance_threshold");
  s.max_estimated_steps = r.real("max_estimated_steps");
  s.body_overlap = r.string("body_overlap");
  s.where = locate(r.path_of("end_time"), r.given("end_time") ? r.given("end_time") : section(root, "simulation"));
}

void Loader::read_grid(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "grid"), {"grid"}, copy_section("grid"), "[grid]");
  r.reject_unknown_keys();
  const auto n = static_cast<std::size_t>(dim_);
  auto& g = cfg.grid;
  g.origin = r.reals("origin", n, false);
  g.extent = r.reals("extent", n, false);
  g.cell_size = r.reals("cell_size", n, true);
  g.where = locate(r.path_of("cell_size"), r.given("cell_size") ? r.given("cell_size") : section(root, "grid"));
  // Node and cell counts in floating point (no overflow), against the 32-bit node index of
  // grid/grid.hpp; Simulation checks the stored nodes again with the shape's ghost layers.
  double nodes = 1.0;
  std::string counts;
  for (std::size_t a = 0; a < n; ++a) {
    const double cells = g.extent[a] / g.cell_size[a];
    if (!(cells <= static_cast<double>(max_cells_per_axis)))
      r.fail("cell_size", r.given("cell_size"),
             fmt::format("at most {} cells along an axis (grid node indices are 32-bit integers)",
                         max_cells_per_axis),
             fmt::format("{} / {} = {:.6g} cells on axis {}", real_text(g.extent[a]),
                         real_text(g.cell_size[a]), cells, "xyz"[a]));
    nodes *= std::round(cells) + 1.0;
    counts += fmt::format("{}{:.0f}", a ? " x " : "", std::round(cells));
  }
  if (nodes > static_cast<double>(INT32_MAX))
    r.fail("cell_size", r.given("cell_size"),
           fmt::format("at most {} grid nodes in all (grid node indices are 32-bit integers)", INT32_MAX),
           fmt::format("{} cells = {:.6g} nodes", counts, nodes));
  for (std::size_t a = 0; a < n; ++a) {
    const double cells = g.extent[a] / g.cell_size[a];
    const double whole = std::round(cells);
    if (whole < 1.0 || std::abs(cells - whole) > ratio_tolerance * cells)
      r.fail("cell_size", r.given("cell_size"),
             fmt::format("grid.extent / grid.cell_size to be a whole number of cells on axis {} "
                         "(within 1e-9 relative)",
                         "xyz"[a]),
             fmt::format("{} / {} = {:.12g}", real_text(g.extent[a]), real_text(g.cell_size[a]), cells));
  }
}

void Loader::read_method(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "method"), {"method"}, copy_section("method"), "[method]");
  r.reject_unknown_keys();
  auto& m = cfg.method;
  m.shape = r.string("shape");
  m.update = r.string("update");
  m.order = r.small_integer("order");
  m.stress_update = r.string("stress_update");
  m.smoothing_length = r.real("smoothing_length");
  m.cpdi_max_span = r.real("cpdi_max_span");
  if (m.shape == "ugimp" && !cfg.grid.cell_size.empty()) {
    // uGIMP reaches l/2 + h beyond a particle; two ghost layers hold that for l <= 2h.
    const double h_min = *std::min_element(cfg.grid.cell_size.begin(), cfg.grid.cell_size.end());
    if (m.smoothing_length > 2.0 * h_min * (1.0 + 1e-12))
      r.fail("smoothing_length", r.given("smoothing_length"),
             fmt::format("a uGIMP smoothing length of at most twice the smallest cell size ({})",
                         real_text(2.0 * h_min)),
             real_text(m.smoothing_length));
  }
  m.beta = r.real("beta");
  m.blend_position = r.string("blend_position");
  m.position_update = r.string("position_update");
  m.grid_damping = r.real("grid_damping");
  m.particle_damping = r.real("particle_damping");
  m.full_mass_cfl = r.real("full_mass_cfl");
  m.velocity_bc_method = r.string("velocity_bc_method");
  m.time_integration = r.string("time_integration");
  m.integration = r.string("integration");
  m.trigger_weight = r.real("trigger_weight");
  m.surface_distance = r.string("surface_distance");
  m.spurious_force = r.string("spurious_force");
  m.velocity_gradient = r.string("velocity_gradient");
  m.filter_acceleration = r.boolean("filter_acceleration");
}

void Loader::read_constants(const toml::table& root, Config& cfg) {
  const toml::table* t = section(root, "constants");
  if (!t) return;
  const std::vector<std::string> reserved{"x", "y", "z", "X", "Y", "Z", "t", "_pi", "_e"};
  for (const auto& [name, node] : entries_in_file_order(*t)) {
    const Path p{"constants", name};
    if (!is_identifier(name))
      fail(p, node, "a constant name that is an identifier (letters, digits, _; not starting with a digit)",
           toml_string(name));
    if (std::find(reserved.begin(), reserved.end(), name) != reserved.end())
      fail(p, node, "a constant name other than " + join(reserved) + " (built into expressions)",
           toml_string(name));
    double x = 0.0;
    if (auto i = node->as_integer()) x = static_cast<double>(i->get());
    else if (auto f = node->as_floating_point()) x = f->get();
    else fail(p, node, "a number", typed_text(*node));
    if (!std::isfinite(x)) fail(p, node, "a finite number", node_text(*node));
    cfg.constants.emplace_back(name, x);
  }
  constants_ = cfg.constants;
}

void Loader::read_materials(const toml::table& root, Config& cfg) {
  const toml::array* entries = root.get_as<toml::array>("material");
  if (!entries) return;
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* t = entries->get(i)->as_table();
    const Path path = child(Path{"material"}, i);
    // The model decides which keys the table may have, so it is read first.
    TableReader common(*this, t, path, copy_section("material"), "[[material]]");
    const std::string model = common.string("model");
    TableReader r(*this, t, path, material_keys(model),
                  fmt::format("[[material]] with model '{}'", model));
    r.reject_unknown_keys();

    MaterialConfig m;
    m.name = r.string("name");
    if (m.name.empty()) r.fail("name", r.given("name"), "a non-empty name", "\"\"");
    for (const auto& other : cfg.materials)
      if (other.name == m.name)
        r.fail("name", r.given("name"),
               fmt::format("a name not used by another [[material]] (used at {})", other.where.str()),
               toml_string(m.name));
    m.model = model;
    m.numbers["density"] = r.real("density");
    m.numbers["conductivity"] = r.real("conductivity");
    m.numbers["heat_capacity"] = r.real("heat_capacity");
    m.where = {file_, line_of(t)};

    const auto info = material_model_info().find(model);
    std::vector<std::string> given_keys;
    if (info != material_model_info().end()) {
      for (const auto& d : info->second.keys) {
        if (r.present(d.name))
          given_keys.push_back(fmt::format("{} = {}", d.name, node_text(*r.given(d.name))));
        if (!r.present(d.name) && d.default_value.empty()) {
          if (d.required)
            r.fail(d.name, nullptr, expected_value_text(d) + " (required key)", "nothing");
          continue;
        }
        switch (d.type) {
          case KeyType::real: m.numbers[d.name] = r.real(d.name); break;
          case KeyType::integer: m.numbers[d.name] = static_cast<double>(r.integer(d.name)); break;
          case KeyType::boolean: m.numbers[d.name] = r.boolean(d.name) ? 1.0 : 0.0; break;
          case KeyType::string: m.strings[d.name] = r.string(d.name); break;
          default:
            throw std::logic_error(fmt::format(
                "material model '{}' declares key '{}' of a type a [[material]] cannot hold", model,
                d.name));
        }
      }
      if (info->second.check) {
        const std::string problem = info->second.check(m);
        if (!problem.empty())
          fail(path, t, problem,
               fmt::format("model '{}' with {}", model,
                           given_keys.empty() ? "none of its own keys" : join(given_keys)));
      }
    }
    cfg.materials.push_back(std::move(m));
  }
}

BodyShapeConfig Loader::read_shape(TableReader& body, const std::vector<BodyConfig>& earlier) {
  const toml::node* node = body.given("shape");
  if (!node) body.fail("shape", nullptr, "an inline table with one shape kind (required key)", "nothing");
  std::vector<std::string> kinds;
  for (const auto& k : body_shape_kinds()) kinds.push_back(k.name);
  const std::string example = "e.g. { box = { min = [...], max = [...] } }";
  const toml::table* t = node->as_table();
  if (!t) body.fail("shape", node, "an inline table with one shape kind, " + example, typed_text(*node));
  if (t->size() != 1) {
    std::vector<std::string> given;
    for (auto&& [k, v] : *t) given.emplace_back(k.str());
    body.fail("shape", node, "exactly one shape kind, one of " + join(kinds),
              given.empty() ? "an empty table" : fmt::format("{} kinds: {}", given.size(), join(given)));
  }
  std::string kind;
  const toml::node* params = nullptr;
  for (auto&& [k, v] : *t) {
    kind = std::string(k.str());
    params = &v;
  }
  const Path path = body.path_of("shape");
  auto info = std::find_if(body_shape_kinds().begin(), body_shape_kinds().end(),
                           [&](const BodyShapeKind& k) { return k.name == kind; });
  if (info == body_shape_kinds().end())
    fail(child(path, kind), params, "a shape kind, one of " + join(kinds) + did_you_mean(kind, kinds),
         toml_string(kind));
  if (!info->valid_in[dim_ - 1]) {
    std::vector<std::string> valid;
    for (const auto& k : body_shape_kinds())
      if (k.valid_in[dim_ - 1]) valid.push_back(k.name);
    fail(child(path, kind), params, fmt::format("a shape kind valid in {}D, one of {}", dim_, join(valid)),
         toml_string(kind));
  }
  if (!params->is_table())
    fail(child(path, kind), params, fmt::format("a table of the {} parameters", kind), typed_text(*params));

  TableReader r(*this, params->as_table(), child(path, kind), copy_section("body.shape." + kind),
                fmt::format("a {} shape", kind));
  r.reject_unknown_keys();
  const auto n = static_cast<std::size_t>(dim_);
  BodyShapeConfig s;
  s.kind = kind;
  if (kind == "box") {
    s.min = r.reals("min", n, false);
    s.max = r.reals("max", n, false);
    for (std::size_t a = 0; a < n; ++a)
      if (!(s.max[a] > s.min[a]))
        r.fail("max", r.given("max"), fmt::format("max > min on every axis"),
               fmt::format("max {} <= min {} on axis {}", real_text(s.max[a]), real_text(s.min[a]), "xyz"[a]));
  } else if (kind == "circle" || kind == "sphere") {
    s.center = r.reals("center", n, false);
    s.radius = r.real("radius");
  } else if (kind == "cylinder") {
    s.center = r.reals("center", n, false);
    s.radius = r.real("radius");
    s.height = r.real("height");
  } else if (kind == "ellipse") {
    s.center = r.reals("center", n, false);
    s.semi_axes = r.reals("semi_axes", n, false);
  } else if (kind == "annulus") {
    s.center = r.reals("center", n, false);
    s.inner_radius = r.real("inner_radius");
    s.outer_radius = r.real("outer_radius");
    if (!(s.inner_radius < s.outer_radius))
      r.fail("inner_radius", r.given("inner_radius"), "inner_radius < outer_radius",
             fmt::format("inner_radius = {}, outer_radius = {}", real_text(s.inner_radius),
                         real_text(s.outer_radius)));
  } else if (kind == "polygon") {
    s.vertices = r.points("vertices", 2, 3);
    double twice_area = 0.0;
    for (std::size_t i = 0; i < s.vertices.size(); ++i) {
      const auto& a = s.vertices[i];
      const auto& b = s.vertices[(i + 1) % s.vertices.size()];
      twice_area += a[0] * b[1] - b[0] * a[1];
    }
    if (twice_area == 0.0)
      r.fail("vertices", r.given("vertices"), "vertices enclosing a non-zero area", "zero area");
  } else if (kind == "image") {
    const std::string file = r.string("file");
    if (file.empty()) r.fail("file", r.given("file"), "a non-empty PNG file name", "\"\"");
    s.file = resolve_input_relative(file, file_);
    s.pixel_size = r.real("pixel_size");
    s.origin = r.reals("origin", 2, false);
    const std::string levels = "an array of 2 integers [lo, hi], each in 0..255";
    if (const toml::node* lv = r.given("levels")) {
      const toml::array* a = lv->as_array();
      if (!a) r.fail("levels", lv, levels, typed_text(*lv));
      if (a->size() != 2) r.fail("levels", lv, levels, fmt::format("{} ({} entries)", node_text(*lv), a->size()));
    }
    const std::vector<int> lh = r.integers("levels", 2, false);
    s.level_min = lh[0];
    s.level_max = lh[1];
    if (s.level_min > s.level_max)
      r.fail("levels", r.given("levels"), "levels [lo, hi] with lo <= hi",
             fmt::format("lo = {} > hi = {}", s.level_min, s.level_max));
    for (const auto& other : earlier)
      if (other.shape.image && other.shape.file == s.file) s.image = other.shape.image;
    if (!s.image) {
      try {
        s.image = std::make_shared<const GreyImage>(read_png_grey(s.file));
      } catch (const std::invalid_argument& e) {
        r.fail("file", r.given("file"), "a readable PNG file (relative to the input file's directory)",
               e.what());
      }
    }
  } else if (kind == "mesh" || kind == "volume_mesh") {
    read_mesh_shape(r, s, earlier);
  } else if (kind == "outline") {
    s.file = file_key(r);
    s.scale = r.real("scale");
    s.translate = r.reals("translate", 2, false);
    s.loops = read_file_key(r, "a CSV outline: lines \"x, y\", loops separated by blank lines, the first the "
                               "outside and the others holes inside it, no two edges meeting (docs/geometry.md)",
                            [&] { return geometry::read_outline_csv(s.file, s.scale, s.translate); });
  } else if (kind == "points") {
    s.file = file_key(r);
    s.points = read_file_key(r, "a point file: CSV with a header row x, y(, z), volume[, vx, vy(, vz)][, temperature] "
                                "and one row per particle, or HDF5 (.h5) with datasets position, volume[, velocity]"
                                "[, temperature] (docs/geometry.md)",
                             [&] { return geometry::read_point_file(s.file, dim_); });
  } else {
    throw std::logic_error("input: shape kind '" + kind + "' declared but not read");
  }
  return s;
}

geometry::MeshPlacement Loader::read_placement(TableReader& r, BodyShapeConfig& s) {
  s.file = file_key(r);
  s.units = r.string("units");
  s.scale = r.real("scale");
  s.rotate = r.reals("rotate", 3, false);
  s.translate = r.reals("translate", 3, false);
  if (dim_ == 2 && (s.rotate[0] != 0.0 || s.rotate[1] != 0.0))
    r.fail("rotate", r.given("rotate"), "[0, 0, angle] in 2D (a turn about z)",
           fmt::format("[{}, {}, {}]", s.rotate[0], s.rotate[1], s.rotate[2]));
  if (dim_ == 2 && s.translate[2] != 0.0)
    r.fail("translate", r.given("translate"), "[x, y, 0] in 2D",
           fmt::format("[{}, {}, {}]", s.translate[0], s.translate[1], s.translate[2]));
  geometry::MeshPlacement placement;
  placement.scale = s.scale;
  if (s.units != "model") {
    double model = 0.0;
    try {
      model = geometry::unit_in_metres(length_unit_);
    } catch (const std::invalid_argument&) {
      r.fail("units", r.given("units"),
             "\"model\" while simulation.units declares no length unit (or declare one, e.g. \"SI\")",
             toml_string(s.units));
    }
    placement.scale *= geometry::unit_in_metres(s.units) / model;
  }
  for (std::size_t a = 0; a < 3; ++a) {
    placement.rotate_degrees[a] = s.rotate[a];
    placement.translate[a] = s.translate[a];
  }
  return placement;
}

void Loader::read_mesh_shape(TableReader& r, BodyShapeConfig& s, const std::vector<BodyConfig>& earlier) {
  const geometry::MeshPlacement placement = read_placement(r, s);
  if (s.kind == "volume_mesh") {
    s.quadrature = static_cast<int>(r.integer("quadrature"));
    s.points = read_file_key(r,
                             "a Gmsh mesh of 3-node triangles (2D) or 4-node tetrahedra (3D), quadrature 1 or 3 "
                             "(2D) / 4 (3D) (docs/geometry.md)",
                             [&] { return geometry::read_volume_mesh(s.file, dim_, s.quadrature, placement); });
    return;
  }
  for (const auto& other : earlier)
    if (other.shape.mesh && other.shape.file == s.file && other.shape.units == s.units &&
        other.shape.scale == s.scale && other.shape.rotate == s.rotate && other.shape.translate == s.translate)
      s.mesh = other.shape.mesh;
  if (s.mesh) return;
  s.mesh = read_file_key(r,
                         "a closed triangle surface without open edges, self-intersections or degenerate faces "
                         "(docs/geometry.md)",
                         [&] { return geometry::read_surface_mesh(s.file, placement); });
  for (const auto& w : s.mesh->warnings()) warn(r.path_of("file"), r.given("file"), w);
}

void Loader::read_bodies(const toml::table& root, Config& cfg) {
  const toml::array* entries = root.get_as<toml::array>("body");
  if (!entries || entries->empty())
    fail({"body"}, nullptr, "at least one [[body]] table", "none");
  std::vector<std::string> material_names;
  for (const auto& m : cfg.materials) material_names.push_back(m.name);
  const auto n = static_cast<std::size_t>(dim_);
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* t = entries->get(i)->as_table();
    TableReader r(*this, t, child(Path{"body"}, i), copy_section("body"), "[[body]]");
    r.reject_unknown_keys();
    BodyConfig b;
    b.name = r.present("name") ? r.string("name") : fmt::format("body{}", i);
    if (b.name.empty()) r.fail("name", r.given("name"), "a non-empty name", "\"\"");
    for (const auto& other : cfg.bodies)
      if (other.name == b.name)
        r.fail("name", r.given("name"),
               fmt::format("a name not used by another [[body]] (used at {})", other.where.str()),
               toml_string(b.name));
    b.material = r.string("material");
    if (std::find(material_names.begin(), material_names.end(), b.material) == material_names.end())
      r.fail("material", r.given("material"),
             material_names.empty()
                 ? std::string("the name of a [[material]] (the input has none)")
                 : "the name of a [[material]], one of " + join(material_names) +
                       did_you_mean(b.material, material_names),
             toml_string(b.material));
    b.shape = read_shape(r, cfg.bodies);
    b.particles_per_cell = r.integers("particles_per_cell", n, true);
    b.velocity = r.expressions("velocity", n, ExpressionVars::initial);
    if (b.velocity.empty()) b.velocity.assign(n, "0");
    b.displacement = r.expressions("displacement", n, ExpressionVars::initial);
    b.clip = r.boolean("clip");
    b.arrangement = r.string("arrangement");
    if (b.arrangement == "radial" && !wls::radial_arrangement_supported(b.shape.kind))
      r.fail("arrangement", r.given("arrangement"),
             "cartesian for a " + b.shape.kind + " (radial needs a circle, annulus or sphere shape)",
             toml_string(b.arrangement));
    b.where = {file_, line_of(t)};
    cfg.bodies.push_back(std::move(b));
  }
}

void Loader::read_boundary(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "boundary"), {"boundary"}, copy_section("boundary"),
                "[boundary]");
  r.reject_unknown_keys();
  std::vector<std::string> valid;
  for (int f = 0; f < 2 * dim_; ++f) valid.push_back(face_names[f]);
  for (int f = 0; f < 6; ++f) {
    if (f >= 2 * dim_) {
      if (r.present(face_names[f]))
        r.fail(face_names[f], r.given(face_names[f]),
               fmt::format("a face of the {}D grid, one of {}", dim_, join(valid)),
               fmt::format("{} (a {}D grid has no {} axis)", face_names[f], dim_, "xyz"[f / 2]));
      continue;
    }
    const std::string c = r.string(face_names[f]);
    for (int k = 0; k < 4; ++k)
      if (c == face_condition_names[k]) cfg.boundary.face[f] = static_cast<FaceCondition>(k);
  }
  cfg.boundary.acceleration = r.string("acceleration") == "velocity_change"
                                  ? BoundaryAcceleration::velocity_change
                                  : BoundaryAcceleration::zero;
  for (int a = 0; a < dim_; ++a) {
    const bool lo = cfg.boundary.face[2 * a] == FaceCondition::periodic;
    const bool hi = cfg.boundary.face[2 * a + 1] == FaceCondition::periodic;
    if (lo != hi) {
      const int f = lo ? 2 * a : 2 * a + 1;
      const auto text = [&](int face) {
        return fmt::format("{} = \"{}\"", face_names[face],
                           face_condition_names[static_cast<int>(cfg.boundary.face[face])]);
      };
      r.fail(face_names[f], r.given(face_names[f]),
             fmt::format("periodic on both {} faces ({} and {})", "xyz"[a], face_names[2 * a],
                         face_names[2 * a + 1]),
             text(2 * a) + ", " + text(2 * a + 1));
    }
  }
}

void Loader::read_thermal(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "thermal"), {"thermal"}, copy_section("thermal"), "[thermal]");
  r.reject_unknown_keys();
  cfg.thermal.conduction = r.boolean("conduction");
  for (int f = 0; f < 6; ++f) {
    const std::string face = face_names[f];
    if (f >= 2 * dim_) {
      for (const std::string& key : {face, face + "_value"})
        if (r.present(key))
          r.fail(key, r.given(key), fmt::format("a face of the {}D grid", dim_), key);
      continue;
    }
    const std::string c = r.string(face);
    cfg.thermal.face[f] = c == "temperature" ? ThermalFace::temperature
                          : c == "flux"      ? ThermalFace::flux
                                             : ThermalFace::adiabatic;
    cfg.thermal.value[f] = r.real(face + "_value");
  }
}

void Loader::read_body_force(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "body_force"), {"body_force"}, copy_section("body_force"),
                "[body_force]");
  r.reject_unknown_keys();
  cfg.body_force.expression = r.expressions("expression", static_cast<std::size_t>(dim_),
                                            ExpressionVars::field);
}

std::string Loader::entry_name(TableReader& r, const std::string& prefix, std::size_t index,
                               std::vector<std::string>& used) {
  const std::string name = r.present("name") ? r.string("name") : fmt::format("{}{}", prefix, index);
  const bool ok = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
  if (!ok) r.fail("name", r.given("name"), "a non-empty name of letters, digits, _ and -", toml_string(name));
  if (std::find(used.begin(), used.end(), name) != used.end())
    r.fail("name", r.given("name"), fmt::format("a name not used by another [[{}]]{}", prefix,
                                                prefix == "traction" ? "" : " or [[velocity]]/[[wall]]"),
           toml_string(name));
  used.push_back(name);
  return name;
}

void Loader::read_box(TableReader& r, std::vector<double>& lo, std::vector<double>& hi) {
  if (r.present("box_min") != r.present("box_max")) {
    const std::string missing = r.present("box_min") ? "box_max" : "box_min";
    r.fail(missing, nullptr, "box_min and box_max together", "only one of them");
  }
  if (!r.present("box_min")) return;
  const auto n = static_cast<std::size_t>(dim_);
  lo = r.reals("box_min", n, false);
  hi = r.reals("box_max", n, false);
  for (std::size_t a = 0; a < n; ++a)
    if (hi[a] < lo[a])
      r.fail("box_max", r.given("box_max"), "box_max >= box_min on every axis",
             fmt::format("box_max {} < box_min {} on axis {}", real_text(hi[a]), real_text(lo[a]), "xyz"[a]));
}

TimeTable Loader::read_table(TableReader& r) {
  TimeTable table;
  if (!r.present("table")) return table;
  for (const auto& point : r.points("table", 2, 1)) table.emplace_back(point[0], point[1]);
  for (std::size_t k = 1; k < table.size(); ++k)
    if (!(table[k].first > table[k - 1].first))
      r.fail("table", r.given("table"), "points [t, f] with increasing t",
             fmt::format("t = {} after t = {}", real_text(table[k].first), real_text(table[k - 1].first)));
  return table;
}

namespace {
/// Index of `name` in `names`, or -1.
int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}
const std::vector<std::string> axis_letters{"x", "y", "z"};
const std::vector<std::string> all_faces{"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
}  // namespace

void Loader::read_tractions(const toml::table& root, Config& cfg) {
  const toml::array* entries = root.get_as<toml::array>("traction");
  if (!entries) return;
  const auto n = static_cast<std::size_t>(dim_);
  std::vector<std::string> used, bodies;
  for (const auto& b : cfg.bodies) bodies.push_back(b.name);
  const std::vector<std::string> faces(all_faces.begin(), all_faces.begin() + 2 * dim_);
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* t = entries->get(i)->as_table();
    const Path path = child(Path{"traction"}, i);
    TableReader r(*this, t, path, copy_section("traction"), "[[traction]]");
    r.reject_unknown_keys();
    TractionConfig c;
    c.name = entry_name(r, "traction", i, used);
    c.body = r.string("body");
    if (!c.body.empty() && index_of(bodies, c.body) < 0)
      r.fail("body", r.given("body"),
             "\"\" or the name of a [[body]], one of " + join(bodies) + did_you_mean(c.body, bodies),
             toml_string(c.body));
    if (r.present("side")) {
      const std::string side = r.string("side");
      c.side = index_of(faces, side);
      if (c.side < 0)
        r.fail("side", r.given("side"), fmt::format("a side of the {}D grid, one of {}", dim_, join(faces)),
               toml_string(side));
    }
    read_box(r, c.box_min, c.box_max);
    if (c.side < 0 && c.box_min.empty())
      fail(path, t, "side, or box_min and box_max, to select the loaded faces", "neither");
    c.traction = r.reals("traction", n, false);
    c.scale = r.expression("scale", ExpressionVars::time);
    c.table = read_table(r);
    c.where = {file_, line_of(t)};
    cfg.tractions.push_back(std::move(c));
  }
}

void Loader::read_velocity_conditions(const toml::table& root, Config& cfg) {
  const toml::array* entries = root.get_as<toml::array>("velocity");
  if (!entries) return;
  const auto n = static_cast<std::size_t>(dim_);
  const std::vector<std::string> faces(all_faces.begin(), all_faces.begin() + 2 * dim_);
  const std::vector<std::string> axes(axis_letters.begin(), axis_letters.begin() + dim_);
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* t = entries->get(i)->as_table();
    const Path path = child(Path{"velocity"}, i);
    TableReader r(*this, t, path, copy_section("velocity"), "[[velocity]]");
    r.reject_unknown_keys();
    VelocityConditionConfig c;
    c.name = entry_name(r, "velocity", i, condition_names_);
    if (r.present("face")) {
      const std::string face = r.string("face");
      c.face = index_of(faces, face);
      if (c.face < 0)
        r.fail("face", r.given("face"), fmt::format("a face of the {}D grid, one of {}", dim_, join(faces)),
               toml_string(face));
      if (cfg.boundary.face[c.face] == FaceCondition::periodic)
        r.fail("face", r.given("face"), "a face that is not periodic ([boundary])", toml_string(face));
    }
    read_box(r, c.box_min, c.box_max);
    if (r.present("plane_axis") != r.present("plane_at")) {
      const std::string missing = r.present("plane_axis") ? "plane_at" : "plane_axis";
      r.fail(missing, nullptr, "plane_axis and plane_at together", "only one of them");
    }
    if (r.present("plane_axis")) {
      const std::string axis = r.string("plane_axis");
      c.plane_axis = index_of(axes, axis);
      if (c.plane_axis < 0)
        r.fail("plane_axis", r.given("plane_axis"), fmt::format("an axis of the {}D grid, one of {}", dim_, join(axes)),
               toml_string(axis));
      c.plane_at = r.real("plane_at");
    }
    if (c.face < 0 && c.box_min.empty() && c.plane_axis < 0)
      fail(path, t, "face, box_min/box_max or plane_axis/plane_at to select the nodes", "none of them");
    c.direction = r.reals("direction", n, false);
    double norm = 0.0;
    for (double d : c.direction) norm += d * d;
    if (!(norm > 0.0)) r.fail("direction", r.given("direction"), "a non-zero direction", "all zeros");
    for (double& d : c.direction) d /= std::sqrt(norm);
    c.velocity = r.expression("velocity", ExpressionVars::time);
    c.table = read_table(r);
    c.where = {file_, line_of(t)};
    cfg.velocity_conditions.push_back(std::move(c));
  }
}

void Loader::read_walls(const toml::table& root, Config& cfg) {
  const toml::array* entries = root.get_as<toml::array>("wall");
  if (!entries) return;
  const std::vector<std::string> axes(axis_letters.begin(), axis_letters.begin() + dim_);
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* t = entries->get(i)->as_table();
    const Path path = child(Path{"wall"}, i);
    TableReader r(*this, t, path, copy_section("wall"), "[[wall]]");
    r.reject_unknown_keys();
    WallConfig c;
    c.name = entry_name(r, "wall", i, condition_names_);
    const std::string axis = r.string("axis");
    c.axis = index_of(axes, axis);
    if (c.axis < 0)
      r.fail("axis", r.given("axis"), fmt::format("an axis of the {}D grid, one of {}", dim_, join(axes)),
             toml_string(axis));
    if (cfg.boundary.face[2 * c.axis] == FaceCondition::periodic)
      r.fail("axis", r.given("axis"), "an axis that is not periodic ([boundary])", toml_string(axis));
    c.inside_below = r.string("inside") == "below";
    c.position = r.real("position");
    const double lo = cfg.grid.origin[c.axis], hi = lo + cfg.grid.extent[c.axis];
    if (c.position < lo || c.position > hi)
      r.fail("position", r.given("position"),
             fmt::format("a wall position inside the grid along {}, in [{}, {}]", axis, real_text(lo), real_text(hi)),
             real_text(c.position));
    c.velocity = r.expression("velocity", ExpressionVars::time);
    c.table = read_table(r);
    const std::string gradient = r.expression("gradient", ExpressionVars::unchecked);
    if (gradient == "zero") {
      c.gradient = WallGradient::zero;
    } else if (gradient == "estimate") {
      c.gradient = WallGradient::estimate;
    } else {
      check_expression(r.path_of("gradient"), r.given("gradient"), gradient, ExpressionVars::time);
      c.gradient = WallGradient::given;
      c.gradient_expression = gradient;
    }
    c.depth = r.real("depth");
    c.where = {file_, line_of(t)};
    cfg.walls.push_back(std::move(c));
  }
}

void Loader::read_fem(const toml::table& root, Config& cfg) {
  // An FEM run has no grid and no particles: the sections that describe them, or features the
  // FEM does not implement, are errors rather than silently ignored.
  for (const char* other : {"grid", "method", "body", "traction", "wall", "contact", "contact_pair", "thermal"})
    if (const toml::node* node = root.get(other))
      fail({other}, node,
           fmt::format("no [{}] in an FEM run ([fem] meshes the body; docs/fem.md lists what the FEM "
                       "supports)", other),
           fmt::format("[{}]", other));
  const toml::table* t = section(root, "fem");
  if (!t) fail({"fem"}, root.get("fem"), "a table, written [fem]", typed_text(*root.get("fem")));
  TableReader r(*this, t, {"fem"}, copy_section("fem"), "[fem]");
  r.reject_unknown_keys();
  if (dim_ != 2)
    fail({"simulation", "dimension"}, nullptr, "dimension = 2 for an FEM run (linear triangles)",
         fmt::format("{}", dim_));
  auto& f = cfg.fem;
  f.enabled = true;
  f.where = {file_, line_of(t)};
  std::vector<std::string> material_names;
  for (const auto& m : cfg.materials) material_names.push_back(m.name);
  f.material = r.string("material");
  if (std::find(material_names.begin(), material_names.end(), f.material) == material_names.end())
    r.fail("material", r.given("material"),
           material_names.empty() ? std::string("the name of a [[material]] (the input has none)")
                                  : "the name of a [[material]], one of " + join(material_names) +
                                        did_you_mean(f.material, material_names),
           toml_string(f.material));
  const auto n = static_cast<std::size_t>(dim_);
  const std::string file = r.string("mesh_file");
  if (file.empty() == !r.present("shape"))
    fail({"fem"}, t, "exactly one of fem.mesh_file (a Gmsh .msh file) and fem.shape (a generated mesh)",
         file.empty() ? "neither" : "both");
  if (!file.empty()) {
    f.mesh_file = resolve_input_relative(file, file_);
  } else {
    f.shape = read_shape(r, {});
    if (f.shape.kind == "image")
      r.fail("shape", r.given("shape"), "a shape the mesher can generate: box, circle, ellipse, annulus or polygon",
             "image");
  }
  f.hole_radius = r.real("hole_radius");
  if (f.hole_radius > 0.0) {
    if (!file.empty()) r.fail("hole_radius", r.given("hole_radius"), "no hole with a mesh_file (the file is the mesh)",
                              real_text(f.hole_radius));
    f.hole_center = r.reals("hole_center", n, false);
  } else if (r.present("hole_center")) {
    r.fail("hole_center", r.given("hole_center"), "hole_radius > 0 with hole_center", "hole_radius = 0");
  }
  f.size = r.real("size");
  if (file.empty() && !(f.size > 0.0))
    r.fail("size", r.given("size"), "an element size > 0 for a generated mesh", real_text(f.size));
  f.mesher = r.string("mesher");
  if (f.mesher == "structured" && file.empty() && f.shape.kind != "box" && f.shape.kind != "annulus")
    r.fail("mesher", r.given("mesher"), "\"gmsh\" for a " + f.shape.kind +
           " (the structured mesher makes boxes and annuli)", toml_string(f.mesher));
  if (f.mesher == "structured" && f.hole_radius > 0.0)
    r.fail("mesher", r.given("mesher"), "\"gmsh\" for a shape with a hole", toml_string(f.mesher));
  f.velocity = r.expressions("velocity", n, ExpressionVars::initial);
  if (f.velocity.empty()) f.velocity.assign(n, "0");
  f.displacement = r.expressions("displacement", n, ExpressionVars::initial);
  f.exact_displacement = r.expressions("exact_displacement", n, ExpressionVars::field);
  for (int face = 0; face < 2 * dim_; ++face)
    if (cfg.boundary.face[face] == FaceCondition::periodic)
      fail({"boundary", face_names[face]}, nullptr, "fixed, symmetry or free in an FEM run", "\"periodic\"");
}

void Loader::read_output(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "output"), {"output"}, copy_section("output"), "[output]");
  r.reject_unknown_keys();
  auto& o = cfg.output;
  o.directory = r.string("directory");
  if (o.directory.empty()) {
    std::string stem = std::filesystem::path(file_).stem().string();
    o.directory = "out/" + (stem.empty() ? std::string("input") : stem);
  }
  o.every = r.real("every");
  o.history_every = r.real("history_every");
  o.checkpoint_every = r.real("checkpoint_every");
  o.snapshots = r.boolean("snapshots");
  o.grid_snapshots = r.boolean("grid_snapshots");
  o.checkpoints = r.boolean("checkpoints");
  o.exact_displacement = r.expressions("exact_displacement", static_cast<std::size_t>(dim_), ExpressionVars::field);
  o.checkpoint_wall_interval = r.real("checkpoint_wall_interval");
  o.compression = r.small_integer("compression");
  o.existing = r.string("existing");
}

void Loader::read_contact(const toml::table& root, Config& cfg) {
  const toml::table* t = section(root, "contact");
  TableReader r(*this, t, {"contact"}, copy_section("contact"), "[contact]");
  r.reject_unknown_keys();
  ContactConfig& c = cfg.contact;
  c.mode = r.string("mode");
  c.where = {file_, t ? line_of(t) : 0};
  std::vector<std::string> fields;
  if (c.mode == "material")
    for (const auto& m : cfg.materials) fields.push_back(m.name);
  else if (c.mode == "body")
    for (const auto& b : cfg.bodies) fields.push_back(b.name);
  auto read_law = [](TableReader& lr) {
    ContactLawConfig law;
    law.law = lr.string("law");
    law.friction = lr.real("friction");
    law.dynamic_friction = lr.real("dynamic_friction");
    law.slide = lr.expression("slide", ExpressionVars::slide);
    return law;
  };
  c.law = read_law(r);
  c.normal = r.string("normal");
  if (c.normal == "specified") {
    if (!r.present("normal_direction"))
      r.fail("normal_direction", nullptr, "a normal direction when normal = \"specified\"", "nothing");
    c.normal_direction = r.reals("normal_direction", static_cast<std::size_t>(dim_), false);
    double norm = 0.0;
    for (double v : c.normal_direction) norm += v * v;
    if (!(norm > 0.0))
      r.fail("normal_direction", r.given("normal_direction"), "a non-zero vector", "a zero vector");
  } else if (r.present("normal_direction")) {
    c.normal_direction = r.reals("normal_direction", static_cast<std::size_t>(dim_), false);
  }
  c.lr_weights = r.string("lr_weights");
  c.lr_refine = r.string("lr_refine");
  c.first_correction = r.string("first_correction");
  c.detection = r.string("detection");
  c.critical_separation = r.real("critical_separation");
  c.touching_tolerance = r.real("touching_tolerance");
  c.lr_separation = r.string("lr_separation");
  c.corrections = r.string("corrections");
  c.three_or_more = r.string("three_or_more");
  c.xpic_correction = r.boolean("xpic_correction");

  const toml::array* entries = root.get_as<toml::array>("contact_pair");
  if (!entries) return;
  for (std::size_t i = 0; i < entries->size(); ++i) {
    const toml::table* e = entries->get(i)->as_table();
    const Path path = child(Path{"contact_pair"}, i);
    TableReader pr(*this, e, path, copy_section("contact_pair"), "[[contact_pair]]");
    pr.reject_unknown_keys();
    if (c.mode == "none")
      fail(path, e, "a [contact] mode of material or body for [[contact_pair]] to apply", "mode = \"none\"");
    ContactPairConfig pc;
    for (const char* key : {"first", "second"}) {
      const std::string name = pr.string(key);
      if (index_of(fields, name) < 0)
        pr.fail(key, pr.given(key),
                fmt::format("the name of a {} (contact mode {}), one of {}{}",
                            c.mode == "material" ? "[[material]]" : "[[body]]", c.mode, join(fields),
                            did_you_mean(name, fields)),
                toml_string(name));
      (std::string(key) == "first" ? pc.first : pc.second) = name;
    }
    if (pc.first == pc.second)
      pr.fail("second", pr.given("second"), "a field other than first", toml_string(pc.second));
    if (!pr.present("law")) pr.fail("law", nullptr, "the pair's contact law", "nothing");
    pc.law = read_law(pr);
    pc.where = {file_, line_of(e)};
    c.pairs.push_back(std::move(pc));
  }
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
      if (std::none_of(decls.begin(), decls.end(), [&](const KeyDecl& d) { return d.name == key; })) {
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
  read_output(root, cfg);
  cfg.resolved_toml = config_to_toml(cfg);
  cfg.warnings = std::move(warnings_);
  return cfg;
}

// ---- writing -------------------------------------------------------------------------------

template <class T, class F>
std::string array_text(const std::vector<T>& values, F&& text) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + text(values[i]);
  return out + "]";
}

std::string reals_text(const std::vector<double>& v) { return array_text(v, real_text); }

/// An expression entry: as a number when reading that number back gives the same text.
std::string expression_text(const std::string& e) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(e.data(), e.data() + e.size(), v);
  if (ec == std::errc() && end == e.data() + e.size() && std::isfinite(v) && expression_number(v) == e)
    return real_text(v);
  return toml_string(e);
}

std::string shape_text(const BodyShapeConfig& s) {
  std::string params;
  if (s.kind == "box") params = fmt::format("min = {}, max = {}", reals_text(s.min), reals_text(s.max));
  else if (s.kind == "circle" || s.kind == "sphere")
    params = fmt::format("center = {}, radius = {}", reals_text(s.center), real_text(s.radius));
  else if (s.kind == "ellipse")
    params = fmt::format("center = {}, semi_axes = {}", reals_text(s.center), reals_text(s.semi_axes));
  else if (s.kind == "cylinder")
    params = fmt::format("center = {}, radius = {}, height = {}", reals_text(s.center), real_text(s.radius),
                         real_text(s.height));
  else if (s.kind == "annulus")
    params = fmt::format("center = {}, inner_radius = {}, outer_radius = {}", reals_text(s.center),
                         real_text(s.inner_radius), real_text(s.outer_radius));
  else if (s.kind == "polygon")
    params = "vertices = " + array_text(s.vertices, reals_text);
  else if (s.kind == "image")
    params = fmt::format("file = {}, pixel_size = {}, origin = {}, levels = [{}, {}]", toml_string(s.file),
                         real_text(s.pixel_size), reals_text(s.origin), s.level_min, s.level_max);
  else if (s.kind == "outline")
    params = fmt::format("file = {}, scale = {}, translate = {}", toml_string(s.file), real_text(s.scale),
                         reals_text(s.translate));
  else if (s.kind == "points")
    params = fmt::format("file = {}", toml_string(s.file));
  else if (s.kind == "mesh" || s.kind == "volume_mesh")
    params = fmt::format("file = {}, {}units = {}, scale = {}, rotate = {}, translate = {}", toml_string(s.file),
                         s.kind == "volume_mesh" ? fmt::format("quadrature = {}, ", s.quadrature) : "",
                         toml_string(s.units), real_text(s.scale), reals_text(s.rotate), reals_text(s.translate));
  return fmt::format("{{ {} = {{ {} }} }}", toml_key(s.kind), params);
}

}  // namespace

std::string config_to_toml(const Config& c) {
  std::string o;
  auto line = [&](const std::string& key, const std::string& value) {
    o += fmt::format("{} = {}\n", toml_key(key), value);
  };
  auto boolean = [](bool b) { return std::string(b ? "true" : "false"); };
  const auto& s = c.simulation;
  o += "[simulation]\n";
  line("title", toml_string(s.title));
  line("dimension", fmt::format("{}", s.dimension));
  line("mode", toml_string(mode_name(s.mode)));
  line("end_time", real_text(s.end_time));
  line("cfl", real_text(s.cfl));
  line("dt", real_text(s.fixed_dt));
  line("time_step", toml_string(s.time_step));
  line("max_steps", fmt::format("{}", s.max_steps));
  line("thickness", real_text(s.thickness));
  line("threads", fmt::format("{}", s.threads));
  line("adapt_threads", s.adapt_threads ? "true" : "false");
  line("sort_particles", s.sort_particles ? "true" : "false");
  line("rebalance_threshold", real_text(s.rebalance_threshold));
  line("units", toml_string(s.units));
  line("memory_limit", real_text(s.memory_limit));
  line("max_estimated_steps", real_text(s.max_estimated_steps));
  line("body_overlap", toml_string(s.body_overlap));

  if (!c.fem.enabled) {
    o += "\n[grid]\n";
    line("origin", reals_text(c.grid.origin));
    line("extent", reals_text(c.grid.extent));
    line("cell_size", reals_text(c.grid.cell_size));

    const auto& m = c.method;
    o += "\n[method]\n";
    line("shape", toml_string(m.shape));
    line("update", toml_string(m.update));
    line("order", fmt::format("{}", m.order));
    line("stress_update", toml_string(m.stress_update));
    line("smoothing_length", real_text(m.smoothing_length));
    line("cpdi_max_span", real_text(m.cpdi_max_span));
    line("beta", real_text(m.beta));
    line("blend_position", toml_string(m.blend_position));
    line("position_update", toml_string(m.position_update));
    line("grid_damping", real_text(m.grid_damping));
    line("particle_damping", real_text(m.particle_damping));
    line("full_mass_cfl", real_text(m.full_mass_cfl));
    line("velocity_bc_method", toml_string(m.velocity_bc_method));
    line("time_integration", toml_string(m.time_integration));
    line("integration", toml_string(m.integration));
    line("trigger_weight", real_text(m.trigger_weight));
    line("surface_distance", toml_string(m.surface_distance));
    line("spurious_force", toml_string(m.spurious_force));
    line("velocity_gradient", toml_string(m.velocity_gradient));
    line("filter_acceleration", m.filter_acceleration ? "true" : "false");
  }

  if (!c.constants.empty()) {
    o += "\n[constants]\n";
    for (const auto& [name, value] : c.constants) line(name, real_text(value));
  }

  for (const auto& mat : c.materials) {
    o += "\n[[material]]\n";
    line("name", toml_string(mat.name));
    line("model", toml_string(mat.model));
    line("density", real_text(mat.number("density")));
    line("conductivity", real_text(mat.number("conductivity")));
    line("heat_capacity", real_text(mat.number("heat_capacity")));
    auto info = material_model_info().find(mat.model);
    if (info == material_model_info().end()) continue;
    for (const auto& d : info->second.keys) {
      if (d.type == KeyType::string) {
        if (auto it = mat.strings.find(d.name); it != mat.strings.end()) line(d.name, toml_string(it->second));
        continue;
      }
      auto it = mat.numbers.find(d.name);
      if (it == mat.numbers.end()) continue;
      if (d.type == KeyType::integer) line(d.name, fmt::format("{}", static_cast<long long>(it->second)));
      else if (d.type == KeyType::boolean) line(d.name, boolean(it->second != 0.0));
      else line(d.name, real_text(it->second));
    }
  }

  for (const auto& b : c.bodies) {
    o += "\n[[body]]\n";
    line("name", toml_string(b.name));
    line("material", toml_string(b.material));
    line("shape", shape_text(b.shape));
    line("particles_per_cell", array_text(b.particles_per_cell, [](int n) { return fmt::format("{}", n); }));
    line("velocity", array_text(b.velocity, expression_text));
    if (!b.displacement.empty()) line("displacement", array_text(b.displacement, expression_text));
    if (b.clip) line("clip", "true");
    line("arrangement", toml_string(b.arrangement));
  }
  if (c.fem.enabled) {
    const auto& f = c.fem;
    o += "\n[fem]\n";
    line("material", toml_string(f.material));
    if (!f.mesh_file.empty()) line("mesh_file", toml_string(f.mesh_file));
    else line("shape", shape_text(f.shape));
    if (f.hole_radius > 0.0) {
      line("hole_center", reals_text(f.hole_center));
      line("hole_radius", real_text(f.hole_radius));
    }
    line("size", real_text(f.size));
    line("mesher", toml_string(f.mesher));
    line("velocity", array_text(f.velocity, expression_text));
    if (!f.displacement.empty()) line("displacement", array_text(f.displacement, expression_text));
    if (!f.exact_displacement.empty())
      line("exact_displacement", array_text(f.exact_displacement, expression_text));
  }

  o += "\n[boundary]\n";
  for (int f = 0; f < 2 * s.dimension && f < 6; ++f)
    line(face_names[f], toml_string(face_condition_names[static_cast<int>(c.boundary.face[f])]));
  line("acceleration", toml_string(c.boundary.acceleration == BoundaryAcceleration::zero ? "zero"
                                                                                  : "velocity_change"));

  if (!c.fem.enabled) {
    o += "\n[thermal]\n";
    line("conduction", boolean(c.thermal.conduction));
    for (int f = 0; f < 2 * s.dimension && f < 6; ++f) {
      const ThermalFace tf = c.thermal.face[f];
      line(face_names[f], toml_string(tf == ThermalFace::temperature ? "temperature"
                                      : tf == ThermalFace::flux      ? "flux"
                                                                     : "adiabatic"));
      line(std::string(face_names[f]) + "_value", real_text(c.thermal.value[f]));
    }
  }

  if (!c.body_force.expression.empty()) {
    o += "\n[body_force]\n";
    line("expression", array_text(c.body_force.expression, expression_text));
  }

  auto table_text = [](const TimeTable& table) {
    std::string t = "[";
    for (std::size_t k = 0; k < table.size(); ++k)
      t += fmt::format("{}[{}, {}]", k ? ", " : "", real_text(table[k].first), real_text(table[k].second));
    return t + "]";
  };
  for (const auto& t : c.tractions) {
    o += "\n[[traction]]\n";
    line("name", toml_string(t.name));
    line("body", toml_string(t.body));
    if (t.side >= 0) line("side", toml_string(face_names[t.side]));
    if (!t.box_min.empty()) {
      line("box_min", reals_text(t.box_min));
      line("box_max", reals_text(t.box_max));
    }
    line("traction", reals_text(t.traction));
    line("scale", expression_text(t.scale));
    if (!t.table.empty()) line("table", table_text(t.table));
  }
  for (const auto& v : c.velocity_conditions) {
    o += "\n[[velocity]]\n";
    line("name", toml_string(v.name));
    if (v.face >= 0) line("face", toml_string(face_names[v.face]));
    if (!v.box_min.empty()) {
      line("box_min", reals_text(v.box_min));
      line("box_max", reals_text(v.box_max));
    }
    if (v.plane_axis >= 0) {
      line("plane_axis", toml_string(std::string(1, "xyz"[v.plane_axis])));
      line("plane_at", real_text(v.plane_at));
    }
    line("direction", reals_text(v.direction));
    line("velocity", expression_text(v.velocity));
    if (!v.table.empty()) line("table", table_text(v.table));
  }
  for (const auto& w : c.walls) {
    o += "\n[[wall]]\n";
    line("name", toml_string(w.name));
    line("axis", toml_string(std::string(1, "xyz"[w.axis])));
    line("inside", toml_string(w.inside_below ? "below" : "above"));
    line("position", real_text(w.position));
    line("velocity", expression_text(w.velocity));
    if (!w.table.empty()) line("table", table_text(w.table));
    line("gradient", w.gradient == WallGradient::zero       ? toml_string("zero")
                     : w.gradient == WallGradient::estimate ? toml_string("estimate")
                                                            : expression_text(w.gradient_expression));
    line("depth", real_text(w.depth));
  }

  const auto& out = c.output;
  if (!c.fem.enabled) {
    const ContactConfig& ct = c.contact;
    auto law_lines = [&](const ContactLawConfig& law) {
      line("law", toml_string(law.law));
      line("friction", real_text(law.friction));
      line("dynamic_friction", real_text(law.dynamic_friction));
      line("slide", expression_text(law.slide));
    };
    o += "\n[contact]\n";
    line("mode", toml_string(ct.mode));
    law_lines(ct.law);
    line("normal", toml_string(ct.normal));
    if (!ct.normal_direction.empty()) line("normal_direction", reals_text(ct.normal_direction));
    line("lr_weights", toml_string(ct.lr_weights));
    line("lr_refine", toml_string(ct.lr_refine));
    line("first_correction", toml_string(ct.first_correction));
    line("detection", toml_string(ct.detection));
    line("critical_separation", real_text(ct.critical_separation));
    line("touching_tolerance", real_text(ct.touching_tolerance));
    line("lr_separation", toml_string(ct.lr_separation));
    line("corrections", toml_string(ct.corrections));
    line("three_or_more", toml_string(ct.three_or_more));
    line("xpic_correction", boolean(ct.xpic_correction));
    for (const auto& pc : ct.pairs) {
      o += "\n[[contact_pair]]\n";
      line("first", toml_string(pc.first));
      line("second", toml_string(pc.second));
      law_lines(pc.law);
    }
  }

  o += "\n[output]\n";
  line("directory", toml_string(out.directory));
  line("every", real_text(out.every));
  line("history_every", real_text(out.history_every));
  line("checkpoint_every", real_text(out.checkpoint_every));
  line("snapshots", boolean(out.snapshots));
  line("grid_snapshots", boolean(out.grid_snapshots));
  line("checkpoints", boolean(out.checkpoints));
  if (!out.exact_displacement.empty())
    line("exact_displacement", array_text(out.exact_displacement, expression_text));
  line("checkpoint_wall_interval", real_text(out.checkpoint_wall_interval));
  line("compression", fmt::format("{}", out.compression));
  line("existing", toml_string(out.existing));
  return o;
}

Config load_config_string(const std::string& toml_text, const std::string& name,
                          const std::vector<std::string>& overrides) {
  const std::string file = name.empty() ? std::string("<input>") : name;
  toml::table root;
  try {
    root = toml::parse(toml_text, file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, static_cast<int>(e.source().begin.line), "", "valid TOML",
                     std::string(e.description()));
  }
  Loader loader(file);
  Config cfg = loader.load(root, overrides);
  cfg.source_file = name;
  return cfg;
}

Config load_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "", "a readable input file", std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  Config cfg = load_config_string(text.str(), path, overrides);
  // A relative output folder from the file (or the default out/<stem>) lies next to the input
  // file; one given with --set is relative to the working directory, as typed.
  bool from_command_line = false;
  for (const auto& o : overrides)
    from_command_line = from_command_line || trim(o.substr(0, o.find('='))) == "output.directory";
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!from_command_line && !folder.empty() && std::filesystem::path(cfg.output.directory).is_relative()) {
    cfg.output.directory = (folder / cfg.output.directory).lexically_normal().string();
    cfg.resolved_toml = config_to_toml(cfg);
  }
  return cfg;
}

}  // namespace cairn
