#include "cairn/bc/time_function.hpp"

#include <stdexcept>

namespace cairn {

double interpolate_table(const TimeTable& table, double t) {
  if (table.empty()) return 1.0;
  if (t <= table.front().first) return table.front().second;
  if (t >= table.back().first) return table.back().second;
  std::size_t lo = 0, hi = table.size() - 1;  // table[lo].first < t < table[hi].first
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (table[mid].first <= t ? lo : hi) = mid;
  }
  const auto& [t0, v0] = table[lo];
  const auto& [t1, v1] = table[hi];
  return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
}

TimeFunction::TimeFunction(const std::string& expression, TimeTable table, const Constants& constants,
                           const std::string& what)
    : table_(std::move(table)) {
  try {
    expression_ = std::make_shared<Expression>(expression, constants);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": " + e.what());
  }
  if (expression_->uses_position())
    throw std::invalid_argument(what + ": expression \"" + expression +
                                "\" may use only t (and [constants]), not a position");
  for (std::size_t k = 1; k < table_.size(); ++k)
    if (!(table_[k].first > table_[k - 1].first))
      throw std::invalid_argument(what + ": table times must increase");
}

double TimeFunction::operator()(double t) {
  const double e = expression_ ? (*expression_)(Vec3::Zero(), Vec3::Zero(), t) : 1.0;
  return e * interpolate_table(table_, t);
}

}  // namespace cairn
