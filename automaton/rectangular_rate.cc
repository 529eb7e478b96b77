#include "automaton/rectangular_rate.h"

#include <stdexcept>

namespace hybrid {

std::string RateInputName(std::string_view variable) { return std::string(variable) + "'"; }

bool IsRateInputName(std::string_view name) { return !name.empty() && name.back() == '\''; }

Expression RectangularFlow(const Range& rate, const Expression& w) {
  const Expression half = Expression::Constant(0.5);
  return Expression::Binary(
      Op::kAdd, Expression::Binary(Op::kMul, half, Expression::Binary(Op::kAdd, rate.lo, rate.hi)),
      Expression::Binary(
          Op::kMul,
          Expression::Binary(Op::kMul, half, Expression::Binary(Op::kSub, rate.hi, rate.lo)), w));
}

namespace {

// Whether `e` is `0.5 * (a OP b)`; sets a and b.
bool IsHalfOf(const Expression& e, Op op, Expression* a, Expression* b) {
  if (e.op() != Op::kMul) return false;
  const Expression& half = e.args()[0];
  const Expression& inner = e.args()[1];
  if (!half.is_constant() || half.constant() != 0.5 || inner.op() != op) return false;
  *a = inner.args()[0];
  *b = inner.args()[1];
  return true;
}

}  // namespace

std::optional<Range> AsRectangularFlow(const Expression& flow) {
  if (flow.op() != Op::kAdd) return std::nullopt;
  Range sum, difference;
  if (!IsHalfOf(flow.args()[0], Op::kAdd, &sum.lo, &sum.hi)) return std::nullopt;
  const Expression& spread = flow.args()[1];
  if (spread.op() != Op::kMul) return std::nullopt;
  const Expression& w = spread.args()[1];
  if (!w.is_symbol() || !IsRateInputName(w.symbol_name())) return std::nullopt;
  if (!IsHalfOf(spread.args()[0], Op::kSub, &difference.hi, &difference.lo)) return std::nullopt;
  if (!(sum == difference)) return std::nullopt;
  return sum;
}

int DeclareRateInput(Automaton& a, std::string_view variable) {
  const std::optional<int> slot = a.symbols().Find(variable);
  if (!slot || a.symbols()[*slot].kind != SymbolKind::kVariable) {
    throw std::invalid_argument("'" + std::string(variable) +
                                "' is not a continuous variable: only variables have rates");
  }
  const std::string name = RateInputName(variable);
  if (const std::optional<int> existing = a.symbols().Find(name)) return *existing;
  return a.AddInput(name, Range{Expression::Constant(-1), Expression::Constant(1)});
}

}  // namespace hybrid
