// Loader: loads, conditions and couplings: [boundary], [thermal], [body_force], [[traction]],
// [[velocity]], [[wall]], [fem], [output], [contact].
#include "cairn/input/loader.hpp"

namespace cairn::input_detail {

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

void Loader::read_parallel(const toml::table& root, Config& cfg) {
  TableReader r(*this, section(root, "parallel"), {"parallel"}, copy_section("parallel"), "[parallel]");
  r.reject_unknown_keys();
  cfg.parallel.halo = r.string("halo");
  cfg.parallel.balance = r.string("balance");
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
  auto read_law = [&](TableReader& lr, const std::string& section) {
    ContactLawConfig law;
    law.law = lr.string("law");
    read_plugin_keys(lr, section, law.plugin, cfg);
    return law;
  };
  c.law = read_law(r, "contact");
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
  c.release = r.string("release");
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
    pc.law = read_law(pr, "contact_pair");
    pc.where = {file_, line_of(e)};
    c.pairs.push_back(std::move(pc));
  }
}


}  // namespace cairn::input_detail
