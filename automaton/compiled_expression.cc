#include "automaton/compiled_expression.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace hybrid {

// Binary operations come in three forms: right operand on the stack (S), a constant in the
// instruction (C) or a symbol read from the environment (V). The accumulator holds the top of the
// stack; `stack` holds the entries below it.
#define HYBRID_BINARY_CODES(OP) OP##S, OP##C, OP##V
enum class CompiledExpression::Code : std::uint32_t {
  kPushC,
  kPushV,
  kNeg,
  kSin,
  kCos,
  kTan,
  kExp,
  kLog,
  kSqrt,
  kAbs,
  kSign,
  kSquare,
  kCube,
  kPowInt,  // slot holds the (small) integer exponent
  HYBRID_BINARY_CODES(kAdd),
  HYBRID_BINARY_CODES(kSub),
  HYBRID_BINARY_CODES(kMul),
  HYBRID_BINARY_CODES(kDiv),
  HYBRID_BINARY_CODES(kPow),
  HYBRID_BINARY_CODES(kMin),
  HYBRID_BINARY_CODES(kMax),
  HYBRID_BINARY_CODES(kAtan2),
  kRSubC,  // acc = value - acc
  kRSubV,  // acc = env[slot] - acc
  kRDivC,
  kRDivV,
  kStoreR,  // registers[slot] = acc (a shared subexpression, computed once)
  kLoadR,   // push acc; acc = registers[slot]
  kEnd,
};
#undef HYBRID_BINARY_CODES

namespace {

using Code = CompiledExpression::Code;

Code UnaryCode(Op op) {
  switch (op) {
    case Op::kNeg:
      return Code::kNeg;
    case Op::kSin:
      return Code::kSin;
    case Op::kCos:
      return Code::kCos;
    case Op::kTan:
      return Code::kTan;
    case Op::kExp:
      return Code::kExp;
    case Op::kLog:
      return Code::kLog;
    case Op::kSqrt:
      return Code::kSqrt;
    case Op::kAbs:
      return Code::kAbs;
    case Op::kSign:
      return Code::kSign;
    default:
      throw std::logic_error("compiling an expression: not a unary operation");
  }
}

// The stack form of a binary op; the constant and symbol forms follow it.
Code BinaryCode(Op op) {
  switch (op) {
    case Op::kAdd:
      return Code::kAddS;
    case Op::kSub:
      return Code::kSubS;
    case Op::kMul:
      return Code::kMulS;
    case Op::kDiv:
      return Code::kDivS;
    case Op::kPow:
      return Code::kPowS;
    case Op::kMin:
      return Code::kMinS;
    case Op::kMax:
      return Code::kMaxS;
    case Op::kAtan2:
      return Code::kAtan2S;
    default:
      throw std::logic_error("compiling an expression: not a binary operation");
  }
}

Code Offset(Code base, int k) {
  return static_cast<Code>(static_cast<std::uint32_t>(base) + static_cast<std::uint32_t>(k));
}

double PowInt(double x, int n) {
  double r = 1.0;
  for (int i = 0; i < std::abs(n); ++i) r *= x;
  return n < 0 ? 1.0 / r : r;
}

}  // namespace

CompiledExpression::CompiledExpression() : CompiledExpression(Expression::Constant(0.0)) {}

CompiledExpression::CompiledExpression(const Expression& expression) {
  // Count the parents of every node of the DAG (children are visited once, on the first visit);
  // nodes with several parents get a register.
  std::unordered_map<const void*, int> parents;
  std::vector<const Expression*> todo = {&expression};
  while (!todo.empty()) {
    const Expression* e = todo.back();
    todo.pop_back();
    for (const Expression& a : e->args()) {
      if (a.is_constant() || a.is_symbol()) continue;
      if (parents[a.node_id()]++ == 0) todo.push_back(&a);
    }
  }
  for (const auto& [id, count] : parents) {
    if (count > 1) registers_.emplace(id, -1);
  }
  Emit(expression);
  code_.push_back({Code::kEnd, 0, 0.0});
  num_registers_ = next_register_;
  registers_.clear();
}

// Emits code that leaves the value of `root` in the accumulator. The work is kept on a heap
// stack of tasks (no recursion, whatever the depth): emitting a subexpression with `depth` stack
// entries in use (accumulator included) once its value is there, appending an instruction, or
// storing a shared subexpression's value into its register. Tasks run in the reverse of the
// order they are pushed.
void CompiledExpression::Emit(const Expression& root) {
  struct Task {
    enum Kind { kEmit, kAppend, kStore } kind;
    const Expression* e;
    int depth;
    Instruction instruction;
  };
  std::vector<Task> todo = {{Task::kEmit, &root, 1, {}}};
  auto emit = [&](const Expression& e, int depth) { todo.push_back({Task::kEmit, &e, depth, {}}); };
  auto append = [&](Code code, std::int32_t slot, double value) {
    todo.push_back({Task::kAppend, nullptr, 0, {code, slot, value}});
  };
  // The operation of the non-leaf `e`, its arguments first.
  auto operation = [&](const Expression& e, int depth) {
    const Expression& lhs = e.args()[0];
    if (Arity(e.op()) == 1) {
      append(UnaryCode(e.op()), 0, 0.0);
      emit(lhs, depth);
      return;
    }
    const Expression& rhs = e.args()[1];
    if (e.op() == Op::kPow && rhs.is_constant() &&
        std::nearbyint(rhs.constant()) == rhs.constant() && std::abs(rhs.constant()) <= 4) {
      const int n = static_cast<int>(rhs.constant());
      if (n == 2 || n == 3) {
        append(n == 2 ? Code::kSquare : Code::kCube, 0, 0.0);
      } else {
        append(Code::kPowInt, n, 0.0);
      }
      emit(lhs, depth);
      return;
    }
    const bool leaf_left = lhs.is_constant() || lhs.is_symbol();
    if (leaf_left && !rhs.is_constant() && !rhs.is_symbol() &&
        (e.op() == Op::kAdd || e.op() == Op::kMul || e.op() == Op::kSub || e.op() == Op::kDiv)) {
      // A leaf on the left of a compound right operand: evaluate the right operand first and
      // apply the operation with the leaf taken from the instruction (exact: + and * commute in
      // IEEE arithmetic, and the reversed forms compute leaf - acc and leaf / acc).
      Code code;
      switch (e.op()) {
        case Op::kAdd:
          code = lhs.is_constant() ? Code::kAddC : Code::kAddV;
          break;
        case Op::kMul:
          code = lhs.is_constant() ? Code::kMulC : Code::kMulV;
          break;
        case Op::kSub:
          code = lhs.is_constant() ? Code::kRSubC : Code::kRSubV;
          break;
        default:
          code = lhs.is_constant() ? Code::kRDivC : Code::kRDivV;
          break;
      }
      append(code, lhs.is_symbol() ? lhs.slot() : 0, lhs.is_constant() ? lhs.constant() : 0.0);
      emit(rhs, depth);
      return;
    }
    const Code base = BinaryCode(e.op());
    if (rhs.is_constant()) {
      append(Offset(base, 1), 0, rhs.constant());
    } else if (rhs.is_symbol()) {
      append(Offset(base, 2), rhs.slot(), 0.0);
    } else {
      append(base, 0, 0.0);
      emit(rhs, depth + 1);
    }
    emit(lhs, depth);
  };
  while (!todo.empty()) {
    const Task task = todo.back();
    todo.pop_back();
    if (task.kind == Task::kAppend) {
      code_.push_back(task.instruction);
      continue;
    }
    if (task.kind == Task::kStore) {
      const int r = next_register_++;
      registers_.at(task.e->node_id()) = r;
      code_.push_back({Code::kStoreR, r, 0.0});
      continue;
    }
    const Expression& e = *task.e;
    max_depth_ = std::max(max_depth_, task.depth);
    if (e.is_constant()) {
      code_.push_back({Code::kPushC, 0, e.constant()});
      continue;
    }
    if (e.is_symbol()) {
      code_.push_back({Code::kPushV, e.slot(), 0.0});
      continue;
    }
    // A shared subexpression: computed the first time, then read from its register.
    auto shared = registers_.find(e.node_id());
    if (shared != registers_.end()) {
      if (shared->second >= 0) {
        code_.push_back({Code::kLoadR, shared->second, 0.0});
        continue;
      }
      todo.push_back({Task::kStore, &e, task.depth, {}});
    }
    operation(e, task.depth);
  }
}

double CompiledExpression::Evaluate(const double* env) const {
  // The value stack, then the registers, in one buffer.
  const int size = max_depth_ + num_registers_;
  if (size <= kMaxInlineStack) {
    double buffer[kMaxInlineStack];
    return Run(env, buffer, buffer + max_depth_);
  }
  std::vector<double> buffer(size);
  return Run(env, buffer.data(), buffer.data() + max_depth_);
}

// Direct threading takes the addresses of labels, a GCC/Clang extension that -Wpedantic reports.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wgnu-label-as-value"
#endif
double CompiledExpression::Run(const double* env, double* stack, double* registers) const {
  // Direct threading (GCC/Clang "labels as values"): each handler jumps straight to the next.
  static const void* const kDispatch[] = {
      &&push_c,  &&push_v,  &&neg,    &&sin_,   &&cos_,   &&tan_,   &&exp_,    &&log_,   &&sqrt_,
      &&abs_,    &&sign_,   &&sq,     &&cube,   &&powint, &&add_s,  &&add_c,   &&add_v,  &&sub_s,
      &&sub_c,   &&sub_v,   &&mul_s,  &&mul_c,  &&mul_v,  &&div_s,  &&div_c,   &&div_v,  &&pow_s,
      &&pow_c,   &&pow_v,   &&min_s,  &&min_c,  &&min_v,  &&max_s,  &&max_c,   &&max_v,  &&atan2_s,
      &&atan2_c, &&atan2_v, &&rsub_c, &&rsub_v, &&rdiv_c, &&rdiv_v, &&store_r, &&load_r, &&end};
  static_assert(sizeof(kDispatch) / sizeof(kDispatch[0]) ==
                static_cast<std::size_t>(Code::kEnd) + 1);
  const Instruction* pc = code_.data();
  double acc = 0.0;
  double* sp = stack;  // next free entry below the accumulator
#define NEXT goto* kDispatch[static_cast<std::uint32_t>((++pc)->code)]
#define BINARY(label, expr_s, expr_c, expr_v) \
  label##_s : {                               \
    const double b = acc;                     \
    const double a = *--sp;                   \
    acc = (expr_s);                           \
    NEXT;                                     \
  }                                           \
  label##_c : {                               \
    const double a = acc;                     \
    const double b = pc->value;               \
    acc = (expr_c);                           \
    NEXT;                                     \
  }                                           \
  label##_v : {                               \
    const double a = acc;                     \
    const double b = env[pc->slot];           \
    acc = (expr_v);                           \
    NEXT;                                     \
  }
#define BINARY_SAME(label, expr) BINARY(label, expr, expr, expr)

  goto* kDispatch[static_cast<std::uint32_t>(pc->code)];
push_c:
  *sp++ = acc;
  acc = pc->value;
  NEXT;
push_v:
  *sp++ = acc;
  acc = env[pc->slot];
  NEXT;
neg:
  acc = -acc;
  NEXT;
sin_:
  acc = std::sin(acc);
  NEXT;
cos_:
  acc = std::cos(acc);
  NEXT;
tan_:
  acc = std::tan(acc);
  NEXT;
exp_:
  acc = std::exp(acc);
  NEXT;
log_:
  acc = std::log(acc);
  NEXT;
sqrt_:
  acc = std::sqrt(acc);
  NEXT;
abs_:
  acc = std::abs(acc);
  NEXT;
sign_:
  acc = acc > 0.0 ? 1.0 : (acc < 0.0 ? -1.0 : 0.0);
  NEXT;
sq:
  acc = acc * acc;
  NEXT;
cube:
  acc = acc * acc * acc;
  NEXT;
powint:
  acc = PowInt(acc, pc->slot);
  NEXT;
  BINARY_SAME(add, a + b)
  BINARY_SAME(sub, a - b)
  BINARY_SAME(mul, a * b)
  BINARY_SAME(div, a / b)
  BINARY_SAME(pow, std::pow(a, b))
  BINARY_SAME(min, std::min(a, b))
  BINARY_SAME(max, std::max(a, b))
  BINARY_SAME(atan2, std::atan2(a, b))
rsub_c:
  acc = pc->value - acc;
  NEXT;
rsub_v:
  acc = env[pc->slot] - acc;
  NEXT;
rdiv_c:
  acc = pc->value / acc;
  NEXT;
rdiv_v:
  acc = env[pc->slot] / acc;
  NEXT;
store_r:
  registers[pc->slot] = acc;
  NEXT;
load_r:
  *sp++ = acc;
  acc = registers[pc->slot];
  NEXT;
end:
  return acc;
#undef BINARY_SAME
#undef BINARY
#undef NEXT
}
#pragma GCC diagnostic pop

}  // namespace hybrid
