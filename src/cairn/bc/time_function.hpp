// A factor of time for loads and velocity conditions: an expression in t (with the tri(t, w) and
// ramp(t, r) functions of bc/expression.hpp and the [constants]) times an optional
// piecewise-linear table, f(t) = expression(t) * table(t). One mechanism for the constant, ramp,
// triangular-pulse, table and free-expression loads of docs/boundary-conditions.md.
//
// Not thread safe (muParser keeps its variables in the parser): evaluate it once per step.
#pragma once

#include <memory>
#include <string>

#include "cairn/bc/expression.hpp"
#include "cairn/config/config.hpp"

namespace cairn {

class TimeFunction {
 public:
  TimeFunction() = default;
  /// Throws std::invalid_argument naming `what` when the expression does not parse or uses a
  /// position variable (x, y, z, X, Y, Z), or when the table's times do not increase.
  TimeFunction(const std::string& expression, TimeTable table, const Constants& constants,
               const std::string& what);

  double operator()(double t);
  [[nodiscard]] bool is_constant() const { return (!expression_ || expression_->is_constant()) && table_.size() < 2; }

 private:
  std::shared_ptr<Expression> expression_;  ///< null: 1
  TimeTable table_;
};

/// Piecewise-linear interpolation in a table of increasing times, constant beyond the ends;
/// 1 for an empty table.
double interpolate_table(const TimeTable& table, double t);

}  // namespace cairn
