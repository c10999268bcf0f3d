#include "cairn/fem/output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "cairn/config/errors.hpp"
#include "cairn/io/atomic_file.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/math/tensor.hpp"

namespace cairn::fem {
namespace fs = std::filesystem;

namespace {

std::vector<double> xyz(const std::vector<Vec<2>>& v) {
  std::vector<double> out(3 * v.size(), 0.0);
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[3 * i] = v[i][0];
    out[3 * i + 1] = v[i][1];
  }
  return out;
}

std::vector<double> flat2(const std::vector<Vec<2>>& v) {
  std::vector<double> out(2 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    out[2 * i] = v[i][0];
    out[2 * i + 1] = v[i][1];
  }
  return out;
}

std::vector<Vec<2>> unflat2(const std::vector<double>& d) {
  std::vector<Vec<2>> out(d.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec<2>(d[2 * i], d[2 * i + 1]);
  return out;
}

std::vector<double> flat9(const std::vector<Mat3>& m) {
  std::vector<double> out(9 * m.size());
  for (std::size_t e = 0; e < m.size(); ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[9 * e + 3 * i + j] = m[e](i, j);
  return out;
}

std::vector<Mat3> unflat9(const std::vector<double>& d) {
  std::vector<Mat3> out(d.size() / 9);
  for (std::size_t e = 0; e < out.size(); ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[e](i, j) = d[9 * e + 3 * i + j];
  return out;
}

}  // namespace

SnapshotWriter::SnapshotWriter(fs::path directory, std::string stem)
    : directory_(std::move(directory)), stem_(std::move(stem)) {}

void SnapshotWriter::write(const Solver& s) {
  const TriangleMesh& mesh = s.mesh();
  const std::size_t nn = mesh.n_nodes(), ne = mesh.n_elements();
  n_nodes_ = nn;
  n_elements_ = ne;
  std::vector<Vec<2>> u(nn);
  for (std::size_t i = 0; i < nn; ++i) u[i] = s.positions()[i] - mesh.nodes[i];
  std::vector<std::int32_t> connectivity(3 * ne);
  std::vector<double> stress(6 * ne), mises(ne), pressure(ne), jacobian(ne), energy(ne), centroid0(3 * ne, 0.0),
      centroid(3 * ne, 0.0);
  for (std::size_t e = 0; e < ne; ++e) {
    const auto& t = mesh.triangles[e];
    for (int k = 0; k < 3; ++k) {
      connectivity[3 * e + k] = t[k];
      for (int a = 0; a < 2; ++a) {
        centroid0[3 * e + a] += mesh.nodes[t[k]][a] / 3.0;
        centroid[3 * e + a] += s.positions()[t[k]][a] / 3.0;
      }
    }
    const Mat3& F = s.deformation_gradients()[e];
    const double J = F.determinant();
    const Mat3 sigma = cauchy_from_kirchhoff(s.kirchhoff_stresses()[e], F);
    // the particle snapshots' order: xx, yy, zz, yz, xz, xy
    const double voigt[6] = {sigma(0, 0), sigma(1, 1), sigma(2, 2), 0.5 * (sigma(1, 2) + sigma(2, 1)),
                             0.5 * (sigma(0, 2) + sigma(2, 0)), 0.5 * (sigma(0, 1) + sigma(1, 0))};
    for (int k = 0; k < 6; ++k) stress[6 * e + k] = voigt[k];
    mises[e] = von_mises(sigma);
    pressure[e] = -sigma.trace() / 3.0;
    jacobian[e] = J;
    energy[e] = s.material().energy_density(F);
  }
  const std::string name = fmt::format("{}-{:04d}.h5", stem_, entries_.size());
  fs::create_directories(directory_ / "snapshots");
  write_file_atomically(directory_ / "snapshots" / name, [&](const fs::path& tmp) {
    h5::Handle file = h5::create_file(tmp);
    const hid_t root = file.get();
    h5::write_string_attribute(root, "format", "cairn-fem-snapshot");
    h5::write_double_attribute(root, "time", s.time());
    h5::write_int64_attribute(root, "step", s.step_count());
    {
      h5::Handle g = h5::create_group(root, "nodes");
      h5::write_doubles(g.get(), "reference_position", xyz(mesh.nodes).data(), nn, 3);
      h5::write_doubles(g.get(), "position", xyz(s.positions()).data(), nn, 3);
      h5::write_doubles(g.get(), "displacement", xyz(u).data(), nn, 3);
      h5::write_doubles(g.get(), "velocity", xyz(s.velocities()).data(), nn, 3);
      h5::write_doubles(g.get(), "acceleration", xyz(s.accelerations()).data(), nn, 3);
      h5::write_doubles(g.get(), "mass", s.masses().data(), nn);
    }
    {
      h5::Handle g = h5::create_group(root, "elements");
      h5::write_ints(g.get(), "connectivity", connectivity.data(), 3 * ne);
      h5::write_doubles(g.get(), "reference_centroid", centroid0.data(), ne, 3);
      h5::write_doubles(g.get(), "centroid", centroid.data(), ne, 3);
      h5::write_doubles(g.get(), "stress", stress.data(), ne, 6);
      h5::write_doubles(g.get(), "von_mises", mises.data(), ne);
      h5::write_doubles(g.get(), "pressure", pressure.data(), ne);
      h5::write_doubles(g.get(), "jacobian", jacobian.data(), ne);
      h5::write_doubles(g.get(), "strain_energy_density", energy.data(), ne);
      h5::write_doubles(g.get(), "reference_volume", s.reference_volumes().data(), ne);
    }
  });
  entries_.emplace_back(s.time(), name);
  write_xdmf();
}

void SnapshotWriter::write_xdmf() const {
  std::string x =
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<Xdmf Version=\"3.0\">\n  <Domain>\n"
      "    <Grid Name=\"fem\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  const std::string nn = std::to_string(n_nodes_), ne = std::to_string(n_elements_);
  for (const auto& entry : entries_) {
    const double time = entry.first;
    const std::string& file = entry.second;  // a lambda below captures it (no structured binding)
    if (!fs::exists(directory_ / "snapshots" / file)) continue;
    const auto item = [&](const std::string& dims, bool integer, const std::string& set) {
      return fmt::format("<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">snapshots/{}:{}</DataItem>",
                         dims, integer ? "Int" : "Float", integer ? 4 : 8, file, set);
    };
    const auto attr = [&](const std::string& name, const char* type, const char* center, const std::string& dims,
                          const std::string& set) {
      return fmt::format("        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">{}</Attribute>\n", name,
                         type, center, item(dims, false, set));
    };
    x += fmt::format("      <Grid Name=\"{}\" GridType=\"Uniform\">\n        <Time Value=\"{:.17g}\"/>\n", file, time);
    x += fmt::format("        <Topology TopologyType=\"Triangle\" NumberOfElements=\"{}\">{}</Topology>\n", ne,
                     item(ne + " 3", true, "/elements/connectivity"));
    x += fmt::format("        <Geometry GeometryType=\"XYZ\">{}</Geometry>\n", item(nn + " 3", false, "/nodes/position"));
    x += attr("displacement", "Vector", "Node", nn + " 3", "/nodes/displacement");
    x += attr("velocity", "Vector", "Node", nn + " 3", "/nodes/velocity");
    x += attr("mass", "Scalar", "Node", nn, "/nodes/mass");
    x += attr("stress", "Matrix", "Cell", ne + " 6", "/elements/stress");
    x += attr("von_mises", "Scalar", "Cell", ne, "/elements/von_mises");
    x += attr("pressure", "Scalar", "Cell", ne, "/elements/pressure");
    x += attr("jacobian", "Scalar", "Cell", ne, "/elements/jacobian");
    x += attr("strain_energy_density", "Scalar", "Cell", ne, "/elements/strain_energy_density");
    x += "      </Grid>\n";
  }
  x += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  write_text_atomically(xdmf_path(), x);
}

void write_checkpoint(const fs::path& path, const Checkpoint& d) {
  write_file_atomically(path, [&](const fs::path& tmp) {
    h5::Handle file = h5::create_file(tmp);
    const hid_t root = file.get();
    h5::write_string_attribute(root, "format", checkpoint_format);
    h5::write_string_attribute(root, "engine", "fem");  // (run/engine.hpp: the engine a checkpoint names)
    h5::write_int64_attribute(root, "version", 1);
    h5::write_text(root, "input", d.config_toml);
    const auto& s = d.state;
    std::map<std::string, double> scalars = d.scalars;
    scalars["time"] = s.time;
    scalars["external_work"] = s.external_work;
    scalars["step"] = static_cast<double>(s.step);
    scalars["displacement_error"] = s.error_now;
    scalars["displacement_error_max"] = s.error_max;
    std::vector<std::string> names;
    std::vector<double> values;
    for (const auto& [k, v] : scalars) {
      names.push_back(k);
      values.push_back(v);
    }
    h5::write_text_list(root, "scalar_names", names);
    h5::write_doubles(root, "scalar_values", values.data(), values.size());
    h5::write_doubles(root, "x", flat2(s.x).data(), s.x.size(), 2);
    h5::write_doubles(root, "v", flat2(s.v).data(), s.v.size(), 2);
    h5::write_doubles(root, "a", flat2(s.a).data(), s.a.size(), 2);
    h5::write_doubles(root, "b", flat2(s.b).data(), s.b.size(), 2);
    h5::write_doubles(root, "reaction", flat2(s.reaction).data(), s.reaction.size(), 2);
    h5::write_doubles(root, "F", flat9(s.F).data(), s.F.size(), 9);
    h5::write_doubles(root, "tau", flat9(s.tau).data(), s.tau.size(), 9);
    h5::write_doubles(root, "element_state", s.element_state.data(), s.element_state.size());
    h5::write_doubles(root, "temperature", s.temperature.data(), s.temperature.size());
    h5::write_text_list(root, "history_columns", d.history_columns);
    std::vector<double> rows;
    for (const auto& r : d.history_rows) rows.insert(rows.end(), r.begin(), r.end());
    h5::write_doubles_shaped(root, "history_rows", rows.data(), {d.history_rows.size(), d.history_columns.size()});
    std::vector<double> times;
    std::vector<std::string> files;
    for (const auto& [t, f] : d.snapshots) {
      times.push_back(t);
      files.push_back(f);
    }
    h5::write_doubles(root, "snapshot_times", times.data(), times.size());
    h5::write_text_list(root, "snapshot_files", files);
  });
}

bool is_checkpoint(const fs::path& path) {
  try {
    h5::silence_errors();
    h5::Handle file = h5::open_file(path);
    return h5::has_attribute(file.get(), "format") &&
           h5::read_string_attribute(file.get(), "format") == checkpoint_format;
  } catch (const std::exception&) {
    return false;
  }
}

Checkpoint read_checkpoint(const fs::path& path) {
  // Whatever is wrong is exit 2 naming the file and the object (docs/robustness.md, "Files from outside").
  auto refuse = [&](const std::string& object, const std::string& expected, const std::string& found) {
    throw InputError(path.string(), 0, object, expected, found);
  };
  if (!is_checkpoint(path)) {
    std::string format = "none";
    try {
      h5::Handle file = h5::open_file(path);
      if (h5::has_attribute(file.get(), "format")) format = "'" + h5::read_string_attribute(file.get(), "format") + "'";
    } catch (const std::exception&) {
      format = "unreadable";
    }
    refuse("format", std::string("'") + checkpoint_format + "', the format of the engine its 'engine' attribute names (fem)",
           format + " (a damaged or edited checkpoint)");
  }
  Checkpoint d;
  std::string where = "/";
  std::error_code size_ec;
  const double file_bytes = static_cast<double>(fs::file_size(path, size_ec));
  try {
    h5::Handle file = h5::open_file(path);
    const hid_t root = file.get();
    // A shape declaring more values than the file's bytes can hold (gzip: about 1000 in the bytes
    // of one) is refused before anything of that size is allocated, as the MPM reader does.
    auto shape_of = [&](const std::string& name) {
      const std::vector<std::size_t> shape = h5::dataset_shape(root, name);
      double values = 1.0;
      for (std::size_t n : shape) values *= static_cast<double>(n);
      if (!h5::file_can_hold(values * 8.0, file_bytes))
        refuse(where, "a dataset that the file's bytes can hold",
               fmt::format("a shape of {:.6g} values in a file of {:.6g} bytes (a damaged or edited checkpoint)",
                           values, file_bytes));
      return shape;
    };
    auto text_list = [&](const std::string& name) {
      (void)shape_of(name);
      return h5::read_text_list(root, name);
    };
    where = "/input";
    d.config_toml = h5::read_text(root, "input");
    where = "/scalar_names";
    const auto names = text_list("scalar_names");
    where = "/scalar_values";
    const auto values = h5::read_doubles(root, "scalar_values", {names.size()});
    for (std::size_t k = 0; k < names.size(); ++k) d.scalars[names[k]] = values[k];
    for (const auto& [name, value] : d.scalars)
      if (!std::isfinite(value)) refuse("/scalar_values (" + name + ")", "finite run-loop scalars", fmt::format("{}", value));
    auto scalar = [&](const char* name) {
      const auto it = d.scalars.find(name);
      if (it == d.scalars.end())
        refuse("/scalar_names", fmt::format("the run-loop scalar '{}'", name), "a list without it (a damaged or edited checkpoint)");
      return it->second;
    };
    auto& s = d.state;
    s.time = scalar("time");
    s.external_work = scalar("external_work");
    const double step = scalar("step");
    if (!(step >= 0.0 && step <= 9e15)) refuse("/scalar_values (step)", "a step count 0..9e15", fmt::format("{}", step));
    s.step = static_cast<long long>(step);
    s.error_now = scalar("displacement_error");
    s.error_max = scalar("displacement_error_max");
    for (const char* name : {"initial_energy", "previous_dt", "checkpoint_index", "snapshots_done", "history_done",
                             "checkpoints_done"}) {
      const double v = scalar(name);
      if (std::string(name).find("_done") != std::string::npos || std::string(name) == "checkpoint_index")
        if (!(v >= 0.0 && v <= 1e9)) refuse(std::string("/scalar_values (") + name + ")", "a count 0..1e9", fmt::format("{}", v));
    }
    // n x cols doubles, every one finite.
    auto read = [&](const std::string& name, std::size_t cols) {
      where = "/" + name;
      const std::vector<std::size_t> shape = shape_of(name);
      if (cols > 0 ? shape.size() != 2 || shape[1] != cols : shape.size() != 1)
        refuse(where, cols > 0 ? fmt::format("an n x {} dataset", cols) : std::string("a 1D dataset"),
               fmt::format("{} axes{}", shape.size(), shape.size() == 2 ? fmt::format(" of {} columns", shape[1]) : ""));
      const std::vector<double> v = h5::read_doubles(root, name, shape);
      for (std::size_t i = 0; i < v.size(); ++i)
        if (!std::isfinite(v[i])) refuse(fmt::format("{}[{}]", where, i / std::max<std::size_t>(cols, 1)), "finite values", fmt::format("{}", v[i]));
      return v;
    };
    s.x = unflat2(read("x", 2));
    s.v = unflat2(read("v", 2));
    s.a = unflat2(read("a", 2));
    s.b = unflat2(read("b", 2));
    s.reaction = unflat2(read("reaction", 2));
    s.F = unflat9(read("F", 9));
    for (std::size_t e = 0; e < s.F.size(); ++e)
      if (!(s.F[e].determinant() > 0.0)) refuse(fmt::format("/F[{}]", e), "a deformation gradient with a positive determinant", "one <= 0");
    s.tau = unflat9(read("tau", 9));
    s.element_state = read("element_state", 0);
    s.temperature = read("temperature", 0);
    where = "/history_columns";
    d.history_columns = text_list("history_columns");
    where = "/history_rows";
    const auto shape = shape_of("history_rows");
    if (shape.size() != 2 || shape[1] != d.history_columns.size())
      refuse(where, fmt::format("rows x {} columns, as /history_columns lists", d.history_columns.size()),
             fmt::format("{} axes{}", shape.size(), shape.size() == 2 ? fmt::format(" of {} columns", shape[1]) : ""));
    const auto rows = h5::read_doubles(root, "history_rows", shape);
    const std::size_t nc = d.history_columns.size();
    for (std::size_t r = 0; nc > 0 && r < rows.size() / nc; ++r)
      d.history_rows.emplace_back(rows.begin() + static_cast<std::ptrdiff_t>(r * nc),
                                  rows.begin() + static_cast<std::ptrdiff_t>((r + 1) * nc));
    where = "/snapshot_files";
    const auto files = text_list("snapshot_files");
    where = "/snapshot_times";
    const auto times = h5::read_doubles(root, "snapshot_times", {files.size()});
    for (std::size_t k = 0; k < times.size() && k < files.size(); ++k) d.snapshots.emplace_back(times[k], files[k]);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {  // the HDF5 helpers: a missing dataset, a wrong shape or type
    refuse(where, "the object as Cairn's FEM writes it", std::string(e.what()) + " (a damaged or edited checkpoint)");
  }
  return d;
}

}  // namespace cairn::fem
