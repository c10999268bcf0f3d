// config_to_toml: a Config as the TOML text that reads back to it (the resolved input stored in
// every output and checkpoint).
#include "cairn/input/loader.hpp"

namespace cairn {
namespace input_detail {
namespace {

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
  else if (s.kind == "image_stack")
    params = fmt::format("folder = {}, pattern = {}, pixel_size = {}, slice_spacing = {}, origin = {}, levels = [{}, {}]",
                         toml_string(s.file), toml_string(s.pattern), real_text(s.pixel_size),
                         real_text(s.slice_spacing), reals_text(s.origin), s.level_min, s.level_max);
  else if (s.kind == "outline")
    params = fmt::format("file = {}, scale = {}, translate = {}, slice_z = {}", toml_string(s.file),
                         real_text(s.scale), reals_text(s.translate), real_text(s.slice_z));
  else if (s.kind == "points")
    params = fmt::format("file = {}", toml_string(s.file));
  else if (s.kind == "mesh" || s.kind == "volume_mesh")
    params = fmt::format("file = {}, {}units = {}, scale = {}, rotate = {}, translate = {}", toml_string(s.file),
                         s.kind == "volume_mesh" ? fmt::format("quadrature = {}, ", s.quadrature) : "",
                         toml_string(s.units), real_text(s.scale), reals_text(s.rotate), reals_text(s.translate));
  return fmt::format("{{ {} = {{ {} }} }}", toml_key(s.kind), params);
}

}  // namespace
}  // namespace input_detail

using namespace input_detail;

std::string config_to_toml(const Config& c) {
  std::string o;
  auto line = [&](const std::string& key, const std::string& value) {
    o += fmt::format("{} = {}\n", toml_key(key), value);
  };
  // The keys plug-ins declare for `section` (config/plugin_keys.hpp), as their types print.
  auto plugin_lines = [&](const std::string& section, const PluginValues& values) {
    for (const KeyDecl* k : section_keys(section)) {
      if (k->owner.empty()) continue;
      switch (k->type) {
        case KeyType::real: line(k->name, real_text(values.real(k->name))); break;
        case KeyType::integer: line(k->name, fmt::format("{}", static_cast<long long>(values.real(k->name)))); break;
        case KeyType::boolean: line(k->name, values.boolean(k->name) ? "true" : "false"); break;
        case KeyType::expression: line(k->name, expression_text(values.text(k->name))); break;
        default: line(k->name, toml_string(values.text(k->name))); break;
      }
    }
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
  line("mpi_timeout", real_text(s.mpi_timeout));
  line("body_overlap", toml_string(s.body_overlap));

  o += "\n[parallel]\n";
  line("halo", toml_string(c.parallel.halo));
  line("balance", toml_string(c.parallel.balance));

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
    line("position_update", toml_string(m.position_update));
    line("grid_damping", real_text(m.grid_damping));
    line("particle_damping", real_text(m.particle_damping));
    line("full_mass_cfl", real_text(m.full_mass_cfl));
    line("velocity_bc_method", toml_string(m.velocity_bc_method));
    line("time_integration", toml_string(m.time_integration));
    line("integration", toml_string(m.integration));
    plugin_lines("method", m.plugin);
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
    if (mat.has("balance_cost")) line("balance_cost", real_text(mat.number("balance_cost")));
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
    auto law_lines = [&](const ContactLawConfig& law, const std::string& section) {
      line("law", toml_string(law.law));
      plugin_lines(section, law.plugin);
    };
    o += "\n[contact]\n";
    line("mode", toml_string(ct.mode));
    law_lines(ct.law, "contact");
    line("normal", toml_string(ct.normal));
    if (!ct.normal_direction.empty()) line("normal_direction", reals_text(ct.normal_direction));
    line("lr_weights", toml_string(ct.lr_weights));
    line("lr_refine", toml_string(ct.lr_refine));
    line("first_correction", toml_string(ct.first_correction));
    line("detection", toml_string(ct.detection));
    line("critical_separation", real_text(ct.critical_separation));
    line("touching_tolerance", real_text(ct.touching_tolerance));
    line("lr_separation", toml_string(ct.lr_separation));
    line("release", toml_string(ct.release));
    line("corrections", toml_string(ct.corrections));
    line("three_or_more", toml_string(ct.three_or_more));
    line("xpic_correction", boolean(ct.xpic_correction));
    for (const auto& pc : ct.pairs) {
      o += "\n[[contact_pair]]\n";
      line("first", toml_string(pc.first));
      line("second", toml_string(pc.second));
      law_lines(pc.law, "contact_pair");
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

}  // namespace cairn
