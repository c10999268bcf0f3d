#include "cairn/bc/expression.hpp"

#include <muParser.h>

#include <algorithm>
#include <stdexcept>

namespace cairn {

namespace {
/// Position of an assignment operator (=, +=, -=, *=, /=) in `text`, or npos. muParser would
/// store into a variable (`t=1e9` sets the time); comparisons ==, <=, >=, != are fine.
std::size_t assignment_at(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '=') continue;
    const char before = i > 0 ? text[i - 1] : ' ';
    const char after = i + 1 < text.size() ? text[i + 1] : ' ';
    if (after == '=') {  // "==": skip both characters
      ++i;
      continue;
    }
    if (before == '<' || before == '>' || before == '!') continue;
    return i;
  }
  return std::string::npos;
}

/// Triangular pulse of full width w, peak 1 at t = w / 2, zero outside 0 < t < w (seed 000
/// Sec. 3.3, tri(t, dt)).
double tri(double t, double w) {
  if (!(w > 0.0) || t <= 0.0 || t >= w) return 0.0;
  const double s = t / w;
  return s <= 0.5 ? 2.0 * s : 2.0 * (1.0 - s);
}
/// Linear ramp from 0 at t = 0 to 1 at t = r, constant afterwards.
double ramp(double t, double r) {
  if (t <= 0.0) return 0.0;
  if (!(r > 0.0) || t >= r) return 1.0;
  return t / r;
}
}  // namespace

namespace {
/// Functions and constants every input expression has.
void define_common(mu::Parser& parser, const Constants& constants) {
  parser.DefineConst("pi", 3.141592653589793238462643383279502884);
  parser.DefineFun("tri", tri);
  parser.DefineFun("ramp", ramp);
  for (const auto& [name, value] : constants) parser.DefineConst(name, value);
}

/// Set `text` on `parser` (variables defined) and evaluate it once, refusing what muParser
/// accepts but an input must not have. Returns the variables it uses.
std::vector<std::string> compile(mu::Parser& parser, const std::string& text) {
  if (const auto at = assignment_at(text); at != std::string::npos) {
    const bool compound = at > 0 && std::string("+-*/").find(text[at - 1]) != std::string::npos;
    throw std::invalid_argument("expression \"" + text + "\": the assignment '" +
                                text.substr(compound ? at - 1 : at, compound ? 2 : 1) +
                                "' is not allowed (an input expression only computes a value)");
  }
  parser.SetExpr(text);
  std::vector<std::string> used;
  for (const auto& [name, ptr] : parser.GetUsedVar()) used.push_back(name);  // also checks the syntax
  parser.Eval();
  // muParser's ',' outside a function's arguments separates expressions and Eval() returns
  // the last: "-9,81" would be 81.
  if (parser.GetNumResults() > 1)
    throw std::invalid_argument(
        "expression \"" + text + "\": ',' outside a function's arguments makes " +
        std::to_string(parser.GetNumResults()) +
        " separate expressions of which only the last would count; write one expression "
        "(a decimal point is '.')");
  return used;
}
}  // namespace

Expression::Expression(const std::string& text, const Constants& constants)
    : text_(text), parser_(std::make_unique<mu::Parser>()) {
  try {
    parser_->DefineVar("x", &x_);
    parser_->DefineVar("y", &y_);
    parser_->DefineVar("z", &z_);
    parser_->DefineVar("X", &X_);
    parser_->DefineVar("Y", &Y_);
    parser_->DefineVar("Z", &Z_);
    parser_->DefineVar("t", &t_);
    define_common(*parser_, constants);
    used_ = compile(*parser_, text);
    const auto uses = [&](const char* v) { return std::find(used_.begin(), used_.end(), v) != used_.end(); };
    constant_ = used_.empty();
    uses_x_ = uses("x") || uses("y") || uses("z");
    uses_position_ = uses_x_ || uses("X") || uses("Y") || uses("Z");
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument("expression \"" + text + "\": " + e.GetMsg());
  }
}

void Expression::check(const std::string& text, const std::vector<std::string>& variables,
                       const Constants& constants) {
  mu::Parser parser;
  std::vector<double> values(variables.size(), 0.0);
  try {
    for (std::size_t i = 0; i < variables.size(); ++i) parser.DefineVar(variables[i], &values[i]);
    define_common(parser, constants);
    compile(parser, text);
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument("expression \"" + text + "\": " + e.GetMsg());
  }
}

Expression::~Expression() = default;

double Expression::operator()(const Vec3& x, const Vec3& X, double t) {
  x_ = x[0];
  y_ = x[1];
  z_ = x[2];
  X_ = X[0];
  Y_ = X[1];
  Z_ = X[2];
  t_ = t;
  return parser_->Eval();
}

template <int D>
ExpressionVector<D>::ExpressionVector(const std::vector<std::string>& texts, const Constants& constants) {
  for (const auto& t : texts) parts_.push_back(std::make_unique<Expression>(t, constants));
}

template <int D>
bool ExpressionVector<D>::is_constant() const {
  for (const auto& p : parts_)
    if (!p->is_constant()) return false;
  return true;
}

template <int D>
Vec<D> ExpressionVector<D>::operator()(const Vec<D>& x, const Vec<D>& X, double t) {
  Vec<D> out = Vec<D>::Zero();
  const Vec3 x3 = to3<D>(x), X3 = to3<D>(X);
  for (int a = 0; a < D && a < static_cast<int>(parts_.size()); ++a) out[a] = (*parts_[a])(x3, X3, t);
  return out;
}

template class ExpressionVector<1>;
template class ExpressionVector<2>;
template class ExpressionVector<3>;

}  // namespace cairn
