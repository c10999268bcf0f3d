// The documentation of the keys: docs/input.md (markdown) and `cairn keys` (plain text), both
// generated from the declarations.
#include "cairn/input/schema_detail.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "cairn/config/units.hpp"
#include "cairn/geometry/shape_keys.hpp"
#include "cairn/materials/material.hpp"

namespace cairn::schema_detail {


// ---- documentation text ------------------------------------------------------------------

struct SectionDoc {
  std::string name;     ///< "simulation"
  std::string heading;  ///< "[simulation]" or "[[material]]"
  std::string intro;
  std::string example;
};

const std::vector<SectionDoc>& section_docs() {
  static const std::vector<SectionDoc> docs{
      {"simulation", "[simulation]",
       "What is simulated and for how long: dimension, kinematic mode, end time and time-step "
       "control. Required.",
       "[simulation]\n"
       "title = \"two blocks\"\n"
       "dimension = 2\n"
       "mode = \"plane_strain\"\n"
       "end_time = 2.0e-3\n"
       "cfl = 0.5\n"},
      {"grid", "[grid]",
       "The regular background grid. Every array has D entries. Required.",
       "[grid]\n"
       "origin = [0.0, 0.0]\n"
       "extent = [0.12, 0.04]\n"
       "cell_size = 1.0e-3   # or [1.0e-3, 1.0e-3]\n"},
      {"parallel", "[parallel]",
       "How a run on several MPI ranks shares its grid (docs/parallel.md). Ignored on one rank.",
       "[parallel]\n"
       "halo = \"nodes\"\n"},
      {"method", "[method]",
       "The numerical method: shape functions, particle update and stress-update timing. The "
       "choices are the names registered in this build.",
       "[method]\n"
       "shape = \"bspline2\"\n"
       "update = \"fmpm\"\n"
       "order = 4\n"
       "stress_update = \"usl\"\n"},
      {"constants", "[constants]",
       "A free table of named numbers usable in every expression (body velocity, displacement, "
       "body force, tractions, velocity conditions, walls). Names must be identifiers other than "
       "x, y, z, X, Y, Z, t, _pi and _e.",
       "[constants]\n"
       "A = 0.05\n"
       "omega = 1.2e3\n"},
      {"material", "[[material]]",
       "One table per material. Besides name, model and density, each model has keys of its own, "
       "listed below; a model may also require a particular combination of them (e.g. exactly two "
       "elastic constants).",
       "[[material]]\n"
       "name = \"rubber\"\n"
       "model = \"neo_hookean\"\n"
       "density = 1500.0\n"
       "# ... the model's own keys\n"},
      {"body", "[[body]]",
       "One table per body: a region of the grid filled with particles of one material. At "
       "least one is required.",
       "[[body]]\n"
       "name = \"left\"\n"
       "material = \"rubber\"\n"
       "shape = { box = { min = [0.01, 0.01], max = [0.06, 0.03] } }\n"
       "particles_per_cell = 2\n"
       "velocity = [8.165, 0.0]\n"
       "\n"
       "[[body]]\n"
       "material = \"rubber\"\n"
       "shape = { circle = { center = [0.09, 0.02], radius = 0.01 } }\n"
       "displacement = [\"A*sin(2*_pi*X)\", \"0\"]\n"},
      {"boundary", "[boundary]",
       "Conditions on the faces of the grid. A periodic axis needs periodic on both of its faces; "
       "y_* and z_* keys exist only in 2D and 3D, z_* only in 3D. fixed holds every velocity "
       "component at zero on the face nodes and the ghost nodes beyond; symmetry holds the normal "
       "component on the face and mirrors ghost nodes (normal component negated); with the "
       "open-knot families (bspline2_open, bspline3_open) only the face value, whose basis "
       "function is the only one non-zero on the face, is held. See docs/shape-functions.md.",
       "[boundary]\n"
       "x_min = \"fixed\"\n"
       "x_max = \"free\"\n"
       "y_min = \"symmetry\"\n"},
      {"thermal", "[thermal]",
       "Heat conduction on the grid and thermal conditions on the grid faces (docs/thermal.md). "
       "Materials give conductivity and heat_capacity.",
       "[thermal]\n"
       "conduction = true\n"
       "x_min = \"temperature\"\n"
       "x_min_value = 400.0\n"},
      {"body_force", "[body_force]",
       "A body force per unit mass (e.g. gravity), applied to every particle.",
       "[body_force]\n"
       "expression = [0.0, \"-9.81\"]\n"},
      {"traction", "[[traction]]",
       "A traction on the exposed faces of a body's particles, added to the grid forces (seed 000 "
       "Sec. 2.4): T(t) = traction * scale(t) * table(t), spread with the grid functions over each "
       "face; the face area follows the deformation with cpdi, b2cpdi and cpgimp (and under "
       "method.integration = \"wls\", which spreads the force over its cut-cell surface, "
       "docs/wls.md). Faces are selected by side, by box or both. See docs/boundary-conditions.md.",
       "[[traction]]\n"
       "body = \"bar\"\n"
       "side = \"x_min\"\n"
       "traction = [-500.0, 0.0]\n"
       "scale = \"tri(t, 1e-3)\"\n"},
      {"velocity", "[[velocity]]",
       "A prescribed grid velocity component on a node set: the intersection of the selectors "
       "given (face, box, plane). Imposed with the [boundary] faces in every scheme, including the "
       "velocity, lumped, combined and constrained full-mass methods (seed 000 Eq. 3); its reaction force is in "
       "history.csv. See docs/boundary-conditions.md.",
       "[[velocity]]\n"
       "name = \"grip\"\n"
       "face = \"x_max\"\n"
       "direction = [1.0, 0.0]\n"
       "velocity = \"0.01*ramp(t, 1e-3)\"\n"},
      {"wall", "[[wall]]",
       "A moving wall normal to an axis (seed 000 Sec. 2.5): it sets v = v_b + grad v_b (x - "
       "x_wall) along its axis on the nodes inside the material within depth d and on the nodes "
       "outside it that carry mass. Its position and reaction force are in history.csv. See "
       "docs/boundary-conditions.md.",
       "[[wall]]\n"
       "name = \"right\"\n"
       "axis = \"x\"\n"
       "inside = \"below\"\n"
       "position = 10.0\n"
       "velocity = 0.025\n"
       "gradient = \"estimate\"\n"
       "depth = 1.5\n"},
      {"contact", "[contact]",
       "Multimaterial contact (seed 004; docs/contact.md): one velocity field per material or "
       "body, contact corrections twice per step, the contact law of each pair, normals and "
       "detection. History gets contact_nodes, contact_active and the force on each field pair.",
       "[contact]\n"
       "mode = \"material\"\n"
       "law = \"coulomb\"\n"
       "friction = 0.2\n"
       "normal = \"lr\"\n"
       "detection = \"lr\"\n"},
      {"contact_pair", "[[contact_pair]]",
       "The contact law of one pair of fields, overriding the [contact] default.",
       "[[contact_pair]]\n"
       "first = \"steel\"\n"
       "second = \"rock\"\n"
       "law = \"perfect\"\n"},
      {"fem", "[fem]",
       "The reference explicit FEM of seed 001 Appendix A on linear triangles (docs/fem.md). With "
       "[fem] the run has no grid and no particles: no [grid], [[body]], [[traction]], [[wall]], "
       "[contact] or [thermal]. [boundary] faces apply to the nodes on the faces of the mesh's "
       "bounding box, [[velocity]] selects nodes by face, box or plane, [body_force] acts on the "
       "nodes (expressions of X, Y, x, y, t).",
       "[fem]\n"
       "material = \"steel\"\n"
       "shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\n"
       "hole_center = [0.0, 0.0]\n"
       "hole_radius = 0.5\n"
       "size = 0.02\n"},
      {"output", "[output]",
       "What is written, where and how often.",
       "[output]\n"
       "directory = \"out/two_blocks\"\n"
       "every = 1.0e-4\n"
       "grid_snapshots = false\n"},
  };
  return docs;
}

std::string md_cell(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|' || c == '<') out += '\\';  // table separator; '<' would start an HTML tag
    out += c;
  }
  return out;
}

std::string md_code(const std::string& s) { return s.empty() ? "" : "`" + s + "`"; }

/// Range or choices for markdown: choices each in backticks.
std::string md_range(const KeyDecl& d) {
  if (d.type == KeyType::string && d.choices) {
    std::vector<std::string> c = d.choices();
    for (auto& s : c) s = "`" + s + "`";
    return join(c, ", ");
  }
  return md_cell(range_text(d));
}

/// Default cell: TOML defaults as code, "required" / "none" / computed defaults as text.
std::string md_default(const KeyDecl& d) {
  if (d.required || d.default_value.empty()) return md_cell(default_text(d));
  return md_code(d.default_value);
}

void md_header(std::string& out) {
  out += "| key | type | default | range / choices | doc |\n";
  out += "|---|---|---|---|---|\n";
}

/// Rows of a key table; `prefix` is prepended to the key names ("circle." for shape parameters).
void md_rows(std::string& out, const std::vector<KeyDecl>& keys, const std::string& prefix = "") {
  for (const auto& d : keys)
    out += fmt::format("| `{}{}` | {} | {} | {} | {} |\n", prefix, d.name, md_cell(type_text(d)),
                       md_default(d), md_range(d), md_cell(d.doc));
}

void md_table(std::string& out, const std::vector<KeyDecl>& keys) {
  md_header(out);
  md_rows(out, keys);
}

std::vector<KeyDecl> copy_section(std::string_view section) {
  std::vector<KeyDecl> out;
  for (const auto* d : section_keys(section)) out.push_back(*d);
  return out;
}

/// The source papers that docs cite as "seed 00N" (README.md, "seed" table), for the headers of
/// `cairn keys` and docs/input.md.
constexpr const char* seeds_cited =
    "Docs cite the five source papers as \"seed 00N\" (README.md lists them): seed 000 = Nairn and "
    "Hammerquist, full mass matrix MPM (FMPM, XPIC, boundary conditions); seed 001 = Wallstedt and "
    "Guilkey, weighted least squares PIC (WLS); seed 002 = Nairn, notes on MPM extrapolations "
    "(particle updates); seed 003 = Steffen, Wallstedt, Guilkey, Kirby and Berzins, MPM "
    "implementation choices (shape functions, time integration); seed 004 = Nairn, Hammerquist and "
    "Smith, MPM contact algorithms.";

std::string markdown_text() {
  std::string out;
  out +=
      "# Cairn input reference\n"
      "\n"
      "<!-- Generated from src/cairn/input/schema.cpp by `cairn keys --markdown > docs/input.md`; "
      "do not edit by hand. -->\n"
      "\n"
      "A Cairn input file is [TOML](https://toml.io). Every key is declared once, with its type, "
      "default, allowed range or choices and a one-line doc; this page is generated from those "
      "declarations. Unknown keys, misspelled sections, values of the wrong type or out of "
      "range are errors that name the file, the line and the key, what was expected and what "
      "was found; every independent error of a file is reported in one run (up to 20), and a "
      "key written in the wrong section says which section declares it.\n"
      "\n";
  out += seeds_cited;
  out +=
      "\n"
      "\n"
      "- `D` is `simulation.dimension`; `real[D]` is an array with one number per axis.\n"
      "- Integers are accepted wherever a real is expected.\n"
      "- `expr[D]` entries are numbers or expression strings such as `\"A*sin(2*_pi*X)\"`; "
      "they may use the names of `[constants]`. An empty string is an error. Each is checked "
      "when the input is read: one expression (a `,` outside a function's arguments, as in "
      "`\"-9,81\"`, is an error), no assignment (`=`, `+=`, ...), only the variables its key "
      "allows: initial values (`[[body]]` velocity and displacement) the positions `x y z X Y Z` "
      "up to the dimension but not `t`; time functions (traction scale, `[[velocity]]` and "
      "`[[wall]]` velocity and gradient) only `t`; the body force both.\n"
      "- A number beyond 1e30 in magnitude (or nonzero below 1e-30) is accepted with a warning: "
      "no unit system needs it, and energies or stresses may overflow.\n"
      "- Before anything is allocated, the grid's node count is checked against the 32-bit node "
      "index (at most 1e9 cells per axis), and the memory of grid, particles and transfer caches "
      "is estimated against `simulation.memory_limit`; a run whose `end_time` / first time step "
      "exceeds `simulation.max_estimated_steps` is refused naming what sets the step. A body must "
      "lie inside the grid (`clip = true` keeps the part inside) and may not share space with "
      "another (`simulation.body_overlap`). docs/robustness.md lists every guard.\n"
      "- Any key can be overridden on the command line: `cairn run case.toml --set "
      "method.order=4 --set material[0].density=1100`. The value is read as a TOML value "
      "(`--set grid.origin=[0,0]`), or as a plain string when it is not one "
      "(`--set method.update=fmpm`). Entries of `[[material]]` and `[[body]]` are addressed by "
      "their index from 0: `material.0.density` or `material[0].density`.\n"
      "- `cairn check case.toml` validates an input and prints it with every default filled "
      "in.\n"
      "- Exit codes of `cairn`: 0 success; 2 bad input (this page's errors, a bad command line, "
      "a damaged or edited checkpoint); 3 the simulation failed; 1 any other error (a full disk "
      "says \"no space left on device\").\n"
      "\n"
      "Sections: ";
  std::vector<std::string> links;
  for (const auto& s : section_docs()) links.push_back(fmt::format("[`{}`](#{})", s.heading, s.name));
  out += join(links, " · ") + "\n";

  for (const auto& s : section_docs()) {
    out += fmt::format("\n## {}\n\n{}\n\n", s.heading, s.intro);
    if (s.name == "constants") {
      md_header(out);
      out += "| *any identifier* | real | none |  | A named number for expressions. |\n";
    } else {
      md_table(out, copy_section(s.name));
    }
    out += fmt::format("\n```toml\n{}```\n", s.example);

    if (s.name == "material") {
      for (const auto& model : material_model_names()) {
        out += fmt::format("\n### model `{}`\n\n", model);
        auto it = material_model_info().find(model);
        if (it == material_model_info().end() || it->second.keys.empty()) {
          if (it != material_model_info().end() && !it->second.doc.empty())
            out += it->second.doc + "\n\n";
          out += "No keys of its own.\n";
          continue;
        }
        if (!it->second.doc.empty()) out += it->second.doc + "\n\n";
        md_table(out, it->second.keys);
      }
    }
    if (s.name == "body") {
      out +=
          "\n### shape kinds\n\n"
          "`shape` holds exactly one of these kinds, each an inline table of its parameters "
          "(required unless a default is shown).\n\n"
          "| kind | dimensions | doc |\n|---|---|---|\n";
      for (const auto& kind : body_shape_kinds()) {
        std::vector<std::string> dims;
        for (int d = 0; d < 3; ++d)
          if (kind.valid_in[d]) dims.push_back(fmt::format("{}D", d + 1));
        out += fmt::format("| `{}` | {} | {} |\n", kind.name, join(dims, ", "), md_cell(kind.doc));
      }
      out += "\n";
      md_header(out);
      for (const auto& kind : body_shape_kinds())
        md_rows(out, copy_section("body.shape." + kind.name), kind.name + ".");
      out +=
          "\nAn `image` body is drawn as a picture (seed 004 Sec. 4.2): a particle position X "
          "belongs to it when the pixel under X has a grey level in `levels`. Pixel (col, row) of "
          "a W x H picture covers x in [x0 + col s, x0 + (col + 1) s), y in [y0 + (H - 1 - row) s, "
          "y0 + (H - row) s), with s = pixel_size and [x0, y0] = origin: row 0, the first row of "
          "the file, is the top of the picture, at the highest y. Positions outside the picture "
          "are outside the body, and a position on a pixel edge (to 1e-6 pixel) belongs to the pixel "
          "on its +x / +y side. A picture whose shades mark several materials becomes one "
          "[[body]] per shade (or range of shades), each with its own material:\n\n"
          "```toml\n"
          "[[body]]\n"
          "material = \"grain1\"\n"
          "shape = { image = { file = \"ellipses.png\", pixel_size = 3.5714e-6, levels = [10, 10] } }\n"
          "\n"
          "[[body]]\n"
          "material = \"grain2\"\n"
          "shape = { image = { file = \"ellipses.png\", pixel_size = 3.5714e-6, levels = [20, 20] } }\n"
          "```\n\n"
          "The picture is read once per file when the input is loaded (a missing or unreadable "
          "file is an input error at the `file` key); the resolved input (`cairn check`, "
          "checkpoints) names it by its absolute path, so a restart needs the file still there.\n"
          "\nAn `image_stack` body (3D) is the same drawn by a stack of slices (a CT scan): the PNG files "
          "of `folder` whose names match `pattern`, slice 0 the one with the lowest number in its name, at "
          "the lowest z; slice k covers z in [z0 + k slice_spacing, z0 + (k + 1) slice_spacing) and its "
          "pixels x and y as in a picture. A missing slice (a gap in the numbers), slices of different "
          "sizes or a folder without a matching file is an input error at `folder` naming the file "
          "(docs/geometry.md):\n\n"
          "```toml\n"
          "[[body]]\n"
          "material = \"bone\"\n"
          "shape = { image_stack = { folder = \"ct\", pattern = \"slice_*.png\", pixel_size = 1.0e-4, "
          "slice_spacing = 2.0e-4, levels = [180, 255] } }\n"
          "```\n"
          "\nA `mesh` body (3D) is the inside of a closed triangle surface read from a file, placed by "
          "x = R (scale x_file) + translate; the file is checked when the input is loaded (an open, "
          "non-manifold, self-intersecting or degenerate surface is an input error at `file`, an "
          "inward or inconsistent orientation is turned with a warning). Formats, the inside test, "
          "limits and recipes from CAD tools are in docs/geometry.md:\n\n"
          "```toml\n"
          "[[body]]\n"
          "material = \"steel\"\n"
          "shape = { mesh = { file = \"part.stl\", units = \"mm\", rotate = [90.0, 0.0, 0.0], "
          "translate = [0.1, 0.0, 0.05] } }\n"
          "```\n\n"
          "A `volume_mesh` body takes the 3-node triangles (2D) or 4-node tetrahedra (3D) of a Gmsh "
          "mesh (a `.geo` outline, holes and all, is meshed when read): one particle per element or per "
          "Gauss point, with its share of the element's area/volume, so the mass is density x mesh "
          "volume exactly. A `points` body takes one particle per row of a CSV file (x, y, z, volume, "
          "optional velocity and temperature).\n";
    }
  }
  return out;
}

/// One aligned block of rows (columns separated by two spaces, the last column not padded).
/// Width of `cairn keys` (a 100-column terminal).
constexpr std::size_t plain_width = 100;

/// Word-wrap `text` into lines of at most `width` characters (a longer word is cut).
std::vector<std::string> wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t space = text.find(' ', pos);
    std::string word = text.substr(pos, space == std::string::npos ? std::string::npos : space - pos);
    pos = space == std::string::npos ? text.size() : space + 1;
    if (word.empty()) continue;
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    while (word.size() > width) {
      if (!line.empty()) lines.push_back(line);
      lines.push_back(word.substr(0, width));
      word.erase(0, width);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty() || lines.empty()) lines.push_back(line);
  return lines;
}

/// A table indented by 2 with 2 spaces between columns, at most plain_width wide: the columns
/// before the last keep their natural width while the last (the doc) has at least 36; then the
/// widest of them but the first (the key names) gives way; every cell wraps within its column.
void plain_rows(std::string& out, const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows)
    for (std::size_t c = 0; c < r.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], r[c].size());
    }
  if (width.empty()) return;
  const std::size_t last = width.size() - 1;
  auto used = [&] {
    std::size_t u = 2;
    for (std::size_t c = 0; c < last; ++c) u += width[c] + 2;
    return u;
  };
  // The first column (key names) stays whole, no column gets narrower than its heading or 16.
  while (used() + 36 > plain_width) {
    std::size_t widest = 0;
    for (std::size_t c = 1; c < last; ++c)
      if (width[c] > std::max<std::size_t>(16, rows[0][c].size()) && (widest == 0 || width[c] > width[widest]))
        widest = c;
    if (widest == 0) break;
    --width[widest];
  }
  width[last] = plain_width > used() ? std::max<std::size_t>(plain_width - used(), 20) : 20;
  for (const auto& r : rows) {
    std::vector<std::vector<std::string>> cells;
    std::size_t height = 1;
    for (std::size_t c = 0; c < r.size(); ++c) {
      cells.push_back(wrap(r[c], width[c]));
      height = std::max(height, cells.back().size());
    }
    for (std::size_t k = 0; k < height; ++k) {
      std::string line = "  ";
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const std::string cell = k < cells[c].size() ? cells[c][k] : "";
        line += c + 1 < cells.size() ? fmt::format("{:<{}}  ", cell, width[c]) : cell;
      }
      while (!line.empty() && line.back() == ' ') line.pop_back();
      out += line + "\n";
    }
  }
}

std::vector<std::vector<std::string>> plain_table(const std::vector<KeyDecl>& keys) {
  std::vector<std::vector<std::string>> rows{{"key", "type", "default", "range/choices", "doc"}};
  for (const auto& d : keys)
    rows.push_back({d.name, type_text(d), default_text(d), range_text(d), d.doc});
  return rows;
}

std::string plain_text() {
  std::string out =
      "Cairn input keys; D = simulation.dimension. `cairn keys --markdown` gives the full "
      "reference.\n"
      "Override any key with --set section.key=value; [[material]] and [[body]] entries by\n"
      "index: --set material.0.density=1100\n";
  for (const auto& line : wrap(seeds_cited, plain_width))
    out += line + "\n";
  for (const auto& s : section_docs()) {
    out += fmt::format("\n{}\n", s.heading);
    if (s.name == "constants") {
      plain_rows(out, {{"key", "type", "doc"}, {"<identifier>", "real", "A named number for expressions."}});
      continue;
    }
    plain_rows(out, plain_table(copy_section(s.name)));
    if (s.name == "material") {
      for (const auto& model : material_model_names()) {
        out += fmt::format("\n[[material]] model = \"{}\"\n", model);
        auto it = material_model_info().find(model);
        if (it == material_model_info().end() || it->second.keys.empty()) {
          out += "  (no keys of its own)\n";
          continue;
        }
        plain_rows(out, plain_table(it->second.keys));
      }
    }
    if (s.name == "body") {
      for (const auto& kind : body_shape_kinds()) {
        out += "\n";
        for (const auto& line : wrap(fmt::format("[[body]] shape = {{ {} = {{ ... }} }}: {}", kind.name, kind.doc), plain_width))
          out += line + "\n";
        plain_rows(out, plain_table(copy_section("body.shape." + kind.name)));
      }
    }
  }
  return out;
}

}  // namespace cairn::schema_detail
