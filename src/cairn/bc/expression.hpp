// Expressions in the input (initial velocities, displacements, body forces) evaluated with
// muParser. Variables: x, y, z (current position), X, Y, Z (reference position), t (time); the
// [constants] of the input and muParser's _pi and _e are available, and `pi` as an alias.
// Time functions for loads and velocity conditions (docs/boundary-conditions.md):
//   tri(t, w)   triangular pulse of full width w: 0 outside 0 < t < w, peak 1 at t = w/2
//               (seed 000 Sec. 3.3);
//   ramp(t, r)  linear rise from 0 at t = 0 to 1 at t = r, 1 afterwards (0 before t = 0).
//
// One Expression is not safe to evaluate from two threads at once (muParser keeps its variables
// in the parser object); ExpressionVector::for_threads() makes one copy per thread.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cairn/math/types.hpp"

namespace mu {
class Parser;
}

namespace cairn {

using Constants = std::vector<std::pair<std::string, double>>;

class Expression {
 public:
  /// Throws std::invalid_argument with muParser's message on a syntax error or unknown name, and
  /// for what muParser accepts but an input must not have: an assignment (`t=1e9`, `x+=1`) and
  /// a ',' outside a function's arguments (`-9,81`, which muParser evaluates to 81).
  Expression(const std::string& text, const Constants& constants);
  ~Expression();
  /// Compile `text` with the variables `variables` (for keys with their own, such as a contact
  /// law's slide expression) and throw as the constructor does.
  static void check(const std::string& text, const std::vector<std::string>& variables,
                    const Constants& constants);
  Expression(const Expression&) = delete;
  Expression& operator=(const Expression&) = delete;

  double operator()(const Vec3& x, const Vec3& X, double t);
  /// True when the expression uses no variable (its value can be computed once).
  [[nodiscard]] bool is_constant() const { return constant_; }
  [[nodiscard]] bool uses_current_position() const { return uses_x_; }
  /// True when the expression uses a position variable (x, y, z, X, Y or Z).
  [[nodiscard]] bool uses_position() const { return uses_position_; }
  [[nodiscard]] const std::string& text() const { return text_; }
  /// The variables (x, y, z, X, Y, Z, t) the expression uses, in alphabetical order.
  [[nodiscard]] const std::vector<std::string>& used_variables() const { return used_; }

 private:
  std::string text_;
  std::unique_ptr<mu::Parser> parser_;
  double x_ = 0, y_ = 0, z_ = 0, X_ = 0, Y_ = 0, Z_ = 0, t_ = 0;
  std::vector<std::string> used_;
  bool constant_ = false;
  bool uses_x_ = false;
  bool uses_position_ = false;
};

/// D expressions forming a vector field.
template <int D>
class ExpressionVector {
 public:
  ExpressionVector() = default;
  ExpressionVector(const std::vector<std::string>& texts, const Constants& constants);
  [[nodiscard]] bool empty() const { return parts_.empty(); }
  [[nodiscard]] bool is_constant() const;
  Vec<D> operator()(const Vec<D>& x, const Vec<D>& X, double t);

 private:
  std::vector<std::unique_ptr<Expression>> parts_;
};

}  // namespace cairn
