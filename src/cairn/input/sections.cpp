// Loader: the sections that make the model: [simulation], [grid], [method], [constants],
// [[material]], [[body]] and their shapes.
#include "cairn/input/loader.hpp"

namespace cairn::input_detail {

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
  s.mpi_timeout = r.real("mpi_timeout");
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
  m.position_update = r.string("position_update");
  m.grid_damping = r.real("grid_damping");
  m.particle_damping = r.real("particle_damping");
  m.full_mass_cfl = r.real("full_mass_cfl");
  m.velocity_bc_method = r.string("velocity_bc_method");
  m.time_integration = r.string("time_integration");
  m.integration = r.string("integration");
  read_plugin_keys(r, "method", m.plugin, cfg);
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
    m.numbers["balance_cost"] = r.real("balance_cost");
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
  } else if (kind == "image" || kind == "image_stack") {
    read_image_shape(r, s, earlier);
  } else if (kind == "mesh" || kind == "volume_mesh") {
    read_mesh_shape(r, s, earlier);
  } else if (kind == "outline") {
    s.file = file_key(r);
    s.scale = r.real("scale");
    s.translate = r.reals("translate", 2, false);
    s.slice_z = r.real("slice_z");
    s.loops = read_file_key(r, "a CSV outline: lines \"x, y\", loops separated by blank lines, the first the "
                               "outside and the others holes inside it, no two edges meeting; or a closed surface "
                               "mesh that the plane z = slice_z cuts in closed curves (docs/geometry.md)",
                            [&] { return geometry::read_outline(s.file, s.scale, s.translate, s.slice_z); });
  } else if (kind == "points") {
    s.file = file_key(r);
    s.points = read_file_key(r, "a point file: CSV with a header row x, y(, z), volume[, vx, vy(, vz)][, temperature]"
                                "[, stress columns sxx, ...] and one row per particle, or HDF5 (.h5) with datasets "
                                "position, volume[, velocity][, temperature][, stress] (docs/geometry.md)",
                             [&] { return geometry::read_point_file(s.file, dim_); });
  } else {
    throw std::logic_error("input: shape kind '" + kind + "' declared but not read");
  }
  return s;
}

void Loader::read_image_shape(TableReader& r, BodyShapeConfig& s, const std::vector<BodyConfig>& earlier) {
  const bool stack = s.kind == "image_stack";
  const std::string key = stack ? "folder" : "file";
  s.file = file_key(r, key);
  s.pixel_size = r.real("pixel_size");
  if (stack) {
    s.slice_spacing = r.real("slice_spacing");
    s.pattern = r.string("pattern");
    if (s.pattern.empty()) r.fail("pattern", r.given("pattern"), "a non-empty glob such as \"*.png\"", "\"\"");
  }
  s.origin = r.reals("origin", stack ? 3 : 2, false);
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
    if (other.shape.image && other.shape.kind == s.kind && other.shape.file == s.file &&
        other.shape.pattern == s.pattern)
      s.image = other.shape.image;
  if (s.image) return;
  s.image = read_file_key(
      r,
      stack ? "a folder of PNG slices numbered consecutively, all of one size (docs/geometry.md)"
            : "a readable PNG file",
      [&] {
        return std::make_shared<const GreyImage>(stack ? read_png_stack(s.file, s.pattern) : read_png_grey(s.file));
      },
      key);
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


}  // namespace cairn::input_detail
