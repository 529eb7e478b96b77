#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/automaton/interval.h"

namespace hybrid {

/// Operations of the expression IR. Unary functions take one argument, binary operators and
/// functions two.
enum class Op : std::uint8_t {
  kConstant,
  kSymbol,
  // unary
  kNeg,
  kSin,
  kCos,
  kTan,
  kExp,
  kLog,
  kSqrt,
  kAbs,
  kSign,
  // binary
  kAdd,
  kSub,
  kMul,
  kDiv,
  kPow,
  kMin,
  kMax,
  kAtan2,
};

/// Number of arguments of `op` (0, 1 or 2).
int Arity(Op op);

/// Name of a function-call operation as written in the model language (`sin`, `min`, ...), or
/// nullopt for the operators written infix/prefix (+, -, *, /, ^, unary -) and leaves.
std::optional<std::string_view> FunctionName(Op op);

/// The function-call operation spelled `name` with `arity` arguments, or nullopt if none.
std::optional<Op> FunctionByName(std::string_view name, int arity);

/// Deepest expression a model may declare, in tree levels: a number or a name is one level, an
/// operator or function call one more than its deepest argument (so the sum `a + b + c`, which
/// is (a + b) + c, has 3 levels, and a comparison one more than its deeper side). The parser, the
/// Automaton API and the System API refuse deeper expressions and predicates with a message
/// (docs/model_language.md, "Limits"). The value is set by the stack the solvers' recursive
/// walks need (the SMT encoding: about 2.1 KiB per level under AddressSanitizer): at
/// kMaxTreeDepth they fit a 1 MiB stack with room to spare. The IR's own walks (printing,
/// evaluation, compilation, derivatives, comparison, destruction) use no stack per level.
inline constexpr int kMaxExpressionDepth = 256;

/// Deepest expression or predicate tree that can be built at all: Expression::Unary and
/// Expression::Binary (and Predicate's combinators) throw std::invalid_argument beyond it. It is
/// above kMaxExpressionDepth to leave room for what solvers derive from model expressions
/// (residuals, negations, integrals), and bounds every recursive walk of a tree.
inline constexpr int kMaxTreeDepth = kMaxExpressionDepth + 128;

/// An affine form c0 + sum_i a_i * x_{slot_i} with numeric coefficients.
struct AffineForm {
  double constant = 0.0;
  /// (slot, coefficient) pairs, sorted by slot, without zero coefficients.
  std::vector<std::pair<int, double>> terms;
  friend bool operator==(const AffineForm&, const AffineForm&) = default;
};

/// An immutable real-valued expression tree over named symbols.
///
/// Each symbol carries its name (for printing) and a slot: the index of its value in the
/// evaluation environment, a flat array of doubles (or intervals) indexed by slot. Copying an
/// Expression is cheap (the tree is shared and never mutated), so it is used as a value type.
///
/// Evaluation follows IEEE semantics: division by zero gives +-inf, log of a negative number NaN;
/// nothing throws. For repeated evaluation use CompiledExpression, which walks no tree.
class Expression {
 public:
  /// The constant 0.
  Expression();

  /// A constant; throws std::invalid_argument if `value` is not finite.
  static Expression Constant(double value);
  /// A reference to the value at `slot` of the environment; `slot` >= 0, `name` non-empty.
  static Expression Symbol(std::string name, int slot);
  /// `op` applied to `arg`; throws std::invalid_argument if `op` is not unary or the result
  /// would be deeper than kMaxTreeDepth. Negation of a constant folds to the negated constant
  /// (so `-5` is the constant -5), nothing else folds.
  static Expression Unary(Op op, Expression arg);
  /// `op` applied to (lhs, rhs); throws std::invalid_argument if `op` is not binary or the result
  /// would be deeper than kMaxTreeDepth.
  static Expression Binary(Op op, Expression lhs, Expression rhs);

  Op op() const;
  bool is_constant() const { return op() == Op::kConstant; }
  bool is_symbol() const { return op() == Op::kSymbol; }
  /// The value of a constant; precondition is_constant().
  double constant() const;
  /// Name and slot of a symbol; precondition is_symbol().
  const std::string& symbol_name() const;
  int slot() const;
  /// The arguments (empty for leaves).
  std::span<const Expression> args() const;
  /// Levels of the tree: 1 for a leaf, 1 + the deepest argument's otherwise (at most
  /// kMaxTreeDepth). Constant time.
  int depth() const;
  /// Identity of the shared, immutable node behind this expression: equal for copies of one
  /// expression and for a subexpression used in several places (expressions built from shared
  /// parts are DAGs). CompiledExpression uses it to evaluate a shared subexpression once.
  const void* node_id() const { return node_.get(); }

  /// Reference evaluation by walking the tree; `env[slot]` must exist for every slot read.
  double Evaluate(std::span<const double> env) const;
  /// An enclosure of {e(x) : x_i in env[i]} (sound: outward rounded, see Interval).
  Interval EvaluateInterval(std::span<const Interval> env) const;
  /// The symbolic partial derivative with respect to the symbol at `slot`, lightly simplified
  /// (0 and 1 are folded). Non-smooth functions use a subgradient: d|x| = sign(x) dx,
  /// d min(a, b) = (da + db)/2 - sign(a - b) (da - db)/2, and likewise for max. The derivative
  /// can be up to three times as deep as the expression; throws std::invalid_argument if it
  /// would be deeper than kMaxTreeDepth.
  Expression Derivative(int slot) const;
  /// Sorted, de-duplicated slots this expression reads.
  std::vector<int> Slots() const;
  /// The affine form of this expression in its symbols, or nullopt if it is not affine
  /// (a product of two non-constant factors, a non-constant function argument, ...).
  /// Constant subexpressions are folded, so `2 * (x + 3) / 4` is 0.5 x + 1.5.
  std::optional<AffineForm> AsAffine() const;
  /// Replaces each symbol for which `f(name, slot)` returns an expression; other symbols stay.
  /// A subexpression shared in this expression is rewritten once and stays shared (so the cost
  /// is linear in the number of distinct nodes, not in the size of the expanded tree).
  Expression Substitute(
      const std::function<std::optional<Expression>(const std::string&, int)>& f) const;
  /// Folds every subtree without symbols into a constant (when the result is finite). Shared
  /// subexpressions stay shared, as in Substitute.
  Expression FoldConstants() const;

  /// The expression in the model language, with the fewest parentheses that parse back to the
  /// same tree. Numbers print in the shortest form that round-trips exactly.
  std::string ToString() const;

  /// Structural equality: same operations, constants, symbol names and slots.
  friend bool operator==(const Expression& a, const Expression& b);

  friend Expression operator+(const Expression& a, const Expression& b);
  friend Expression operator-(const Expression& a, const Expression& b);
  friend Expression operator*(const Expression& a, const Expression& b);
  friend Expression operator/(const Expression& a, const Expression& b);
  friend Expression operator-(const Expression& a);

 private:
  struct Node;
  explicit Expression(std::shared_ptr<const Node> node);
  std::shared_ptr<const Node> node_;
};

/// Formats `value` in the shortest decimal form that parses back to the same double.
std::string FormatNumber(double value);

}  // namespace hybrid
