#include "automaton/expression.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace hybrid {

struct Expression::Node {
  Op op = Op::kConstant;
  double value = 0.0;
  std::string name;
  int slot = -1;
  std::vector<Expression> args;
};

namespace {

struct FunctionSpelling {
  Op op;
  std::string_view name;
};

constexpr FunctionSpelling kFunctions[] = {
    {Op::kSin, "sin"}, {Op::kCos, "cos"},   {Op::kTan, "tan"},     {Op::kExp, "exp"},
    {Op::kLog, "log"}, {Op::kSqrt, "sqrt"}, {Op::kAbs, "abs"},     {Op::kSign, "sign"},
    {Op::kMin, "min"}, {Op::kMax, "max"},   {Op::kAtan2, "atan2"},
};

double SignOf(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }

double ApplyUnary(Op op, double a) {
  switch (op) {
    case Op::kNeg:
      return -a;
    case Op::kSin:
      return std::sin(a);
    case Op::kCos:
      return std::cos(a);
    case Op::kTan:
      return std::tan(a);
    case Op::kExp:
      return std::exp(a);
    case Op::kLog:
      return std::log(a);
    case Op::kSqrt:
      return std::sqrt(a);
    case Op::kAbs:
      return std::abs(a);
    case Op::kSign:
      return SignOf(a);
    default:
      throw std::logic_error("ApplyUnary: not a unary op");
  }
}

double ApplyBinary(Op op, double a, double b) {
  switch (op) {
    case Op::kAdd:
      return a + b;
    case Op::kSub:
      return a - b;
    case Op::kMul:
      return a * b;
    case Op::kDiv:
      return a / b;
    case Op::kPow:
      return std::pow(a, b);
    case Op::kMin:
      return std::min(a, b);
    case Op::kMax:
      return std::max(a, b);
    case Op::kAtan2:
      return std::atan2(a, b);
    default:
      throw std::logic_error("ApplyBinary: not a binary op");
  }
}

// Precedence levels for printing: sums < products < prefix minus < power < atoms.
int Precedence(const Expression& e) {
  switch (e.op()) {
    case Op::kAdd:
    case Op::kSub:
      return 1;
    case Op::kMul:
    case Op::kDiv:
      return 2;
    case Op::kNeg:
      return 3;
    case Op::kPow:
      return 4;
    case Op::kConstant:
      return e.constant() < 0.0 || std::signbit(e.constant()) ? 3 : 5;
    default:
      return 5;
  }
}

std::string_view InfixSpelling(Op op) {
  switch (op) {
    case Op::kAdd:
      return " + ";
    case Op::kSub:
      return " - ";
    case Op::kMul:
      return " * ";
    case Op::kDiv:
      return " / ";
    case Op::kPow:
      return "^";
    default:
      return "?";
  }
}

void Print(const Expression& e, std::string* out);

void PrintWrapped(const Expression& e, bool wrap, std::string* out) {
  if (wrap) out->push_back('(');
  Print(e, out);
  if (wrap) out->push_back(')');
}

void Print(const Expression& e, std::string* out) {
  switch (e.op()) {
    case Op::kConstant:
      out->append(FormatNumber(e.constant()));
      return;
    case Op::kSymbol:
      out->append(e.symbol_name());
      return;
    case Op::kNeg:
      out->push_back('-');
      PrintWrapped(e.args()[0], Precedence(e.args()[0]) < 3, out);
      return;
    case Op::kAdd:
    case Op::kSub:
    case Op::kMul:
    case Op::kDiv: {
      const int p = Precedence(e);
      PrintWrapped(e.args()[0], Precedence(e.args()[0]) < p, out);
      out->append(InfixSpelling(e.op()));
      // Left-associative: an equal-precedence right operand needs parentheses.
      PrintWrapped(e.args()[1], Precedence(e.args()[1]) <= p, out);
      return;
    }
    case Op::kPow:
      // Right-associative and binding tighter than prefix minus: -x^2 is -(x^2).
      PrintWrapped(e.args()[0], Precedence(e.args()[0]) <= 4, out);
      out->push_back('^');
      PrintWrapped(e.args()[1], Precedence(e.args()[1]) < 3, out);
      return;
    default: {
      out->append(*FunctionName(e.op()));
      out->push_back('(');
      for (size_t i = 0; i < e.args().size(); ++i) {
        if (i > 0) out->append(", ");
        Print(e.args()[i], out);
      }
      out->push_back(')');
    }
  }
}

// Simplifying constructors used by Derivative(): fold 0 and 1 and constant operands.
Expression SAdd(const Expression& a, const Expression& b) {
  if (a.is_constant() && a.constant() == 0.0) return b;
  if (b.is_constant() && b.constant() == 0.0) return a;
  if (a.is_constant() && b.is_constant()) return Expression::Constant(a.constant() + b.constant());
  return a + b;
}
Expression SNeg(const Expression& a) {
  if (a.is_constant()) return Expression::Constant(-a.constant());
  if (a.op() == Op::kNeg) return a.args()[0];
  return -a;
}
Expression SSub(const Expression& a, const Expression& b) {
  if (b.is_constant() && b.constant() == 0.0) return a;
  if (a.is_constant() && a.constant() == 0.0) return SNeg(b);
  if (a.is_constant() && b.is_constant()) return Expression::Constant(a.constant() - b.constant());
  return a - b;
}
Expression SMul(const Expression& a, const Expression& b) {
  if ((a.is_constant() && a.constant() == 0.0) || (b.is_constant() && b.constant() == 0.0)) {
    return Expression::Constant(0.0);
  }
  if (a.is_constant() && a.constant() == 1.0) return b;
  if (b.is_constant() && b.constant() == 1.0) return a;
  if (a.is_constant() && b.is_constant()) return Expression::Constant(a.constant() * b.constant());
  return a * b;
}
Expression SDiv(const Expression& a, const Expression& b) {
  if (a.is_constant() && a.constant() == 0.0) return a;
  if (b.is_constant() && b.constant() == 1.0) return a;
  return a / b;
}
Expression Call(Op op, const Expression& a) { return Expression::Unary(op, a); }
Expression Call(Op op, const Expression& a, const Expression& b) {
  return Expression::Binary(op, a, b);
}

void CollectSlots(const Expression& e, std::vector<int>* slots) {
  if (e.is_symbol()) {
    slots->push_back(e.slot());
    return;
  }
  for (const Expression& a : e.args()) CollectSlots(a, slots);
}

AffineForm Scale(AffineForm f, double k) {
  f.constant *= k;
  for (auto& [slot, c] : f.terms) c *= k;
  std::erase_if(f.terms, [](const auto& t) { return t.second == 0.0; });
  return f;
}

AffineForm Combine(const AffineForm& a, const AffineForm& b, double sign) {
  std::map<int, double> terms(a.terms.begin(), a.terms.end());
  for (const auto& [slot, c] : b.terms) terms[slot] += sign * c;
  AffineForm r;
  r.constant = a.constant + sign * b.constant;
  for (const auto& [slot, c] : terms) {
    if (c != 0.0) r.terms.emplace_back(slot, c);
  }
  return r;
}

/// FoldConstants() of `e`, with the value of `e` when it reads no symbol. A symbol-free subtree
/// whose value is not finite stays unfolded but still passes its value up, so that a finite
/// result above it (`sign(log(0))`, `min(1 / 0, 2)`) folds like any other symbol-free subtree.
using FoldMemo = std::unordered_map<const void*, std::pair<Expression, std::optional<double>>>;

std::pair<Expression, std::optional<double>> FoldWithValue(const Expression& e, FoldMemo& memo) {
  switch (e.op()) {
    case Op::kConstant:
      return {e, e.constant()};
    case Op::kSymbol:
      return {e, std::nullopt};
    default:
      break;
  }
  if (auto it = memo.find(e.node_id()); it != memo.end()) return it->second;
  std::vector<Expression> args;
  std::vector<double> values;
  for (const Expression& a : e.args()) {
    auto [folded, value] = FoldWithValue(a, memo);
    args.push_back(std::move(folded));
    if (value) values.push_back(*value);
  }
  const bool unary = Arity(e.op()) == 1;
  std::optional<double> value;
  std::pair<Expression, std::optional<double>> out;
  if (values.size() == args.size()) {
    value = unary ? ApplyUnary(e.op(), values[0]) : ApplyBinary(e.op(), values[0], values[1]);
  }
  if (value && std::isfinite(*value)) {
    out = {Expression::Constant(*value), value};
  } else {
    out = {
        unary ? Expression::Unary(e.op(), args[0]) : Expression::Binary(e.op(), args[0], args[1]),
        value};
  }
  memo.emplace(e.node_id(), out);
  return out;
}

using SubstituteMemo = std::unordered_map<const void*, Expression>;

Expression SubstituteShared(
    const Expression& e, const std::function<std::optional<Expression>(const std::string&, int)>& f,
    SubstituteMemo& memo) {
  if (e.op() == Op::kConstant) return e;
  if (e.op() == Op::kSymbol) {
    auto replacement = f(e.symbol_name(), e.slot());
    return replacement ? *replacement : e;
  }
  if (auto it = memo.find(e.node_id()); it != memo.end()) return it->second;
  Expression out = Arity(e.op()) == 1
                       ? Expression::Unary(e.op(), SubstituteShared(e.args()[0], f, memo))
                       : Expression::Binary(e.op(), SubstituteShared(e.args()[0], f, memo),
                                            SubstituteShared(e.args()[1], f, memo));
  memo.emplace(e.node_id(), out);
  return out;
}

}  // namespace

int Arity(Op op) {
  switch (op) {
    case Op::kConstant:
    case Op::kSymbol:
      return 0;
    case Op::kNeg:
    case Op::kSin:
    case Op::kCos:
    case Op::kTan:
    case Op::kExp:
    case Op::kLog:
    case Op::kSqrt:
    case Op::kAbs:
    case Op::kSign:
      return 1;
    default:
      return 2;
  }
}

std::optional<std::string_view> FunctionName(Op op) {
  for (const auto& f : kFunctions) {
    if (f.op == op) return f.name;
  }
  return std::nullopt;
}

std::optional<Op> FunctionByName(std::string_view name, int arity) {
  for (const auto& f : kFunctions) {
    if (f.name == name && Arity(f.op) == arity) return f.op;
  }
  return std::nullopt;
}

std::string FormatNumber(double value) {
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  if (ec != std::errc()) throw std::logic_error("FormatNumber: cannot format");
  return std::string(buffer, end);
}

Expression::Expression() : Expression(Constant(0.0)) {}

Expression::Expression(std::shared_ptr<const Node> node) : node_(std::move(node)) {}

Expression Expression::Constant(double value) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument("Expression::Constant: value is not finite");
  }
  auto node = std::make_shared<Node>();
  node->op = Op::kConstant;
  node->value = value;
  return Expression(std::move(node));
}

Expression Expression::Symbol(std::string name, int slot) {
  if (name.empty() || slot < 0) {
    throw std::invalid_argument("Expression::Symbol: empty name or negative slot");
  }
  auto node = std::make_shared<Node>();
  node->op = Op::kSymbol;
  node->name = std::move(name);
  node->slot = slot;
  return Expression(std::move(node));
}

Expression Expression::Unary(Op op, Expression arg) {
  if (Arity(op) != 1) throw std::invalid_argument("Expression::Unary: operation is not unary");
  if (op == Op::kNeg && arg.is_constant()) return Constant(-arg.constant());
  auto node = std::make_shared<Node>();
  node->op = op;
  node->args.push_back(std::move(arg));
  return Expression(std::move(node));
}

Expression Expression::Binary(Op op, Expression lhs, Expression rhs) {
  if (Arity(op) != 2) throw std::invalid_argument("Expression::Binary: operation is not binary");
  auto node = std::make_shared<Node>();
  node->op = op;
  node->args.push_back(std::move(lhs));
  node->args.push_back(std::move(rhs));
  return Expression(std::move(node));
}

Op Expression::op() const { return node_->op; }
double Expression::constant() const { return node_->value; }
const std::string& Expression::symbol_name() const { return node_->name; }
int Expression::slot() const { return node_->slot; }
std::span<const Expression> Expression::args() const { return node_->args; }

double Expression::Evaluate(std::span<const double> env) const {
  const Node& n = *node_;
  switch (Arity(n.op)) {
    case 0:
      return n.op == Op::kConstant ? n.value : env[n.slot];
    case 1:
      return ApplyUnary(n.op, n.args[0].Evaluate(env));
    default:
      return ApplyBinary(n.op, n.args[0].Evaluate(env), n.args[1].Evaluate(env));
  }
}

Interval Expression::EvaluateInterval(std::span<const Interval> env) const {
  const Node& n = *node_;
  switch (n.op) {
    case Op::kConstant:
      return Interval(n.value);
    case Op::kSymbol:
      return env[n.slot];
    default:
      break;
  }
  const Interval a = n.args[0].EvaluateInterval(env);
  switch (n.op) {
    case Op::kNeg:
      return -a;
    case Op::kSin:
      return Sin(a);
    case Op::kCos:
      return Cos(a);
    case Op::kTan:
      return Tan(a);
    case Op::kExp:
      return Exp(a);
    case Op::kLog:
      return Log(a);
    case Op::kSqrt:
      return Sqrt(a);
    case Op::kAbs:
      return Abs(a);
    case Op::kSign:
      return Interval(a.lo() > 0.0 ? 1.0 : (a.lo() < 0.0 ? -1.0 : 0.0),
                      a.hi() > 0.0 ? 1.0 : (a.hi() < 0.0 ? -1.0 : 0.0));
    default:
      break;
  }
  const Interval b = n.args[1].EvaluateInterval(env);
  switch (n.op) {
    case Op::kAdd:
      return a + b;
    case Op::kSub:
      return a - b;
    case Op::kMul:
      return a * b;
    case Op::kDiv:
      return a / b;
    case Op::kPow:
      return Pow(a, b);
    case Op::kMin:
      return Min(a, b);
    case Op::kMax:
      return Max(a, b);
    case Op::kAtan2:
      return Atan2(a, b);
    default:
      throw std::logic_error("Expression::EvaluateInterval: unknown op");
  }
}

Expression Expression::Derivative(int slot) const {
  const Node& n = *node_;
  if (n.op == Op::kConstant) return Constant(0.0);
  if (n.op == Op::kSymbol) return Constant(n.slot == slot ? 1.0 : 0.0);
  const Expression& a = n.args[0];
  const Expression da = a.Derivative(slot);
  const auto half = Constant(0.5);
  switch (n.op) {
    case Op::kNeg:
      return SNeg(da);
    case Op::kSin:
      return SMul(Call(Op::kCos, a), da);
    case Op::kCos:
      return SNeg(SMul(Call(Op::kSin, a), da));
    case Op::kTan:
      return SDiv(da, Binary(Op::kPow, Call(Op::kCos, a), Constant(2.0)));
    case Op::kExp:
      return SMul(*this, da);
    case Op::kLog:
      return SDiv(da, a);
    case Op::kSqrt:
      return SDiv(da, SMul(Constant(2.0), *this));
    case Op::kAbs:
      return SMul(Call(Op::kSign, a), da);
    case Op::kSign:
      return Constant(0.0);
    default:
      break;
  }
  const Expression& b = n.args[1];
  const Expression db = b.Derivative(slot);
  switch (n.op) {
    case Op::kAdd:
      return SAdd(da, db);
    case Op::kSub:
      return SSub(da, db);
    case Op::kMul:
      return SAdd(SMul(da, b), SMul(a, db));
    case Op::kDiv:
      return SDiv(SSub(SMul(da, b), SMul(a, db)), Binary(Op::kPow, b, Constant(2.0)));
    case Op::kPow:
      if (b.is_constant()) {
        return SMul(SMul(b, Binary(Op::kPow, a, Constant(b.constant() - 1.0))), da);
      }
      return SMul(*this, SAdd(SMul(db, Call(Op::kLog, a)), SDiv(SMul(b, da), a)));
    case Op::kMin:
    case Op::kMax: {
      const Expression mean = SMul(half, SAdd(da, db));
      const Expression jump = SMul(SMul(half, Call(Op::kSign, a - b)), SSub(da, db));
      return n.op == Op::kMin ? SSub(mean, jump) : SAdd(mean, jump);
    }
    case Op::kAtan2:  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
      return SDiv(SSub(SMul(b, da), SMul(a, db)),
                  Binary(Op::kPow, a, Constant(2.0)) + Binary(Op::kPow, b, Constant(2.0)));
    default:
      throw std::logic_error("Expression::Derivative: unknown op");
  }
}

std::vector<int> Expression::Slots() const {
  std::vector<int> slots;
  CollectSlots(*this, &slots);
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  return slots;
}

std::optional<AffineForm> Expression::AsAffine() const {
  const Node& n = *node_;
  if (n.op == Op::kConstant) return AffineForm{n.value, {}};
  if (n.op == Op::kSymbol) return AffineForm{0.0, {{n.slot, 1.0}}};
  std::vector<AffineForm> parts;
  for (const Expression& a : n.args) {
    auto f = a.AsAffine();
    if (!f) return std::nullopt;
    parts.push_back(std::move(*f));
  }
  const bool all_constant =
      std::all_of(parts.begin(), parts.end(), [](const AffineForm& f) { return f.terms.empty(); });
  if (all_constant) {
    const double v = Arity(n.op) == 1 ? ApplyUnary(n.op, parts[0].constant)
                                      : ApplyBinary(n.op, parts[0].constant, parts[1].constant);
    if (!std::isfinite(v)) return std::nullopt;
    return AffineForm{v, {}};
  }
  switch (n.op) {
    case Op::kNeg:
      return Scale(parts[0], -1.0);
    case Op::kAdd:
      return Combine(parts[0], parts[1], 1.0);
    case Op::kSub:
      return Combine(parts[0], parts[1], -1.0);
    case Op::kMul:
      if (parts[0].terms.empty()) return Scale(parts[1], parts[0].constant);
      if (parts[1].terms.empty()) return Scale(parts[0], parts[1].constant);
      return std::nullopt;
    case Op::kDiv:
      if (parts[1].terms.empty() && parts[1].constant != 0.0) {
        return Scale(parts[0], 1.0 / parts[1].constant);
      }
      return std::nullopt;
    case Op::kPow:
      if (parts[1].terms.empty() && parts[1].constant == 1.0) return parts[0];
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

Expression Expression::Substitute(
    const std::function<std::optional<Expression>(const std::string&, int)>& f) const {
  SubstituteMemo memo;
  return SubstituteShared(*this, f, memo);
}

Expression Expression::FoldConstants() const {
  FoldMemo memo;
  return FoldWithValue(*this, memo).first;
}

std::string Expression::ToString() const {
  std::string out;
  Print(*this, &out);
  return out;
}

bool operator==(const Expression& a, const Expression& b) {
  if (a.node_ == b.node_) return true;
  const auto& x = *a.node_;
  const auto& y = *b.node_;
  if (x.op != y.op || x.args.size() != y.args.size()) return false;
  if (x.op == Op::kConstant) return x.value == y.value;
  if (x.op == Op::kSymbol) return x.slot == y.slot && x.name == y.name;
  for (size_t i = 0; i < x.args.size(); ++i) {
    if (!(x.args[i] == y.args[i])) return false;
  }
  return true;
}

Expression operator+(const Expression& a, const Expression& b) {
  return Expression::Binary(Op::kAdd, a, b);
}
Expression operator-(const Expression& a, const Expression& b) {
  return Expression::Binary(Op::kSub, a, b);
}
Expression operator*(const Expression& a, const Expression& b) {
  return Expression::Binary(Op::kMul, a, b);
}
Expression operator/(const Expression& a, const Expression& b) {
  return Expression::Binary(Op::kDiv, a, b);
}
Expression operator-(const Expression& a) { return Expression::Unary(Op::kNeg, a); }

}  // namespace hybrid
