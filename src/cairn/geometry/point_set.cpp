// CSV point files as bodies (point_set.hpp).
#include "cairn/geometry/point_set.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>

namespace cairn::geometry {

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

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

}  // namespace

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
    for (int a = 0; a < dimension; ++a) {
      x[static_cast<std::size_t>(a)] = value(axes[static_cast<std::size_t>(a)]);
      set->lo[static_cast<std::size_t>(a)] = std::min(set->lo[static_cast<std::size_t>(a)], x[static_cast<std::size_t>(a)]);
      set->hi[static_cast<std::size_t>(a)] = std::max(set->hi[static_cast<std::size_t>(a)], x[static_cast<std::size_t>(a)]);
    }
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
  }
  if (column.empty()) fail(0, "no header row (an empty file?)");
  if (set->position.empty()) fail(0, "a header but no particle rows");
  return set;
}

}  // namespace cairn::geometry
