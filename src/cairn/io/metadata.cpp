#include "cairn/io/metadata.hpp"

#include <algorithm>

#include "cairn/io/hdf5_util.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/util/sha256.hpp"

namespace cairn {

OutputMetadata output_metadata(const Config& config) {
  OutputMetadata m;
  m.title = config.simulation.title;
  m.units = config.simulation.units;
  for (const auto& mat : config.materials) m.material_names.push_back(mat.name);
  for (const auto& body : config.bodies) m.body_names.push_back(body.name);
  m.input_toml = config.resolved_toml;
  m.compression = config.output.compression;
  // The models' state variables, merged by name over the materials (a model is cheap to make).
  const auto n_materials = config.materials.size();
  for (std::size_t i = 0; i < n_materials; ++i) {
    for (const auto& v : make_material(config.materials[i])->state_variables()) {
      auto it = std::find_if(m.state_variables.begin(), m.state_variables.end(),
                             [&](const auto& s) { return s.name == v.name; });
      if (it == m.state_variables.end()) {
        std::string unit = m.unit(v.unit);
        if (v.per != Quantity::dimensionless) {
          const std::string per = m.unit(v.per);
          const bool compound = per.find_first_of("*/") != std::string::npos;
          unit = (v.unit == Quantity::dimensionless ? "1" : unit) + "/" + (compound ? "(" + per + ")" : per);
        }
        m.state_variables.push_back({v.name, unit, v.description, std::vector<int>(n_materials, -1)});
        it = m.state_variables.end() - 1;
      }
      it->index[i] = v.index;
    }
  }
  return m;
}

namespace h5 {

void write_metadata(hid_t root, const OutputMetadata& meta, bool with_input) {
  write_string_attribute(root, "cairn_version", CAIRN_VERSION);
  write_string_attribute(root, "title", meta.title);
  write_string_attribute(root, "units", meta.units);
  write_string_attribute(root, "unit_length", meta.unit(Quantity::length));
  write_string_attribute(root, "unit_mass", meta.unit(Quantity::mass));
  write_string_attribute(root, "unit_time", meta.unit(Quantity::time));
  write_string_attribute(root, "unit_temperature", meta.unit(Quantity::temperature));
  write_string_attribute(root, "input_sha256", sha256_hex(meta.input_toml));
  if (with_input) write_text(root, "input", meta.input_toml);
  write_text_list(root, "material_names", meta.material_names);
  write_text_list(root, "body_names", meta.body_names);
}

void describe_dataset(hid_t loc, const std::string& name, const std::string& units,
                      const std::string& description, const std::string& components) {
  Handle dset(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (dset.get() < 0) throw std::runtime_error("HDF5: cannot open dataset " + describe(loc, name));
  write_string_attribute(dset.get(), "units", units);
  write_string_attribute(dset.get(), "description", description);
  if (!components.empty()) write_string_attribute(dset.get(), "components", components);
}

}  // namespace h5

}  // namespace cairn
