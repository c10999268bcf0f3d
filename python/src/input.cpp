// Input for Python: configs from files, TOML text and dicts through the one validator of
// `cairn run` (input/input.hpp), InputError with its attributes, and the declared keys.
#include <pybind11/stl.h>
#include <toml++/toml.h>

#include <sstream>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/util/registry.hpp"

namespace cairn::python {
namespace {

std::unique_ptr<toml::node> to_node(py::handle value, const std::string& where, int depth);

/// A dict as a TOML table. Tables below a section (a body's shape, a condition's value) are
/// written inline, as input files write them.
std::unique_ptr<toml::table> to_table(py::handle dict, const std::string& where, int depth) {
  auto table = std::make_unique<toml::table>();
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(dict)) {
    if (!py::isinstance<py::str>(key))
      throw py::type_error(where + ": keys must be strings, found " + std::string(py::str(key.get_type())));
    const std::string name = key.cast<std::string>();
    if (value.is_none()) continue;  // None: the key is left out (its default applies)
    const std::string path = where.empty() ? name : where + "." + name;
    table->insert(name, std::move(*to_node(value, path, depth + 1)));
  }
  table->is_inline(depth >= 2);
  return table;
}

std::unique_ptr<toml::node> to_node(py::handle value, const std::string& where, int depth) {
  if (py::isinstance<py::bool_>(value)) return std::make_unique<toml::value<bool>>(value.cast<bool>());
  if (py::isinstance<py::dict>(value)) return to_table(value, where, depth);
  if (py::isinstance<py::str>(value)) return std::make_unique<toml::value<std::string>>(value.cast<std::string>());
  if (py::isinstance<py::int_>(value) || (py::hasattr(value, "__index__") && !py::isinstance<py::float_>(value)))
    return std::make_unique<toml::value<std::int64_t>>(value.cast<std::int64_t>());
  if (py::isinstance<py::float_>(value) || py::hasattr(value, "__float__"))
    return std::make_unique<toml::value<double>>(value.cast<double>());
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) || py::hasattr(value, "tolist")) {
    const py::object sequence = py::hasattr(value, "tolist") ? value.attr("tolist")() : py::reinterpret_borrow<py::object>(value);
    const py::list items(sequence);
    auto array = std::make_unique<toml::array>();
    int i = 0;
    for (const auto& item : items) {
      auto node = to_node(item, where + "[" + std::to_string(i++) + "]", depth);
      array->push_back(std::move(*node));
    }
    return array;
  }
  throw py::type_error(where + ": a TOML value (bool, int, float, str, list, dict) expected, found " +
                       std::string(py::str(value.get_type())));
}

/// A config as TOML text: sections as [section] and [[section]] blocks.
std::string dict_to_toml(const py::dict& config) {
  const auto table = to_table(config, "", 0);
  std::ostringstream out;
  out << toml::toml_formatter{*table};
  return out.str() + "\n";
}

/// `section.key=value` for load_config's overrides, the value written as TOML.
std::vector<std::string> overrides_of(const py::object& set) {
  std::vector<std::string> out;
  if (set.is_none()) return out;
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(set)) {
    const std::string name = py::str(key);
    toml::table holder;
    holder.insert("v", std::move(*to_node(value, name, 2)));
    std::ostringstream text;
    text << toml::toml_formatter{holder};
    std::string v = text.str();  // "v = <value>"
    v = v.substr(v.find('=') + 1);
    v.erase(0, v.find_first_not_of(' '));
    while (!v.empty() && (v.back() == '\n' || v.back() == ' ')) v.pop_back();
    out.push_back(name + "=" + v);
  }
  return out;
}

/// cairn.InputError (python/cairn/_errors.py) carrying the C++ error's fields.
py::object python_input_error(const InputError& e) {
  const py::object cls = py::module_::import("cairn._errors").attr("InputError");
  return cls(e.what(), e.file(), e.line(), e.key(), e.expected(), e.found());
}

py::dict key_entry(const KeyDecl& k) {
  py::dict d;
  d["section"] = k.section;
  d["name"] = k.name;
  d["type"] = type_text(k);
  d["default"] = default_text(k);
  d["range"] = range_text(k);
  d["required"] = k.required;
  d["doc"] = k.doc;
  return d;
}

}  // namespace

void bind_input(py::module_& m) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputErrors& e) {
      py::object error = python_input_error(e);
      py::list all;
      for (const auto& one : e.errors()) all.append(python_input_error(one));
      error.attr("errors") = all;
      PyErr_SetObject(error.get_type().ptr(), error.ptr());
    } catch (const InputError& e) {
      py::object error = python_input_error(e);
      error.attr("errors") = py::make_tuple(error);
      PyErr_SetObject(error.get_type().ptr(), error.ptr());
    } catch (const UnknownName& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<Config>(m, "Config", "A validated, fully resolved input (the Config of io/config.hpp).")
      .def_property_readonly("toml", [](const Config& c) { return c.resolved_toml; },
                             "The resolved input as TOML text, every key written out.")
      .def_property_readonly("source_file", [](const Config& c) { return c.source_file; })
      .def_property_readonly("output_directory", [](const Config& c) { return c.output.directory; })
      .def_property_readonly("dimension", [](const Config& c) { return c.simulation.dimension; })
      .def_property_readonly("end_time", [](const Config& c) { return c.simulation.end_time; })
      .def_property_readonly("warnings", [](const Config& c) { return c.warnings; });

  m.def(
      "load_config", [](const std::string& path, const py::object& set) { return load_config(path, overrides_of(set)); },
      py::arg("path"), py::arg("set") = py::none(), "Read and validate an input file, as `cairn run FILE --set ...`.");
  m.def(
      "load_config_string",
      [](const std::string& text, const std::string& name, const py::object& set) {
        return load_config_string(text, name, overrides_of(set));
      },
      py::arg("text"), py::arg("name"), py::arg("set") = py::none(),
      "Validate TOML text; `name` stands for the file name in messages and the default output folder.");
  m.def("to_toml", &dict_to_toml, py::arg("config"),
        "The TOML text of an input given as a dict (sections as dicts, [[material]]/[[body]] as lists of dicts).");
  m.def("overrides", &overrides_of, py::arg("set"), "The `section.key=value` texts of a dict of overrides.");
  m.def(
      "keys",
      [] {
        py::dict out;
        for (const auto& k : declared_keys()) out[py::str(k.section + "." + k.name)] = key_entry(k);
        for (const auto& [model, info] : material_model_info())
          for (const auto& k : info.keys) {
            py::dict d = key_entry(k);
            d["section"] = "material";
            d["model"] = model;
            out[py::str("material[" + model + "]." + k.name)] = d;
          }
        return out;
      },
      "Every declared input key: 'section.key' -> {type, default, range, required, doc}; a material model's own "
      "keys as 'material[model].key'.");
  m.def("keys_text", &keys_text, py::arg("markdown") = false, "`cairn keys` (markdown: docs/input.md).");
}

}  // namespace cairn::python
