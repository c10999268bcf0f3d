#include "cairn/io/checkpoint.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "cairn/io/atomic_file.hpp"
#include "cairn/io/checksum.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/parallel/agree.hpp"
#include "cairn/util/child_process.hpp"

namespace cairn {

namespace fs = std::filesystem;

namespace {

constexpr const char* format_name = "cairn-checkpoint";

// Particle arrays are written from the simulation's own storage: vectors directly (a Vec<D> is D
// contiguous doubles, stored n x 3 with zeros beyond D, the shape snapshots use: format version
// 2), matrices (column-major in memory, row-major in the file) through a bounded block buffer,
// so a checkpoint never holds a second copy of the particles.
template <int D>
void write_vecs(hid_t loc, const std::string& name, const std::vector<Vec<D>>& v, h5::Rows rows, int deflate) {
  static_assert(sizeof(Vec<D>) == D * sizeof(double), "Vec<D> must be D packed doubles");
  h5::write_doubles_padded(loc, name, v.empty() ? nullptr : v.front().data(), rows, D, 3, deflate);
}

/// Reads n x 3 (version 2) or n x D (version 1) vectors.
template <int D>
/// Rows [first, first + n) of n x 3 (version 2) or n x D (version 1) vectors.
std::vector<Vec<D>> read_vecs(hid_t loc, const std::string& name, std::size_t first, std::size_t n) {
  const std::vector<std::size_t> shape = h5::dataset_shape(loc, name);
  const std::size_t cols = shape.size() == 2 && shape[1] == 3 ? 3 : static_cast<std::size_t>(D);
  const std::vector<double> buffer = h5::read_doubles_rows(loc, name, first, n, cols);
  std::vector<Vec<D>> v(n);
  for (std::size_t p = 0; p < n; ++p)
    for (int a = 0; a < D; ++a) v[p][a] = buffer[cols * p + a];
  return v;
}

/// Mat3 or SymMat3 per particle, n x 9 row-major.
template <class M>
void write_mats(hid_t loc, const std::string& name, const std::vector<M>& m, h5::Rows rows, int deflate) {
  h5::write_doubles_blocked(loc, name, rows, 9, [&](std::size_t first, std::size_t count, double* out) {
    for (std::size_t p = first; p < first + count; ++p)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) *out++ = m[p](i, j);
  }, deflate);
}

std::vector<Mat3> read_mats(hid_t loc, const std::string& name, std::size_t first, std::size_t n) {
  const std::vector<double> buffer = h5::read_doubles_rows(loc, name, first, n, 9);
  std::vector<Mat3> m(n);
  for (std::size_t p = 0; p < n; ++p)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[p](i, j) = buffer[9 * p + 3 * i + j];
  return m;
}

template <int D>
void check_particles(const Particles<D>& ps) {
  const std::size_t n = ps.n();
  const bool ok = ps.reference_position.size() == n && ps.velocity.size() == n &&
                  ps.mass.size() == n && ps.volume0.size() == n && ps.size0.size() == n &&
                  ps.deformation_gradient.size() == n && ps.kirchhoff_stress.size() == n &&
                  ps.affine_velocity.size() == (ps.has_affine ? n : 0) &&
                  ps.temperature.size() == (ps.has_temperature ? n : 0) &&
                  ps.material.size() == n &&
                  ps.body.size() == n && ps.n_state_per_particle >= 0 &&
                  ps.state.size() == n * static_cast<std::size_t>(ps.n_state_per_particle);
  if (!ok) throw std::invalid_argument("write_checkpoint: particle arrays have inconsistent lengths");
}

/// A damaged or edited checkpoint: exit 2 naming the file and the object (a root attribute or a
/// dataset path such as /particles/mass[17]).
[[noreturn]] void refuse(const fs::path& path, const std::string& object, const std::string& expected,
                         const std::string& found) {
  throw InputError(path.string(), 0, object, expected, found);
}

/// Run `read` and turn what the HDF5 helpers throw (std::runtime_error naming the HDF5 object: a
/// missing dataset, a wrong shape or type) into an InputError naming the checkpoint and `where`.
template <class Read>
void reading(const fs::path& path, const std::string& where, Read&& read) {
  try {
    read();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // (std::bad_alloc, std::length_error: a damaged size)
    refuse(path, where, "the object as Cairn writes it", std::string(e.what()) + " (a damaged or edited checkpoint)");
  }
}

/// Open `path` and check that it is a Cairn checkpoint of the supported version; returns the
/// open file and stores its dimension.
h5::Handle open_checkpoint(const fs::path& path, int& dimension) {
  std::error_code ec;
  if (!fs::exists(path, ec)) refuse(path, "", "an existing checkpoint file", "it does not exist");
  h5::Handle file;
  try {
    file = h5::open_file(path);
  } catch (const std::runtime_error&) {
    refuse(path, "", "a Cairn checkpoint (an HDF5 file)",
           "a file HDF5 cannot open: not a Cairn checkpoint (not HDF5, truncated or damaged)");
  }
  const hid_t root = file.get();
  std::string where = "format";
  reading(path, where, [&] {
    if (!h5::has_attribute(root, "format"))
      refuse(path, where, std::string("the root attribute 'format' = '") + format_name + "'",
             "an HDF5 file without it (not a Cairn checkpoint)");
    std::string format;
    try {
      format = h5::read_string_attribute(root, "format");
    } catch (const std::runtime_error&) {
      format = "?";
    }
    if (format != format_name) {
      // The FEM's own format under an 'engine' attribute that names another engine.
      std::string engine;
      if (format == "cairn-fem-checkpoint" && h5::has_attribute(root, "engine")) {
        try {
          engine = h5::read_string_attribute(root, "engine");
        } catch (const std::runtime_error&) {
          engine = "?";
        }
      }
      refuse(path, where, std::string("'") + format_name + "' (a checkpoint of the mpm or wls engine)",
             "'" + format + "'" +
                 (engine.empty() ? std::string(" (not a Cairn checkpoint of the mpm or wls engine)")
                                 : " (the FEM's checkpoint format, but its 'engine' attribute says '" + engine +
                                       "': a damaged or edited checkpoint)"));
    }
    where = "version";
    const long long version = h5::read_int64_attribute(root, "version");
    if (version < 1 || version > checkpoint_format_version)
      refuse(path, where, fmt::format("a format version this build of Cairn reads, 1 to {}", checkpoint_format_version),
             fmt::format("version {}", version));
    where = "dimension";
    const long long dim = h5::read_int64_attribute(root, "dimension");
    if (dim < 1 || dim > 3) refuse(path, where, "1, 2 or 3", fmt::format("{}", dim));
    dimension = static_cast<int>(dim);
  });
  return file;
}

/// Whether the n x (3 x 3) matrices in `m` are finite; `det` also asks for a positive determinant.
template <class M>
void check_matrices(const fs::path& path, const std::string& name, const std::vector<M>& m, std::size_t first,
                    bool det) {
  for (std::size_t p = 0; p < m.size(); ++p) {
    bool ok = true;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ok = ok && std::isfinite(m[p](i, j));
    if (ok && det) ok = Mat3(m[p]).determinant() > 0.0;
    if (!ok)
      refuse(path, fmt::format("/particles/{}[{}]", name, first + p),
             det ? "a finite deformation gradient with a positive determinant" : "finite values",
             "a non-finite value" + std::string(det ? " or a determinant <= 0" : "") + " (a damaged or edited checkpoint)");
  }
}

/// The values a run could have written: finite, masses, volumes and sizes not below zero,
/// deformation gradients that keep orientation, indices not negative (their upper bounds belong
/// to the input: the engine checks them).
template <int D>
void check_values(const fs::path& path, const CheckpointData<D>& data, std::size_t first) {
  auto bad = [&](const std::string& object, const std::string& expected, double found) {
    refuse(path, object, expected, fmt::format("{} (a damaged or edited checkpoint)", found));
  };
  if (!std::isfinite(data.time) || data.time < 0.0) bad("time", "a finite time >= 0", data.time);
  if (data.step < 0) bad("step", "a step count >= 0", static_cast<double>(data.step));
  if (!std::isfinite(data.previous_dt) || data.previous_dt < 0.0) bad("previous_dt", "a finite step >= 0", data.previous_dt);
  if (data.snapshot_next_index < 0) bad("snapshot_next_index", "an index >= 0", data.snapshot_next_index);
  for (const auto& [name, value] : data.scalars)
    if (!std::isfinite(value)) bad("/scalars/values (" + name + ")", "finite run-loop scalars", value);
  for (const auto& [t, file] : data.snapshot_entries)
    if (!std::isfinite(t)) bad("/snapshots/times", "finite snapshot times", t);
  const Particles<D>& ps = data.particles;
  auto at = [&](const char* name, std::size_t p) { return fmt::format("/particles/{}[{}]", name, first + p); };
  for (std::size_t p = 0; p < ps.n(); ++p) {
    // (WLS surface particles carry neither mass nor volume.)
    if (!(std::isfinite(ps.mass[p]) && ps.mass[p] >= 0.0)) bad(at("mass", p), "a finite mass >= 0", ps.mass[p]);
    if (!(std::isfinite(ps.volume0[p]) && ps.volume0[p] >= 0.0))
      bad(at("volume0", p), "a finite volume >= 0", ps.volume0[p]);
    for (int a = 0; a < D; ++a) {
      if (!std::isfinite(ps.velocity[p][a])) bad(at("velocity", p), "a finite velocity", ps.velocity[p][a]);
      if (!std::isfinite(ps.reference_position[p][a]))
        bad(at("reference_position", p), "a finite position", ps.reference_position[p][a]);
      if (!(std::isfinite(ps.size0[p][a]) && ps.size0[p][a] >= 0.0)) bad(at("size0", p), "a finite size >= 0", ps.size0[p][a]);
    }
    if (ps.has_temperature && !std::isfinite(ps.temperature[p]))
      bad(at("temperature", p), "a finite temperature", ps.temperature[p]);
    if (ps.material[p] < 0) bad(at("material", p), "a material index >= 0", ps.material[p]);
    if (ps.body[p] < 0) bad(at("body", p), "a body index >= 0", ps.body[p]);
  }
  check_matrices(path, "deformation_gradient", ps.deformation_gradient, first, true);
  check_matrices(path, "kirchhoff_stress", ps.kirchhoff_stress, first, false);
  if (ps.has_affine) check_matrices(path, "affine_velocity", ps.affine_velocity, first, false);
  const auto width = static_cast<std::size_t>(ps.n_state_per_particle);
  for (std::size_t k = 0; k < ps.state.size(); ++k)
    if (std::isnan(ps.state[k])) bad(at("state", k / std::max<std::size_t>(width, 1)), "state variables that are numbers", ps.state[k]);
}

}  // namespace

template <int D>
void write_checkpoint(const fs::path& path, const CheckpointData<D>& data) {
  write_checkpoint(path, data, data.particles);
}

template <int D>
void write_checkpoint(const fs::path& path, const CheckpointData<D>& data, const Particles<D>& particles) {
  write_checkpoint(path, data, particles, Comm::serial());
}

template <int D>
void write_checkpoint(const fs::path& path, const CheckpointData<D>& data, const Particles<D>& particles,
                      const Comm& comm) {
  check_particles(particles);
  const std::size_t n_rows = data.history_rows.size();
  const std::size_t n_cols = n_rows > 0 ? data.history_rows.front().size() : data.history_columns.size();
  for (const auto& row : data.history_rows) {
    if (row.size() != n_cols) {
      throw std::invalid_argument("write_checkpoint: history rows have different lengths");
    }
  }
  // Particles rank after rank (one rank: all, in order), each with its id.
  const h5::Rows rows = h5::rows_of(comm, particles.n());
  auto checksum = [](const fs::path& tmp) {  // from the closed file, as one process
    h5::Handle file(H5Fopen(tmp.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    if (file.get() < 0) throw std::runtime_error("cannot reopen '" + tmp.string() + "' for its checksum");
    write_content_checksum(file.get());
  };
  write_file_atomically(path, comm, [&](const fs::path& tmp) {
    h5::Handle file = h5::create_file(tmp, comm);
    const hid_t root = file.get();
    h5::write_string_attribute(root, "format", format_name);
    h5::write_int64_attribute(root, "version", checkpoint_format_version);
    h5::write_string_attribute(root, "engine", data.engine);
    h5::write_int64_attribute(root, "dimension", D);
    h5::write_double_attribute(root, "time", data.time);
    h5::write_int64_attribute(root, "step", data.step);
    h5::write_double_attribute(root, "previous_dt", data.previous_dt);
    h5::write_int64_attribute(root, "snapshot_next_index", data.snapshot_next_index);
    h5::write_text(root, "config_toml", data.config_toml);
    OutputMetadata meta = data.metadata;
    meta.input_toml = data.config_toml;  // input_sha256 fingerprints /config_toml
    h5::write_metadata(root, meta, false);
    {
      h5::Handle g = h5::create_group(root, "scalars");
      std::vector<std::string> names;
      std::vector<double> values;
      for (const auto& [name, value] : data.scalars) {
        names.push_back(name);
        values.push_back(value);
      }
      h5::write_text_list(g.get(), "names", names);
      h5::write_doubles(g.get(), "values", values.data(), values.size());
    }
    {
      h5::Handle g = h5::create_group(root, "history");
      h5::write_text_list(g.get(), "columns", data.history_columns);
      std::vector<double> rows;
      rows.reserve(n_rows * n_cols);
      for (const auto& row : data.history_rows) rows.insert(rows.end(), row.begin(), row.end());
      h5::write_doubles_shaped(g.get(), "rows", rows.data(), {n_rows, n_cols});
    }
    {
      h5::Handle g = h5::create_group(root, "snapshots");
      std::vector<double> times;
      std::vector<std::string> files;
      for (const auto& [t, f] : data.snapshot_entries) {
        times.push_back(t);
        files.push_back(f);
      }
      h5::write_doubles(g.get(), "times", times.data(), times.size());
      h5::write_text_list(g.get(), "files", files);
    }
    // Every rank its own pairs, rank after rank (collective: the total decides for all).
    if (const h5::Rows pairs = h5::rows_of(comm, data.contact_record.size()); pairs.total > 0) {
      h5::Handle g = h5::create_group(root, "contact");
      h5::write_int64s_rows(g.get(), "in_contact", data.contact_record.data(), pairs);
    }
    {
      const Particles<D>& ps = particles;
      const int z = data.metadata.compression;
      h5::Handle g = h5::create_group(root, "particles");
      const hid_t gid = g.get();
      h5::write_int64_attribute(gid, "n_state_per_particle", ps.n_state_per_particle);
      write_vecs<D>(gid, "position", ps.position, rows, z);
      write_vecs<D>(gid, "reference_position", ps.reference_position, rows, z);
      write_vecs<D>(gid, "velocity", ps.velocity, rows, z);
      h5::write_doubles_rows(gid, "mass", ps.mass.data(), rows);
      h5::write_doubles_rows(gid, "volume0", ps.volume0.data(), rows);
      if (ps.has_temperature) h5::write_doubles_rows(gid, "temperature", ps.temperature.data(), rows);
      write_vecs<D>(gid, "size0", ps.size0, rows, z);
      write_mats(gid, "deformation_gradient", ps.deformation_gradient, rows, z);
      write_mats(gid, "kirchhoff_stress", ps.kirchhoff_stress, rows, z);
      if (ps.has_affine) write_mats(gid, "affine_velocity", ps.affine_velocity, rows, z);
      h5::write_ints_rows(gid, "material", ps.material.data(), rows);
      h5::write_ints_rows(gid, "body", ps.body.data(), rows);
      h5::write_int64s_rows(gid, "id", ps.id.data(), rows);
      const auto n_state = static_cast<std::size_t>(ps.n_state_per_particle);
      h5::write_doubles_rows(gid, "state", ps.state.data(),
                             h5::Rows{rows.first * n_state, rows.count * n_state, rows.total * n_state}, 0, z);
    }
  }, checksum);  // the checksum last: it covers everything above
}

template <int D>
CheckpointData<D> read_checkpoint(const fs::path& path) {
  return read_checkpoint<D>(path, Comm::serial());
}

template <int D>
CheckpointData<D> read_checkpoint(const fs::path& path, const Comm& comm) {
  int dimension = 0;
  h5::Handle file = open_checkpoint(path, dimension);
  if (dimension != D) refuse(path, "dimension", fmt::format("{}D, the dimension read", D), fmt::format("{}D", dimension));
  const hid_t root = file.get();
  // Rank 0 reads the whole file for the checksum; the verdict goes to every rank.
  std::string verdict;
  if (comm.is_root()) {
    try {
      if (std::string stored, computed; !content_checksum_matches(root, stored, computed)) verdict = stored + " " + computed;
    } catch (const std::exception& e) {  // an object HDF5 cannot read; a damaged size (bad_alloc)
      verdict = std::string("! ") + e.what();
    }
  }
  comm.broadcast(verdict, 0);
  if (verdict.rfind("! ", 0) == 0)
    refuse(path, "checksum", "a file whose every object can be read to verify its content checksum",
           verdict.substr(2) + " (a damaged checkpoint)");
  if (!verdict.empty()) {
    const std::string stored = verdict.substr(0, verdict.find(' ')), computed = verdict.substr(verdict.find(' ') + 1);
    throw InputError(path.string(), 0, "checksum",
                     fmt::format("the content checksum stored when the checkpoint was written ({})", stored),
                     fmt::format("content with checksum {}: the file was changed or damaged after it "
                                 "was written, so it is refused",
                                 computed));
  }
  CheckpointData<D> data;
  // A file larger in its declared shapes than its bytes could hold (gzip stores at most about
  // 1000 values in the bytes of one) is refused before anything of that size is allocated.
  std::error_code size_ec;
  const double file_bytes = static_cast<double>(fs::file_size(path, size_ec));
  std::size_t first = 0;
  std::string where = "engine";
  reading(path, where, [&] {
    auto shape_of = [&](hid_t loc, const std::string& name, std::size_t bytes_per_row) {
      const std::vector<std::size_t> shape = h5::dataset_shape(loc, name);
      double values = 1.0;
      for (std::size_t d : shape) values *= static_cast<double>(d);
      if (!h5::file_can_hold(values * static_cast<double>(bytes_per_row), file_bytes))
        refuse(path, where, "a dataset that the file's bytes can hold",
               fmt::format("a shape of {:.6g} values in a file of {:.6g} bytes (a damaged or edited checkpoint)",
                           values, file_bytes));
      return shape;
    };
    data.engine_named = h5::has_attribute(root, "engine");
    data.engine = data.engine_named ? h5::read_string_attribute(root, "engine") : "mpm";
    where = "time";
    data.time = h5::read_double_attribute(root, "time");
    where = "step";
    data.step = h5::read_int64_attribute(root, "step");
    where = "previous_dt";
    data.previous_dt = h5::read_double_attribute(root, "previous_dt");
    where = "snapshot_next_index";
    const long long next_index = h5::read_int64_attribute(root, "snapshot_next_index");
    if (next_index < 0 || next_index > 1000000000)
      refuse(path, where, "a snapshot index 0..1e9", fmt::format("{}", next_index));
    data.snapshot_next_index = static_cast<int>(next_index);
    where = "/config_toml";
    (void)shape_of(root, "config_toml", 1);
    data.config_toml = h5::read_text(root, "config_toml");
    {
      where = "/scalars";
      h5::Handle g = h5::open_group(root, "scalars");
      where = "/scalars/names";
      (void)shape_of(g.get(), "names", 8);
      const std::vector<std::string> names = h5::read_text_list(g.get(), "names");
      where = "/scalars/values";
      const std::vector<double> values = h5::read_doubles(g.get(), "values", {names.size()});
      for (std::size_t i = 0; i < names.size(); ++i) data.scalars[names[i]] = values[i];
    }
    {
      where = "/history";
      h5::Handle g = h5::open_group(root, "history");
      where = "/history/columns";
      data.history_columns = h5::read_text_list(g.get(), "columns");
      where = "/history/rows";
      const std::vector<std::size_t> shape = shape_of(g.get(), "rows", 8);
      if (shape.size() != 2) refuse(path, where, "a 2D dataset (rows x columns)", fmt::format("{} axes", shape.size()));
      const std::vector<double> rows = h5::read_doubles(g.get(), "rows", shape);
      for (std::size_t r = 0; r < shape[0]; ++r) {
        const auto row = rows.begin() + static_cast<std::ptrdiff_t>(r * shape[1]);
        data.history_rows.emplace_back(row, row + static_cast<std::ptrdiff_t>(shape[1]));
      }
    }
    {
      where = "/snapshots";
      h5::Handle g = h5::open_group(root, "snapshots");
      where = "/snapshots/files";
      (void)shape_of(g.get(), "files", 8);
      const std::vector<std::string> files = h5::read_text_list(g.get(), "files");
      where = "/snapshots/times";
      const std::vector<double> times = h5::read_doubles(g.get(), "times", {files.size()});
      for (std::size_t i = 0; i < files.size(); ++i) data.snapshot_entries.emplace_back(times[i], files[i]);
    }
    if (h5::has_child(root, "contact")) {  // every rank reads all of the record
      where = "/contact";
      h5::Handle g = h5::open_group(root, "contact");
      where = "/contact/in_contact";
      const std::vector<std::size_t> s = shape_of(g.get(), "in_contact", 8);
      if (s.size() != 1) refuse(path, where, "a 1D dataset (one key per field pair)", fmt::format("{} axes", s.size()));
      data.contact_record = h5::read_int64s_rows(g.get(), "in_contact", 0, s[0]);
    }
    where = "/particles";
    h5::Handle g = h5::open_group(root, "particles");
    const hid_t gid = g.get();
    where = "/particles/mass";
    const std::vector<std::size_t> shape = shape_of(gid, "mass", 200);
    if (shape.size() != 1) refuse(path, where, "a 1D dataset (one mass per particle)", fmt::format("{} axes", shape.size()));
    const std::size_t total = shape[0];
    if (total > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      refuse(path, where, "at most 2^31 - 1 particles", fmt::format("{}", total));
    where = "/particles (attribute n_state_per_particle)";
    const long long n_state = h5::read_int64_attribute(gid, "n_state_per_particle");
    if (n_state < 0 || n_state > 1000) refuse(path, where, "0..1000 state variables per particle", fmt::format("{}", n_state));
    // Every particle dataset has a row per particle: one of another length is refused, not cut.
    auto rows_of = [&](const char* name, std::size_t rows) {
      where = std::string("/particles/") + name;
      const std::vector<std::size_t> s = shape_of(gid, name, 8);
      if (s.empty() || s[0] != rows)
        refuse(path, where, fmt::format("{} rows, as /particles/mass has", rows),
               s.empty() ? std::string("a scalar") : fmt::format("{} rows", s[0]));
    };
    for (const char* name : {"position", "reference_position", "velocity", "volume0", "size0", "deformation_gradient",
                             "kirchhoff_stress", "material", "body"})
      rows_of(name, total);
    for (const char* name : {"temperature", "affine_velocity", "id"})
      if (h5::has_child(gid, name)) rows_of(name, total);
    rows_of("state", total * static_cast<std::size_t>(n_state));
    // On several ranks each reads an equal slab of rows; the run then sends every particle to
    // its owner, so any number of ranks reads a checkpoint of any other number.
    const auto ranks = static_cast<std::size_t>(comm.size()), rank = static_cast<std::size_t>(comm.rank());
    first = total * rank / ranks;
    const std::size_t n = total * (rank + 1) / ranks - first;
    const auto width = static_cast<std::size_t>(n_state);
    Particles<D>& ps = data.particles;
    ps.n_state_per_particle = static_cast<int>(n_state);
    where = "/particles/position";
    ps.position = read_vecs<D>(gid, "position", first, n);
    where = "/particles/reference_position";
    ps.reference_position = read_vecs<D>(gid, "reference_position", first, n);
    where = "/particles/velocity";
    ps.velocity = read_vecs<D>(gid, "velocity", first, n);
    where = "/particles/mass";
    ps.mass = h5::read_doubles_rows(gid, "mass", first, n);
    where = "/particles/volume0";
    ps.volume0 = h5::read_doubles_rows(gid, "volume0", first, n);
    ps.has_temperature = h5::has_child(gid, "temperature");
    where = "/particles/temperature";
    if (ps.has_temperature) ps.temperature = h5::read_doubles_rows(gid, "temperature", first, n);
    where = "/particles/size0";
    ps.size0 = read_vecs<D>(gid, "size0", first, n);
    where = "/particles/deformation_gradient";
    ps.deformation_gradient = read_mats(gid, "deformation_gradient", first, n);
    where = "/particles/kirchhoff_stress";
    const std::vector<Mat3> tau = read_mats(gid, "kirchhoff_stress", first, n);
    ps.kirchhoff_stress.assign(tau.begin(), tau.end());
    // APIC runs store C_p; others leave it out (older files also hold velocity_gradient,
    // which is recomputed every step and not read).
    ps.has_affine = h5::has_child(gid, "affine_velocity");
    where = "/particles/affine_velocity";
    if (ps.has_affine) ps.affine_velocity = read_mats(gid, "affine_velocity", first, n);
    where = "/particles/material";
    ps.material = h5::read_ints_rows(gid, "material", first, n);
    where = "/particles/body";
    ps.body = h5::read_ints_rows(gid, "body", first, n);
    // Files written before particle ids: rows in creation order.
    where = "/particles/id";
    if (h5::has_child(gid, "id")) {
      ps.id = h5::read_int64s_rows(gid, "id", first, n);
    } else {
      ps.id.resize(n);
      for (std::size_t p = 0; p < n; ++p) ps.id[p] = static_cast<std::int64_t>(first + p);
    }
    where = "/particles/state";
    ps.state = h5::read_doubles_rows(gid, "state", first * width, n * width);
  });
  return data;
}

template <int D>
void check_checkpoint_values(const fs::path& path, const CheckpointData<D>& data, std::size_t first_row) {
  check_values(path, data, first_row);
}

int checkpoint_dimension(const fs::path& path) {
  int dimension = 0;
  h5::Handle file = open_checkpoint(path, dimension);
  return dimension;
}

void check_readable_by_hdf5(const fs::path& path) {
  std::error_code ec;
  const auto bytes = fs::file_size(path, ec);
  const int timeout_seconds = hdf5_reading_seconds(ec ? 0.0 : static_cast<double>(bytes));
  const ChildResult r = run_in_child(
      [&](std::string& out) {
        out = "read";  // a file HDF5 cannot open is named by the parent's own open
        h5::silence_errors();
        const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
        if (file < 0) return 0;
        try {
          (void)h5_content_checksum(file);
        } catch (const std::exception& e) {
          // The traversal stopped at an object it cannot read: the objects after it were not
          // read here, and one of them may be what the parent reads first (a damaged global heap
          // under the engine attribute on which HDF5 loops without end, found by
          // cairn_fuzz_checkpoint), so the parent refuses the file at once.
          out = std::string("!") + e.what();
          return 0;
        }
        H5Fclose(file);
        return 0;
      },
      timeout_seconds);
  if (!r.timed_out && r.signal == 0 && r.exit_code == 0 && r.output.rfind('!', 0) == 0)
    refuse(path, "", "a checkpoint whose every object the HDF5 library can read",
           r.output.substr(1) + " (a damaged checkpoint)");
  if (r.signal != 0 || (!r.timed_out && (r.exit_code != 0 || r.output != "read")))
    refuse(path, "", "a checkpoint the HDF5 library can read",
           fmt::format("a file on which it crashed ({}): a damaged checkpoint", child_ending(r, timeout_seconds)));
  if (r.timed_out)
    refuse(path, "", "a checkpoint the HDF5 library can read",
           fmt::format("a file it did not finish reading in {} s: a damaged checkpoint", timeout_seconds));
}

std::string checkpoint_engine(const fs::path& path, const Comm& comm) {
  if (comm.parallel()) {  // one reading child for the job, not one per rank
    std::string engine;
    agree_on_errors(comm, [&] {
      if (comm.is_root()) engine = checkpoint_engine(path, Comm::serial());
    });
    comm.broadcast(engine, 0);
    return engine;
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) refuse(path, "", "an existing checkpoint file", "it does not exist");
  check_readable_by_hdf5(path);
  h5::Handle file;
  try {
    h5::silence_errors();
    file = h5::open_file(path);
  } catch (const std::runtime_error&) {
    refuse(path, "", "a Cairn checkpoint (an HDF5 file)",
           "a file HDF5 cannot open: not a Cairn checkpoint (not HDF5, truncated or damaged)");
  }
  const hid_t root = file.get();
  try {
    if (h5::has_attribute(root, "engine")) return h5::read_string_attribute(root, "engine");
    // Before engines had names: the FEM wrote its own format (fem/output.hpp).
    if (h5::has_attribute(root, "format") && h5::read_string_attribute(root, "format") == "cairn-fem-checkpoint")
      return "fem";
  } catch (const std::runtime_error& e) {
    refuse(path, "engine", "a string attribute naming the engine that wrote it",
           std::string(e.what()) + " (a damaged or edited checkpoint)");
  }
  return "mpm";
}

double stored_scalar(const std::map<std::string, double>& scalars, const std::string& name,
                     const std::filesystem::path& path) {
  const auto it = scalars.find(name);
  if (it == scalars.end())
    refuse(path, "/scalars/names", fmt::format("the run-loop scalar '{}' this engine restores", name),
           "a list without it (a damaged or edited checkpoint, or one of another engine)");
  return it->second;
}

long long stored_count(const std::map<std::string, double>& scalars, const std::string& name,
                       const std::filesystem::path& path) {
  const double v = stored_scalar(scalars, name, path);
  if (!(v >= 0.0 && v <= 9e15 && v == std::floor(v)))
    refuse(path, "/scalars/values (" + name + ")", "a count: a whole number 0..9e15",
           fmt::format("{} (a damaged or edited checkpoint)", v));
  return static_cast<long long>(v);
}

template void write_checkpoint<1>(const fs::path&, const CheckpointData<1>&);
template void write_checkpoint<2>(const fs::path&, const CheckpointData<2>&);
template void write_checkpoint<3>(const fs::path&, const CheckpointData<3>&);
template void write_checkpoint<1>(const fs::path&, const CheckpointData<1>&, const Particles<1>&);
template void write_checkpoint<2>(const fs::path&, const CheckpointData<2>&, const Particles<2>&);
template void write_checkpoint<3>(const fs::path&, const CheckpointData<3>&, const Particles<3>&);
template void write_checkpoint<1>(const fs::path&, const CheckpointData<1>&, const Particles<1>&, const Comm&);
template void write_checkpoint<2>(const fs::path&, const CheckpointData<2>&, const Particles<2>&, const Comm&);
template void write_checkpoint<3>(const fs::path&, const CheckpointData<3>&, const Particles<3>&, const Comm&);
template CheckpointData<1> read_checkpoint<1>(const fs::path&, const Comm&);
template CheckpointData<2> read_checkpoint<2>(const fs::path&, const Comm&);
template CheckpointData<3> read_checkpoint<3>(const fs::path&, const Comm&);
template void check_checkpoint_values<1>(const fs::path&, const CheckpointData<1>&, std::size_t);
template void check_checkpoint_values<2>(const fs::path&, const CheckpointData<2>&, std::size_t);
template void check_checkpoint_values<3>(const fs::path&, const CheckpointData<3>&, std::size_t);
template CheckpointData<1> read_checkpoint<1>(const fs::path&);
template CheckpointData<2> read_checkpoint<2>(const fs::path&);
template CheckpointData<3> read_checkpoint<3>(const fs::path&);

}  // namespace cairn
