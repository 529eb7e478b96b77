#include "automaton/compiled_expression.h"

#include <algorithm>
#include <cmath>

namespace hybrid {

CompiledExpression::CompiledExpression() : CompiledExpression(Expression::Constant(0.0)) {}

CompiledExpression::CompiledExpression(const Expression& expression) { Emit(expression, 1); }

// Emits code leaving the value of `e` on top of the stack; `depth` is the stack height after it.
void CompiledExpression::Emit(const Expression& e, int depth) {
  max_depth_ = std::max(max_depth_, depth);
  switch (e.op()) {
    case Op::kConstant:
      code_.push_back({Op::kConstant, Operand::kConstant, -1, e.constant()});
      return;
    case Op::kSymbol:
      code_.push_back({Op::kSymbol, Operand::kSlot, e.slot(), 0.0});
      return;
    default: break;
  }
  Emit(e.args()[0], depth);
  if (Arity(e.op()) == 1) {
    code_.push_back({e.op(), Operand::kStack, -1, 0.0});
    return;
  }
  const Expression& rhs = e.args()[1];
  if (rhs.is_constant()) {
    code_.push_back({e.op(), Operand::kConstant, -1, rhs.constant()});
  } else if (rhs.is_symbol()) {
    code_.push_back({e.op(), Operand::kSlot, rhs.slot(), 0.0});
  } else {
    Emit(rhs, depth + 1);
    code_.push_back({e.op(), Operand::kStack, -1, 0.0});
  }
}

double CompiledExpression::Evaluate(const double* env) const {
  if (max_depth_ <= kMaxInlineStack) {
    double stack[kMaxInlineStack];
    return Run(env, stack);
  }
  std::vector<double> stack(max_depth_);
  return Run(env, stack.data());
}

double CompiledExpression::Run(const double* env, double* stack) const {
  double* top = stack - 1;  // points at the top element once something is pushed
  for (const Instruction& in : code_) {
    switch (in.op) {
      case Op::kConstant: *++top = in.value; continue;
      case Op::kSymbol: *++top = env[in.slot]; continue;
      case Op::kNeg: *top = -*top; continue;
      case Op::kSin: *top = std::sin(*top); continue;
      case Op::kCos: *top = std::cos(*top); continue;
      case Op::kTan: *top = std::tan(*top); continue;
      case Op::kExp: *top = std::exp(*top); continue;
      case Op::kLog: *top = std::log(*top); continue;
      case Op::kSqrt: *top = std::sqrt(*top); continue;
      case Op::kAbs: *top = std::abs(*top); continue;
      case Op::kSign: *top = *top > 0.0 ? 1.0 : (*top < 0.0 ? -1.0 : 0.0); continue;
      default: break;
    }
    const double b = in.operand == Operand::kStack      ? *top--
                     : in.operand == Operand::kConstant ? in.value
                                                        : env[in.slot];
    double& a = *top;
    switch (in.op) {
      case Op::kAdd: a = a + b; break;
      case Op::kSub: a = a - b; break;
      case Op::kMul: a = a * b; break;
      case Op::kDiv: a = a / b; break;
      case Op::kPow: a = std::pow(a, b); break;
      case Op::kMin: a = std::min(a, b); break;
      case Op::kMax: a = std::max(a, b); break;
      case Op::kAtan2: a = std::atan2(a, b); break;
      default: break;
    }
  }
  return *top;
}

}  // namespace hybrid
