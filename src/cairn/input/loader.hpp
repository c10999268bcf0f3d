// The input validator's machinery, shared by the files of input/ (not for other folders): a key's
// path, the TOML text helpers, TableReader (one table against its declared keys) and Loader
// (overrides, sections, the Config).
#pragma once

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
#include "cairn/geometry/image.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/input/schema_detail.hpp"
#include "cairn/config/plugin_keys.hpp"
#include "cairn/config/units.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/input/input.hpp"
#include "cairn/wls/arrangement.hpp"

namespace cairn::input_detail {


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
  declared,  ///< the variables of the key's declaration (KeyDecl::variables, e.g. a contact law's)
  unchecked, ///< read as text: the caller checks it (a wall gradient may be a word)
};

inline Path child(Path p, std::string part) {
  p.push_back(std::move(part));
  return p;
}
inline Path child(Path p, std::size_t index) { return child(std::move(p), std::to_string(index)); }

inline bool is_index(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

inline bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

/// Dotted key as users see it: {"material", "0", "density"} -> "material[0].density".
inline std::string display(const Path& p) {
  std::string out;
  for (const auto& part : p) {
    if (is_index(part) && !out.empty()) out += "[" + part + "]";
    else out += (out.empty() ? "" : ".") + part;
  }
  return out;
}

using schema_detail::join;

inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

inline std::size_t edit_distance(const std::string& a, const std::string& b) {
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
inline std::optional<std::string> closest(const std::string& name, const std::vector<std::string>& candidates) {
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

inline std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates) {
  auto c = closest(name, candidates);
  return c ? fmt::format(" (did you mean '{}'?)", *c) : "";
}

// ---- TOML text ---------------------------------------------------------------------------

inline std::string toml_string(const std::string& s) {
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

inline std::string toml_key(const std::string& k) {
  const bool bare = !k.empty() && std::all_of(k.begin(), k.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
  return bare ? k : toml_string(k);
}

/// Shortest text that reads back as the same double, always with a '.' or exponent so that
/// TOML reads it as a real.

/// Full-precision text of a number stored in an expression (Config keeps expressions as text).
inline std::string expression_number(double v) { return fmt::format("{:.17g}", v); }

inline std::string node_text(const toml::node& node) {
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

inline std::string type_name(const toml::node& node) {
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
inline std::string typed_text(const toml::node& node) {
  return fmt::format("{} ({})", node_text(node), type_name(node));
}

inline int line_of(const toml::node* node) {
  return node ? static_cast<int>(node->source().begin.line) : 0;
}

/// Entries of a table sorted by their position in the file (toml++ keeps them sorted by key).
inline std::vector<std::pair<std::string, const toml::node*>> entries_in_file_order(const toml::table& t) {
  std::vector<std::pair<std::string, const toml::node*>> out;
  for (auto&& [k, v] : t) out.emplace_back(std::string(k.str()), &v);
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    const auto& sa = a.second->source().begin;
    const auto& sb = b.second->source().begin;
    return sa.line != sb.line ? sa.line < sb.line : sa.column < sb.column;
  });
  return out;
}

inline std::string mode_name(Mode m) {
  switch (m) {
    case Mode::uniaxial_strain_1d: return "uniaxial";
    case Mode::plane_strain: return "plane_strain";
    case Mode::plane_stress: return "plane_stress";
    case Mode::three_d: return "3d";
  }
  return "?";
}

inline const char* const face_names[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};

/// The sections written as arrays of tables ([[material]], ...), addressed by index in --set.
inline bool is_table_array(const std::string& section) {
  return section == "material" || section == "body" || section == "traction" ||
         section == "velocity" || section == "wall" || section == "contact_pair";
}
inline const char* const face_condition_names[4] = {"free", "fixed", "symmetry", "periodic"};

/// " (one per axis, dimension 2)" when n is the dimension.
inline std::string per_axis(std::size_t n, int dim) {
  return n == static_cast<std::size_t>(dim) ? fmt::format(" (one per axis, dimension {})", dim) : "";
}

inline std::vector<KeyDecl> copy_section(std::string_view section) {
  std::vector<KeyDecl> out;
  for (const auto* d : section_keys(section)) out.push_back(*d);
  return out;
}

/// Where else a key named `key` is declared, as a hint for one found in the table at `path`:
/// " ('cfl' is a key of [simulation]: did you mean simulation.cfl?)", or "" when nowhere else.
inline std::string declared_elsewhere(const Path& path, const std::string& key) {
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
inline std::string undeclared_key_expected(const Path& path, const std::string& key, const std::vector<KeyDecl>& decls,
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
  /// The same for an expression in exactly `variables` (and [constants]).
  void check_expression_in(const Path& path, const toml::node* node, const std::string& text,
                           const std::vector<std::string>& variables) const;
  /// The keys that plug-ins declare for `section` (config/plugin_keys.hpp) into `values`, then
  /// the checks of those plug-ins against `cfg` (which holds the sections read so far).
  void read_plugin_keys(TableReader& r, const std::string& section, PluginValues& values, const Config& cfg);

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
  /// shape = { image = {...} } (2D) or { image_stack = {...} } (3D): the placement, the levels and
  /// the picture or slices (geometry/image.hpp), read once per file (folder and pattern).
  void read_image_shape(TableReader& r, BodyShapeConfig& s, const std::vector<BodyConfig>& earlier);
  /// The `key` (`file`, `folder`) of a shape read from a file: non-empty, resolved against the
  /// input's folder.
  std::string file_key(TableReader& r, const std::string& key = "file") {
    const std::string file = r.string(key);
    if (file.empty()) r.fail(key, r.given(key), "a non-empty " + key + " name", "\"\"");
    return resolve_input_relative(file, file_);
  }
  /// What `read` returns, its std::invalid_argument an input error at `key` (the `file` key).
  template <class Read>
  auto read_file_key(TableReader& r, const std::string& expected, Read&& read, const std::string& key = "file")
      -> decltype(read()) {
    try {
      return read();
    } catch (const std::invalid_argument& e) {
      r.fail(key, r.given(key), expected + ", relative to the input file's directory", e.what());
    }
  }
  void read_boundary(const toml::table& root, Config& cfg);
  void read_body_force(const toml::table& root, Config& cfg);
  void read_thermal(const toml::table& root, Config& cfg);
  void read_parallel(const toml::table& root, Config& cfg);
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

}  // namespace cairn::input_detail
