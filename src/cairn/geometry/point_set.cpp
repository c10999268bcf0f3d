// CSV point files as bodies (point_set.hpp).
#include "cairn/geometry/point_set.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <hdf5.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <stdexcept>

#include "cairn/geometry/text.hpp"

#include "cairn/io/hdf5_util.hpp"
#include "cairn/util/child_process.hpp"

namespace cairn::geometry {

namespace {

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

void add_bounds(PointSet& set, const std::array<double, 3>& x) {
  for (std::size_t a = 0; a < static_cast<std::size_t>(set.dimension); ++a) {
    set.lo[a] = std::min(set.lo[a], x[a]);
    set.hi[a] = std::max(set.hi[a], x[a]);
  }
}

std::shared_ptr<const PointSet> read_point_h5(const std::string& path, int dimension) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument(fmt::format("point file '{}': {}", path, what));
  };
  auto set = std::make_shared<PointSet>();
  set->file = path;
  set->dimension = dimension;
  for (auto& v : set->lo) v = std::numeric_limits<double>::infinity();
  for (auto& v : set->hi) v = -std::numeric_limits<double>::infinity();
  const auto d = static_cast<std::size_t>(dimension);
  try {
    const h5::Handle file = h5::open_file(path);
    const hid_t root = file.get();
    auto has = [&](const char* name) { return H5Lexists(root, name, H5P_DEFAULT) > 0; };
    for (const char* need : {"position", "volume"})
      if (!has(need)) fail(fmt::format("no dataset '{}' (datasets: position n x {}, volume n; optional velocity, "
                                       "temperature)",
                                       need, dimension));
    const auto shape = h5::dataset_shape(root, "position");
    if (shape.size() != 2 || shape[1] != d || shape[0] == 0)
      fail(fmt::format("dataset 'position' of shape [{}], not n x {} with n > 0", fmt::join(shape, ", "), dimension));
    const std::size_t n = shape[0];
    auto read = [&](const char* name, std::size_t cols) {
      const std::vector<double> v =
          h5::read_doubles(root, name, cols ? std::vector<std::size_t>{n, cols} : std::vector<std::size_t>{n});
      for (std::size_t i = 0; i < v.size(); ++i)
        if (!std::isfinite(v[i])) fail(fmt::format("dataset '{}', entry {}: not a finite number", name, i));
      return v;
    };
    const std::vector<double> position = read("position", d), volume = read("volume", 0);
    const std::vector<double> velocity = has("velocity") ? read("velocity", d) : std::vector<double>{};
    const std::vector<double> temperature = has("temperature") ? read("temperature", 0) : std::vector<double>{};
    const std::size_t n_stress = d == 3 ? 6 : 3;  // Voigt xx, yy, zz, yz, xz, xy; 2D xx, yy, xy
    if (has("stress")) {
      const auto s_shape = h5::dataset_shape(root, "stress");
      if (s_shape.size() != 2 || s_shape[0] != n || s_shape[1] != n_stress)
        fail(fmt::format("dataset 'stress' of shape [{}], not {} x {} ({})", fmt::join(s_shape, ", "), n, n_stress,
                         d == 3 ? "xx, yy, zz, yz, xz, xy" : "xx, yy, xy"));
    }
    const std::vector<double> stress = has("stress") ? read("stress", n_stress) : std::vector<double>{};
    for (std::size_t i = 0; i < n; ++i) {
      std::array<double, 3> x{0.0, 0.0, 0.0};
      for (std::size_t a = 0; a < d; ++a) x[a] = position[i * d + a];
      if (!(volume[i] > 0.0)) fail(fmt::format("dataset 'volume', entry {}: {} is not above zero", i, volume[i]));
      add_bounds(*set, x);
      set->position.push_back(x);
      set->volume.push_back(volume[i]);
      set->total_volume += volume[i];
      if (!velocity.empty()) {
        std::array<double, 3> v{0.0, 0.0, 0.0};
        for (std::size_t a = 0; a < d; ++a) v[a] = velocity[i * d + a];
        set->velocity.push_back(v);
      }
      if (!temperature.empty()) set->temperature.push_back(temperature[i]);
      if (!stress.empty()) {
        const double* t = &stress[i * n_stress];
        set->stress.push_back(d == 3 ? std::array<double, 6>{t[0], t[1], t[2], t[3], t[4], t[5]}
                                     : std::array<double, 6>{t[0], t[1], 0.0, 0.0, 0.0, t[2]});
      }
    }
  } catch (const std::runtime_error& e) {  // HDF5 failures (h5:: helpers)
    fail(e.what());
  } catch (const std::bad_alloc&) {
    // A damaged dataset size: the reading child's memory is limited (read_point_h5_in_child).
    std::error_code ec;
    fail(fmt::format("its datasets' sizes ask for more memory than a point file of {} bytes may take: a damaged size",
                     std::filesystem::file_size(path, ec)));
  } catch (const std::length_error&) {
    fail("a dataset's size is larger than any array can hold: a damaged size");
  }
  return set;
}

std::shared_ptr<const PointSet> read_point_csv(const std::string& path, int dimension) {
  auto fail = [&](long line, const std::string& what) -> void {
    throw std::invalid_argument(line > 0 ? fmt::format("point file '{}', line {}: {}", path, line, what)
                                         : fmt::format("point file '{}': {}", path, what));
  };
  std::ifstream in(path);
  if (!in) fail(0, "cannot open it");
  auto set = std::make_shared<PointSet>();
  set->file = path;
  set->dimension = dimension;
  const std::vector<std::string> axes{"x", "y", "z"};
  std::vector<std::string> allowed(axes.begin(), axes.begin() + dimension);
  allowed.push_back("volume");
  for (int a = 0; a < dimension; ++a) allowed.push_back("v" + axes[static_cast<std::size_t>(a)]);
  allowed.push_back("temperature");
  // Initial stress, in Voigt order (xx, yy, zz, yz, xz, xy); 2D: xx, yy, xy.
  const std::vector<std::string> stress_names =
      dimension == 3 ? std::vector<std::string>{"sxx", "syy", "szz", "syz", "sxz", "sxy"}
                     : std::vector<std::string>{"sxx", "syy", "sxy"};
  allowed.insert(allowed.end(), stress_names.begin(), stress_names.end());
  std::map<std::string, std::size_t> column;
  std::size_t n_columns = 0;
  std::string line;
  long number = 0;
  for (auto& v : set->lo) v = std::numeric_limits<double>::infinity();
  for (auto& v : set->hi) v = -std::numeric_limits<double>::infinity();
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const std::vector<std::string> f = fields(t);
    if (column.empty()) {
      for (std::size_t i = 0; i < f.size(); ++i) {
        if (std::find(allowed.begin(), allowed.end(), f[i]) == allowed.end())
          fail(number, fmt::format("unknown column '{}' in the header (columns in {}D: {})", f[i], dimension,
                                   fmt::join(allowed, ", ")));
        if (!column.emplace(f[i], i).second) fail(number, fmt::format("column '{}' twice in the header", f[i]));
      }
      for (int a = 0; a <= dimension; ++a) {
        const std::string& need = a < dimension ? axes[static_cast<std::size_t>(a)] : "volume";
        if (!column.count(need)) fail(number, fmt::format("the header has no column '{}'", need));
      }
      int velocities = 0;
      for (int a = 0; a < dimension; ++a) velocities += column.count("v" + axes[static_cast<std::size_t>(a)]) ? 1 : 0;
      if (velocities != 0 && velocities != dimension)
        fail(number, fmt::format("{} of the {} velocity columns (all or none)", velocities, dimension));
      std::size_t stresses = 0;
      for (const auto& name : stress_names) stresses += column.count(name);
      if (stresses != 0 && stresses != stress_names.size())
        fail(number, fmt::format("{} of the {} stress columns {} (all or none)", stresses, stress_names.size(),
                                 fmt::join(stress_names, ", ")));
      n_columns = f.size();
      continue;
    }
    if (f.size() != n_columns) fail(number, fmt::format("{} fields, the header has {}", f.size(), n_columns));
    auto value = [&](const std::string& name) {
      const std::string& text = f[column.at(name)];
      double v = 0.0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
        fail(number, fmt::format("column '{}': '{}' is not a finite number", name, text));
      return v;
    };
    std::array<double, 3> x{0.0, 0.0, 0.0};
    for (int a = 0; a < dimension; ++a) x[static_cast<std::size_t>(a)] = value(axes[static_cast<std::size_t>(a)]);
    add_bounds(*set, x);
    const double vol = value("volume");
    if (!(vol > 0.0)) fail(number, fmt::format("volume {} is not above zero", vol));
    set->position.push_back(x);
    set->volume.push_back(vol);
    set->total_volume += vol;
    if (column.count("vx")) {
      std::array<double, 3> v{0.0, 0.0, 0.0};
      for (int a = 0; a < dimension; ++a) v[static_cast<std::size_t>(a)] = value("v" + axes[static_cast<std::size_t>(a)]);
      set->velocity.push_back(v);
    }
    if (column.count("temperature")) set->temperature.push_back(value("temperature"));
    if (column.count("sxx")) {
      std::array<double, 6> t{0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
      const std::array<std::size_t, 6> slot{0, 1, 2, 3, 4, 5}, planar{0, 1, 5, 0, 0, 0};
      for (std::size_t i = 0; i < stress_names.size(); ++i)
        t[dimension == 3 ? slot[i] : planar[i]] = value(stress_names[i]);
      set->stress.push_back(t);
    }
  }
  if (column.empty()) fail(0, "no header row (an empty file?)");
  if (set->position.empty()) fail(0, "a header but no particle rows");
  return set;
}

}  // namespace

namespace {

/// read_point_h5 in a child process: HDF5 1.10 crashes on some damaged files (as on damaged
/// checkpoints, io/checkpoint.hpp) and keeps about 2 MB of every damaged file it fails on (found
/// by cairn_fuzz_geometry); the child sends back the points or the error.
std::shared_ptr<const PointSet> read_point_h5_in_child(const std::string& path, int dimension) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  const double bytes = ec ? 0.0 : static_cast<double>(size);
  const int timeout_seconds = hdf5_reading_seconds(bytes);
  const ChildResult r = run_in_child(
      [&](std::string& out) {
        limit_address_space((1u << 30) + 200.0 * bytes);
        auto put = [&](const void* p, std::size_t n) { put_bytes(out, p, n); };
        try {
          const auto set = read_point_h5(path, dimension);
          out.assign(1, 'P');  // (not `out = "P"`: GCC 12 warns falsely on a one-character literal there)
          const std::uint64_t n[5] = {set->position.size(), set->volume.size(), set->velocity.size(),
                                      set->temperature.size(), set->stress.size()};
          put(n, sizeof n);
          put(set->position.data(), n[0] * sizeof set->position[0]);
          put(set->volume.data(), n[1] * sizeof(double));
          put(set->velocity.data(), n[2] * sizeof set->velocity[0]);
          put(set->temperature.data(), n[3] * sizeof(double));
          put(set->stress.data(), n[4] * sizeof set->stress[0]);
          put(set->lo.data(), sizeof set->lo);
          put(set->hi.data(), sizeof set->hi);
          put(&set->total_volume, sizeof set->total_volume);
        } catch (const std::exception& e) {
          out = std::string("E") + e.what();
        }
        return 0;
      },
      timeout_seconds);
  if (r.signal != 0 || r.timed_out || r.exit_code != 0 || r.output.empty())
    throw std::invalid_argument(fmt::format("point file '{}': the HDF5 library failed on it ({}): a damaged file", path,
                                            child_ending(r, timeout_seconds)));
  if (r.output[0] == 'E') throw std::invalid_argument(r.output.substr(1));
  AnswerReader answer(r.output, 1);
  auto take = [&](void* p, std::size_t n) {
    if (!answer.take(p, n)) throw std::invalid_argument(fmt::format("point file '{}': a short answer", path));
  };
  auto set = std::make_shared<PointSet>();
  set->file = path;
  set->dimension = dimension;
  std::uint64_t n[5];
  take(n, sizeof n);
  for (std::uint64_t k : n)
    if (k > r.output.size()) throw std::invalid_argument(fmt::format("point file '{}': a bad answer", path));
  set->position.resize(n[0]);
  take(set->position.data(), n[0] * sizeof set->position[0]);
  set->volume.resize(n[1]);
  take(set->volume.data(), n[1] * sizeof(double));
  set->velocity.resize(n[2]);
  take(set->velocity.data(), n[2] * sizeof set->velocity[0]);
  set->temperature.resize(n[3]);
  take(set->temperature.data(), n[3] * sizeof(double));
  set->stress.resize(n[4]);
  take(set->stress.data(), n[4] * sizeof set->stress[0]);
  take(set->lo.data(), sizeof set->lo);
  take(set->hi.data(), sizeof set->hi);
  take(&set->total_volume, sizeof set->total_volume);
  return set;
}

}  // namespace

std::shared_ptr<const PointSet> read_point_file(const std::string& path, int dimension) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".h5" || ext == ".hdf5" ? read_point_h5_in_child(path, dimension) : read_point_csv(path, dimension);
}

}  // namespace cairn::geometry
