#include "cairn/util/cpu_quota.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cairn {
namespace {

namespace fs = std::filesystem;

/// The first line of a file, or nothing.
std::optional<std::string> first_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  return line;
}

std::optional<double> number(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    return used > 0 ? std::optional<double>(v) : std::nullopt;
  } catch (...) {
    return std::nullopt;
  }
}

/// v2 `cpu.max`: "max PERIOD" (no limit) or "QUOTA PERIOD".
std::optional<double> limit_v2(const fs::path& dir) {
  const auto line = first_line(dir / "cpu.max");
  if (!line) return std::nullopt;
  std::istringstream in(*line);
  std::string quota, period;
  if (!(in >> quota >> period) || quota == "max") return std::nullopt;
  const auto q = number(quota), p = number(period);
  if (!q || !p || *q <= 0.0 || *p <= 0.0) return std::nullopt;
  return *q / *p;
}

/// v1 `cpu.cfs_quota_us` (-1: no limit) over `cpu.cfs_period_us`.
std::optional<double> limit_v1(const fs::path& dir) {
  const auto quota = first_line(dir / "cpu.cfs_quota_us"), period = first_line(dir / "cpu.cfs_period_us");
  if (!quota || !period) return std::nullopt;
  const auto q = number(*quota), p = number(*period);
  if (!q || !p || *q <= 0.0 || *p <= 0.0) return std::nullopt;
  return *q / *p;
}

/// best becomes the smaller of best and limit (either may be absent).
void keep_smaller(std::optional<double>& best, const std::optional<double>& limit) {
  if (limit) best = best ? std::min(*best, *limit) : *limit;
}

/// The smallest limit from `mount / group` up to `mount`.
template <class Limit>
std::optional<double> smallest_up_to_root(const fs::path& mount, const std::string& group, Limit&& limit) {
  std::optional<double> best;
  fs::path rel = fs::path(group).relative_path();
  for (;;) {
    keep_smaller(best, limit(mount / rel));
    if (rel.empty()) break;
    rel = rel.parent_path();
  }
  return best;
}

}  // namespace

std::optional<double> cgroup_cpu_limit(const fs::path& proc_cgroup, const fs::path& cgroup_root) {
  std::ifstream in(proc_cgroup);
  if (!in) return std::nullopt;
  std::optional<double> best;
  // Lines "ID:CONTROLLERS:PATH": "0::PATH" is the unified (v2) hierarchy; a v1 line whose
  // comma-separated controllers include "cpu" names the group of the CPU controller.
  for (std::string line; std::getline(in, line);) {
    const auto c1 = line.find(':');
    const auto c2 = c1 == std::string::npos ? std::string::npos : line.find(':', c1 + 1);
    if (c2 == std::string::npos) continue;
    const std::string controllers = line.substr(c1 + 1, c2 - c1 - 1), group = line.substr(c2 + 1);
    if (controllers.empty()) {
      if (fs::exists(cgroup_root / "cgroup.controllers"))
        keep_smaller(best, smallest_up_to_root(cgroup_root, group, limit_v2));
      continue;
    }
    std::vector<std::string> names;
    std::istringstream list(controllers);
    for (std::string name; std::getline(list, name, ',');) names.push_back(name);
    if (std::find(names.begin(), names.end(), "cpu") == names.end()) continue;
    // The v1 CPU hierarchy is mounted as cpu, cpu,cpuacct or cpuacct,cpu (a link to one).
    for (const char* mount : {"cpu", "cpu,cpuacct", "cpuacct,cpu"}) {
      if (!fs::is_directory(cgroup_root / mount)) continue;
      keep_smaller(best, smallest_up_to_root(cgroup_root / mount, group, limit_v1));
      break;
    }
  }
  return best;
}

int threads_for_cpu_limit(double cpus) {
  return std::max(1, static_cast<int>(std::ceil(cpus - 1e-9)));
}

}  // namespace cairn
