#include "hybrid/automaton/expression.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <map>
#include <stdexcept>
#include <unordered_map>

#include "automaton/tree_walk.h"

namespace hybrid {

struct Expression::Node {
  Op op = Op::kConstant;
  double value = 0.0;
  std::string name;
  int slot = -1;
  int depth = 1;  // levels of the tree below and including this node
  std::vector<Expression> args;

  Node() = default;
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;
  ~Node();
};

Expression::Node::~Node() {
  // Destroying the arguments would destroy their nodes in turn, recursively, on a stack as deep as
  // the tree: the nodes this one owns alone are taken apart here, one at a time, instead.
  std::vector<std::shared_ptr<const Node>> orphans;
  auto adopt = [&](std::vector<Expression>& children) {
    for (Expression& c : children) {
      if (c.node_ && c.node_.use_count() == 1) orphans.push_back(std::move(c.node_));
    }
  };
  adopt(args);
  while (!orphans.empty()) {
    std::shared_ptr<const Node> n = std::move(orphans.back());
    orphans.pop_back();
    adopt(const_cast<Node&>(*n).args);  // nodes are created mutable (make_shared<Node>)
  }
}

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
      throw std::logic_error("not a unary operation");
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
      throw std::logic_error("not a binary operation");
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

// Appends the model-language text of `root` to `out` (see Expression::ToString), keeping the
// pending pieces on a heap stack: a piece is either text or a subexpression, wrapped in
// parentheses or not.
void Print(const Expression& root, std::string* out) {
  struct Piece {
    const Expression* e;    // nullptr for text
    std::string_view text;  // static text when e is nullptr
    bool wrap = false;
  };
  std::vector<Piece> todo = {{&root, {}, false}};
  // Pieces of one node are pushed in reverse, so that they pop in order.
  auto then = [&](std::initializer_list<Piece> pieces) {
    for (auto it = std::rbegin(pieces); it != std::rend(pieces); ++it) todo.push_back(*it);
  };
  auto sub = [](const Expression& e, bool wrap) { return Piece{&e, {}, wrap}; };
  auto text = [](std::string_view t) { return Piece{nullptr, t, false}; };
  while (!todo.empty()) {
    const Piece piece = todo.back();
    todo.pop_back();
    if (piece.e == nullptr) {
      out->append(piece.text);
      continue;
    }
    const Expression& e = *piece.e;
    if (piece.wrap) {
      out->push_back('(');
      todo.push_back(text(")"));
    }
    const auto args = e.args();
    switch (e.op()) {
      case Op::kConstant:
        out->append(FormatNumber(e.constant()));
        break;
      case Op::kSymbol:
        out->append(e.symbol_name());
        break;
      case Op::kNeg:
        out->push_back('-');
        todo.push_back(sub(args[0], Precedence(args[0]) < 3));
        break;
      case Op::kAdd:
      case Op::kSub:
      case Op::kMul:
      case Op::kDiv: {
        const int p = Precedence(e);
        // Left-associative: an equal-precedence right operand needs parentheses.
        then({sub(args[0], Precedence(args[0]) < p), text(InfixSpelling(e.op())),
              sub(args[1], Precedence(args[1]) <= p)});
        break;
      }
      case Op::kPow:
        // Right-associative and binding tighter than prefix minus: -x^2 is -(x^2).
        then({sub(args[0], Precedence(args[0]) <= 4), text("^"),
              sub(args[1], Precedence(args[1]) < 3)});
        break;
      default:
        out->append(*FunctionName(e.op()));
        out->push_back('(');
        if (args.size() == 1) {
          then({sub(args[0], false), text(")")});
        } else {
          then({sub(args[0], false), text(", "), sub(args[1], false), text(")")});
        }
        break;
    }
  }
}

// The children of an expression, for the walks of tree_walk.h.
std::span<const Expression> Args(const Expression& e) { return e.args(); }

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

// The value of `e` when it reads no symbol, next to FoldConstants() of `e`.
using Folded = std::pair<Expression, std::optional<double>>;

// Expression `op` (unary or binary) over `args`.
Expression Rebuild(Op op, std::span<const Expression> args) {
  return args.size() == 1 ? Expression::Unary(op, args[0])
                          : Expression::Binary(op, args[0], args[1]);
}

// `depth` if a tree may be that deep (kMaxTreeDepth); throws std::invalid_argument otherwise.
int CheckedDepth(int depth) {
  if (depth > kMaxTreeDepth) {
    throw std::invalid_argument("expression too long or nested too deeply (more than " +
                                std::to_string(kMaxTreeDepth) + " levels)");
  }
  return depth;
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
  if (ec != std::errc()) throw std::logic_error("cannot format a number");
  return std::string(buffer, end);
}

Expression::Expression() : Expression(Constant(0.0)) {}

Expression::Expression(std::shared_ptr<const Node> node) : node_(std::move(node)) {}

Expression Expression::Constant(double value) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument("constant " + FormatNumber(value) + " is not finite");
  }
  auto node = std::make_shared<Node>();
  node->op = Op::kConstant;
  node->value = value;
  return Expression(std::move(node));
}

Expression Expression::Symbol(std::string name, int slot) {
  if (name.empty() || slot < 0) {
    throw std::invalid_argument(name.empty() ? "a name in an expression is empty"
                                             : "name '" + name + "' has no slot");
  }
  auto node = std::make_shared<Node>();
  node->op = Op::kSymbol;
  node->name = std::move(name);
  node->slot = slot;
  return Expression(std::move(node));
}

Expression Expression::Unary(Op op, Expression arg) {
  if (Arity(op) != 1) throw std::invalid_argument("operation does not take one argument");
  if (op == Op::kNeg && arg.is_constant()) return Constant(-arg.constant());
  auto node = std::make_shared<Node>();
  node->op = op;
  node->depth = CheckedDepth(arg.depth() + 1);
  node->args.push_back(std::move(arg));
  return Expression(std::move(node));
}

Expression Expression::Binary(Op op, Expression lhs, Expression rhs) {
  if (Arity(op) != 2) throw std::invalid_argument("operation does not take two arguments");
  auto node = std::make_shared<Node>();
  node->op = op;
  node->depth = CheckedDepth(std::max(lhs.depth(), rhs.depth()) + 1);
  node->args.push_back(std::move(lhs));
  node->args.push_back(std::move(rhs));
  return Expression(std::move(node));
}

Op Expression::op() const { return node_->op; }
double Expression::constant() const { return node_->value; }
const std::string& Expression::symbol_name() const { return node_->name; }
int Expression::slot() const { return node_->slot; }
std::span<const Expression> Expression::args() const { return node_->args; }
int Expression::depth() const { return node_->depth; }

double Expression::Evaluate(std::span<const double> env) const {
  return internal::PostOrder<double>(
      *this, Args,
      [&](const Expression& e) -> std::optional<double> {
        if (e.is_constant()) return e.constant();
        if (e.is_symbol()) return env[e.slot()];
        return std::nullopt;
      },
      [](const Expression& e, std::span<double> v) {
        return v.size() == 1 ? ApplyUnary(e.op(), v[0]) : ApplyBinary(e.op(), v[0], v[1]);
      });
}

namespace {

Interval ApplyUnary(Op op, const Interval& a) {
  switch (op) {
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
      throw std::logic_error("interval evaluation: not a unary operation");
  }
}

Interval ApplyBinary(Op op, const Interval& a, const Interval& b) {
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
      return Pow(a, b);
    case Op::kMin:
      return Min(a, b);
    case Op::kMax:
      return Max(a, b);
    case Op::kAtan2:
      return Atan2(a, b);
    default:
      throw std::logic_error("interval evaluation: not a binary operation");
  }
}

// The derivative of operation `e` given the derivatives `d` of its arguments (Derivative()).
Expression DerivativeOf(const Expression& e, std::span<const Expression> d) {
  const Expression& a = e.args()[0];
  const Expression& da = d[0];
  const auto half = Expression::Constant(0.5);
  const auto two = Expression::Constant(2.0);
  switch (e.op()) {
    case Op::kNeg:
      return SNeg(da);
    case Op::kSin:
      return SMul(Call(Op::kCos, a), da);
    case Op::kCos:
      return SNeg(SMul(Call(Op::kSin, a), da));
    case Op::kTan:
      return SDiv(da, Expression::Binary(Op::kPow, Call(Op::kCos, a), two));
    case Op::kExp:
      return SMul(e, da);
    case Op::kLog:
      return SDiv(da, a);
    case Op::kSqrt:
      return SDiv(da, SMul(two, e));
    case Op::kAbs:
      return SMul(Call(Op::kSign, a), da);
    case Op::kSign:
      return Expression::Constant(0.0);
    default:
      break;
  }
  const Expression& b = e.args()[1];
  const Expression& db = d[1];
  switch (e.op()) {
    case Op::kAdd:
      return SAdd(da, db);
    case Op::kSub:
      return SSub(da, db);
    case Op::kMul:
      return SAdd(SMul(da, b), SMul(a, db));
    case Op::kDiv:
      return SDiv(SSub(SMul(da, b), SMul(a, db)), Expression::Binary(Op::kPow, b, two));
    case Op::kPow:
      if (b.is_constant()) {
        return SMul(
            SMul(b, Expression::Binary(Op::kPow, a, Expression::Constant(b.constant() - 1.0))), da);
      }
      return SMul(e, SAdd(SMul(db, Call(Op::kLog, a)), SDiv(SMul(b, da), a)));
    case Op::kMin:
    case Op::kMax: {
      const Expression mean = SMul(half, SAdd(da, db));
      const Expression jump = SMul(SMul(half, Call(Op::kSign, a - b)), SSub(da, db));
      return e.op() == Op::kMin ? SSub(mean, jump) : SAdd(mean, jump);
    }
    case Op::kAtan2:  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
      return SDiv(SSub(SMul(b, da), SMul(a, db)),
                  Expression::Binary(Op::kPow, a, two) + Expression::Binary(Op::kPow, b, two));
    default:
      throw std::logic_error("derivative: unknown operation");
  }
}

// The affine form of operation `e` given those of its arguments (AsAffine()).
std::optional<AffineForm> AffineOf(const Expression& e,
                                   std::span<std::optional<AffineForm>> parts) {
  for (const auto& p : parts) {
    if (!p) return std::nullopt;
  }
  const bool all_constant =
      std::all_of(parts.begin(), parts.end(), [](const auto& f) { return f->terms.empty(); });
  if (all_constant) {
    const double v = parts.size() == 1
                         ? ApplyUnary(e.op(), parts[0]->constant)
                         : ApplyBinary(e.op(), parts[0]->constant, parts[1]->constant);
    if (!std::isfinite(v)) return std::nullopt;
    return AffineForm{v, {}};
  }
  switch (e.op()) {
    case Op::kNeg:
      return Scale(*parts[0], -1.0);
    case Op::kAdd:
      return Combine(*parts[0], *parts[1], 1.0);
    case Op::kSub:
      return Combine(*parts[0], *parts[1], -1.0);
    case Op::kMul:
      if (parts[0]->terms.empty()) return Scale(*parts[1], parts[0]->constant);
      if (parts[1]->terms.empty()) return Scale(*parts[0], parts[1]->constant);
      return std::nullopt;
    case Op::kDiv:
      if (parts[1]->terms.empty() && parts[1]->constant != 0.0) {
        return Scale(*parts[0], 1.0 / parts[1]->constant);
      }
      return std::nullopt;
    case Op::kPow:
      if (parts[1]->terms.empty() && parts[1]->constant == 1.0) return *parts[0];
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

}  // namespace

Interval Expression::EvaluateInterval(std::span<const Interval> env) const {
  return internal::PostOrder<Interval>(
      *this, Args,
      [&](const Expression& e) -> std::optional<Interval> {
        if (e.is_constant()) return Interval(e.constant());
        if (e.is_symbol()) return env[e.slot()];
        return std::nullopt;
      },
      [](const Expression& e, std::span<Interval> v) {
        return v.size() == 1 ? ApplyUnary(e.op(), v[0]) : ApplyBinary(e.op(), v[0], v[1]);
      });
}

Expression Expression::Derivative(int slot) const {
  return internal::PostOrder<Expression>(
      *this, Args,
      [&](const Expression& e) -> std::optional<Expression> {
        if (e.is_constant()) return Constant(0.0);
        if (e.is_symbol()) return Constant(e.slot() == slot ? 1.0 : 0.0);
        return std::nullopt;
      },
      [](const Expression& e, std::span<Expression> d) { return DerivativeOf(e, d); });
}

std::vector<int> Expression::Slots() const {
  std::vector<int> slots;
  internal::PreOrder(*this, Args, [&](const Expression& e) {
    if (e.is_symbol()) slots.push_back(e.slot());
  });
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  return slots;
}

std::optional<AffineForm> Expression::AsAffine() const {
  return internal::PostOrder<std::optional<AffineForm>>(
      *this, Args,
      [](const Expression& e) -> std::optional<std::optional<AffineForm>> {
        if (e.is_constant()) return AffineForm{e.constant(), {}};
        if (e.is_symbol()) return AffineForm{0.0, {{e.slot(), 1.0}}};
        return std::nullopt;
      },
      [](const Expression& e, std::span<std::optional<AffineForm>> parts) {
        return AffineOf(e, parts);
      });
}

Expression Expression::Substitute(
    const std::function<std::optional<Expression>(const std::string&, int)>& f) const {
  // A shared subexpression is rewritten once (memo by node) and stays shared.
  std::unordered_map<const void*, Expression> memo;
  return internal::PostOrder<Expression>(
      *this, Args,
      [&](const Expression& e) -> std::optional<Expression> {
        if (e.is_constant()) return e;
        if (e.is_symbol()) {
          std::optional<Expression> replacement = f(e.symbol_name(), e.slot());
          if (replacement) return replacement;
          return e;
        }
        if (auto it = memo.find(e.node_id()); it != memo.end()) return it->second;
        return std::nullopt;
      },
      [&](const Expression& e, std::span<Expression> args) {
        Expression out = Rebuild(e.op(), args);
        memo.emplace(e.node_id(), out);
        return out;
      });
}

Expression Expression::FoldConstants() const {
  // A symbol-free subtree whose value is not finite stays unfolded but still passes its value up,
  // so that a finite result above it (`sign(log(0))`, `min(1 / 0, 2)`) folds like any other
  // symbol-free subtree. Shared subexpressions are folded once and stay shared.
  std::unordered_map<const void*, Folded> memo;
  return internal::PostOrder<Folded>(
             *this, Args,
             [&](const Expression& e) -> std::optional<Folded> {
               if (e.is_constant()) return Folded{e, e.constant()};
               if (e.is_symbol()) return Folded{e, std::nullopt};
               if (auto it = memo.find(e.node_id()); it != memo.end()) return it->second;
               return std::nullopt;
             },
             [&](const Expression& e, std::span<Folded> parts) {
               std::vector<Expression> args;
               std::vector<double> values;
               for (const Folded& p : parts) {
                 args.push_back(p.first);
                 if (p.second) values.push_back(*p.second);
               }
               std::optional<double> value;
               if (values.size() == args.size()) {
                 value = values.size() == 1 ? ApplyUnary(e.op(), values[0])
                                            : ApplyBinary(e.op(), values[0], values[1]);
               }
               Folded out = value && std::isfinite(*value)
                                ? Folded{Expression::Constant(*value), value}
                                : Folded{Rebuild(e.op(), args), value};
               memo.emplace(e.node_id(), out);
               return out;
             })
      .first;
}

std::string Expression::ToString() const {
  std::string out;
  Print(*this, &out);
  return out;
}

bool operator==(const Expression& a, const Expression& b) {
  std::vector<std::pair<const Expression*, const Expression*>> todo = {{&a, &b}};
  while (!todo.empty()) {
    const auto [p, q] = todo.back();
    todo.pop_back();
    if (p->node_ == q->node_) continue;
    const auto& x = *p->node_;
    const auto& y = *q->node_;
    if (x.op != y.op || x.args.size() != y.args.size()) return false;
    if (x.op == Op::kConstant && x.value != y.value) return false;
    if (x.op == Op::kSymbol && (x.slot != y.slot || x.name != y.name)) return false;
    for (size_t i = 0; i < x.args.size(); ++i) todo.emplace_back(&x.args[i], &y.args[i]);
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
