#include "hybrid/automaton/compiled_expression.h"

#include <algorithm>
#include <cmath>
#include <optional>
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

// How a non-leaf expression is compiled: the code of `first` (left in the accumulator), then,
// if `second` is set, the code of `second` (one stack entry deeper), then one instruction.
struct OperationPlan {
  Code code;
  std::int32_t slot = 0;
  double value = 0.0;
  const Expression* first;
  const Expression* second = nullptr;
};

// Whether `e` is read straight from an instruction (a constant or a symbol).
bool IsLeaf(const Expression& e) { return e.is_constant() || e.is_symbol(); }

// `lhs ^ rhs` with rhs an integer constant in [-4, 4]: squared, cubed or PowInt; else nullopt.
std::optional<OperationPlan> SmallPowerPlan(const Expression& lhs, const Expression& rhs) {
  if (!rhs.is_constant() || std::nearbyint(rhs.constant()) != rhs.constant() ||
      !(std::abs(rhs.constant()) <= 4)) {
    return std::nullopt;
  }
  const int n = static_cast<int>(rhs.constant());
  if (n == 2 || n == 3) return OperationPlan{n == 2 ? Code::kSquare : Code::kCube, 0, 0.0, &lhs};
  return OperationPlan{Code::kPowInt, n, 0.0, &lhs};
}

// A leaf on the left of a compound right operand of + * - /: the right operand is evaluated
// first and the operation applied with the leaf taken from the instruction (exact: + and *
// commute in IEEE arithmetic, and the reversed forms compute leaf - acc and leaf / acc).
OperationPlan LeafLeftPlan(Op op, const Expression& lhs, const Expression& rhs) {
  const bool constant = lhs.is_constant();
  Code code;
  switch (op) {
    case Op::kAdd:
      code = constant ? Code::kAddC : Code::kAddV;
      break;
    case Op::kMul:
      code = constant ? Code::kMulC : Code::kMulV;
      break;
    case Op::kSub:
      code = constant ? Code::kRSubC : Code::kRSubV;
      break;
    default:
      code = constant ? Code::kRDivC : Code::kRDivV;
      break;
  }
  return {code, lhs.is_symbol() ? lhs.slot() : 0, constant ? lhs.constant() : 0.0, &rhs};
}

// The plan of the non-leaf `e`.
OperationPlan PlanOperation(const Expression& e) {
  const Expression& lhs = e.args()[0];
  if (Arity(e.op()) == 1) return {UnaryCode(e.op()), 0, 0.0, &lhs};
  const Expression& rhs = e.args()[1];
  if (e.op() == Op::kPow) {
    if (std::optional<OperationPlan> power = SmallPowerPlan(lhs, rhs)) return *power;
  }
  if (IsLeaf(lhs) && !IsLeaf(rhs) &&
      (e.op() == Op::kAdd || e.op() == Op::kMul || e.op() == Op::kSub || e.op() == Op::kDiv)) {
    return LeafLeftPlan(e.op(), lhs, rhs);
  }
  // The stack form of the op; the constant and symbol forms follow it.
  const Code base = BinaryCode(e.op());
  if (rhs.is_constant()) return {Offset(base, 1), 0, rhs.constant(), &lhs};
  if (rhs.is_symbol()) return {Offset(base, 2), rhs.slot(), 0.0, &lhs};
  return {base, 0, 0.0, &lhs, &rhs};
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
    // The operation of the non-leaf `e`, its operands first.
    const OperationPlan plan = PlanOperation(e);
    todo.push_back({Task::kAppend, nullptr, 0, {plan.code, plan.slot, plan.value}});
    if (plan.second) todo.push_back({Task::kEmit, plan.second, task.depth + 1, {}});
    todo.push_back({Task::kEmit, plan.first, task.depth, {}});
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
// The handlers of Run's instructions. Each ends by jumping to the handler of the next
// instruction. SET sets the accumulator to `expr`; PUSH pushes the accumulator on the stack, then
// sets it to `expr`; BINARY defines the three forms of a binary operation (label_s, label_c,
// label_v) computing `expr` from its operands a (left) and b (right).
#define NEXT goto* kDispatch[static_cast<std::uint32_t>((++pc)->code)]
#define SET(label, expr) \
  label:                 \
  acc = (expr);          \
  NEXT;
#define PUSH(label, expr) \
  label:                  \
  *sp++ = acc;            \
  acc = (expr);           \
  NEXT;
#define BINARY(label, expr)         \
  label##_s : {                     \
    const double b = acc;           \
    const double a = *--sp;         \
    acc = (expr);                   \
    NEXT;                           \
  }                                 \
  label##_c : {                     \
    const double a = acc;           \
    const double b = pc->value;     \
    acc = (expr);                   \
    NEXT;                           \
  }                                 \
  label##_v : {                     \
    const double a = acc;           \
    const double b = env[pc->slot]; \
    acc = (expr);                   \
    NEXT;                           \
  }

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
  goto* kDispatch[static_cast<std::uint32_t>(pc->code)];
  PUSH(push_c, pc->value)
  PUSH(push_v, env[pc->slot])
  SET(neg, -acc)
  SET(sin_, std::sin(acc))
  SET(cos_, std::cos(acc))
  SET(tan_, std::tan(acc))
  SET(exp_, std::exp(acc))
  SET(log_, std::log(acc))
  SET(sqrt_, std::sqrt(acc))
  SET(abs_, std::abs(acc))
  SET(sign_, acc > 0.0 ? 1.0 : (acc < 0.0 ? -1.0 : 0.0))
  SET(sq, acc * acc)
  SET(cube, acc * acc * acc)
  SET(powint, PowInt(acc, pc->slot))
  BINARY(add, a + b)
  BINARY(sub, a - b)
  BINARY(mul, a * b)
  BINARY(div, a / b)
  BINARY(pow, std::pow(a, b))
  BINARY(min, std::min(a, b))
  BINARY(max, std::max(a, b))
  BINARY(atan2, std::atan2(a, b))
  SET(rsub_c, pc->value - acc)
  SET(rsub_v, env[pc->slot] - acc)
  SET(rdiv_c, pc->value / acc)
  SET(rdiv_v, env[pc->slot] / acc)
store_r:
  registers[pc->slot] = acc;
  NEXT;
  PUSH(load_r, registers[pc->slot])
end:
  return acc;
}
#undef BINARY
#undef PUSH
#undef SET
#undef NEXT
#pragma GCC diagnostic pop

}  // namespace hybrid
