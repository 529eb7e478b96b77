#include "hybrid/automaton/compiled_expression.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "tests/automaton/stack_budget.h"
#include "tests/test_utilities/random_models.h"

namespace hybrid {
namespace {

using ::hybrid::testing::GenExpression;
using ::hybrid::testing::GenInt;
using ::hybrid::testing::GenReal;

const Expression x = Expression::Symbol("x", 0);
const Expression y = Expression::Symbol("y", 1);
const Expression z = Expression::Symbol("z", 2);
const Expression w = Expression::Symbol("w", 3);

// One more level of the chain e * e + e (shares e three times).
Expression E2(const Expression& e) { return e * e + e; }

Expression C(double v) { return Expression::Constant(v); }

/// Same bits, or both NaN (NaN payloads and signs are not specified by the C library).
bool SameDouble(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b) ||
         (std::isnan(a) && std::isnan(b));
}

/// An integer constant exponent that CompiledExpression computes by multiplication.
bool IsSmallIntegerExponent(const Expression& e) {
  return e.is_constant() && std::nearbyint(e.constant()) == e.constant() &&
         std::abs(e.constant()) <= 4;
}

/// Expression::Evaluate, except that each `b^n` with an integer constant n in [-4, 4] takes the
/// compiled program's value of that power alone: CompiledExpression computes such powers by
/// multiplication (documented to differ from std::pow in the last bit), everything else must
/// match the tree bit for bit.
double Reference(const Expression& e, std::span<const double> env) {
  static const Expression t0 = Expression::Symbol("t0", 0);
  static const Expression t1 = Expression::Symbol("t1", 1);
  switch (e.op()) {
    case Op::kConstant:
      return e.constant();
    case Op::kSymbol:
      return env[e.slot()];
    default:
      break;
  }
  const double a = Reference(e.args()[0], env);
  if (Arity(e.op()) == 1) return Expression::Unary(e.op(), t0).Evaluate(std::vector<double>{a});
  if (e.op() == Op::kPow && IsSmallIntegerExponent(e.args()[1])) {
    const double base[] = {a};
    return CompiledExpression(Expression::Binary(Op::kPow, t0, e.args()[1])).Evaluate(base);
  }
  const double b = Reference(e.args()[1], env);
  return Expression::Binary(e.op(), t0, t1).Evaluate(std::vector<double>{a, b});
}

/// True when `e` has a power with a small integer constant exponent.
bool HasSmallIntegerPower(const Expression& e) {
  if (e.op() == Op::kPow && IsSmallIntegerExponent(e.args()[1])) return true;
  for (const Expression& a : e.args()) {
    if (HasSmallIntegerPower(a)) return true;
  }
  return false;
}

/// A right-nested chain sin(s0) + (sin(s1) + (...)): every right operand is a compound
/// expression, so the evaluation stack grows by one per level.
Expression RightChain(int depth, Op op) {
  Expression e = Expression::Unary(Op::kCos, w);
  for (int i = depth; i > 0; --i) {
    const Expression s = std::vector<Expression>{x, y, z, w}[i % 4];
    e = Expression::Binary(op, Expression::Unary(Op::kSin, s), e);
  }
  return e;
}

TEST(CompiledExpressionTest, DefaultEvaluatesToZero) {
  const CompiledExpression c;
  EXPECT_EQ(c.Evaluate(nullptr), 0.0);
  EXPECT_EQ(c.size(), CompiledExpression(C(7.0)).size());
}

TEST(CompiledExpressionTest, Examples) {
  const std::vector<double> env = {2.0, -3.0, 0.25, 0.0};
  EXPECT_EQ(CompiledExpression(x * y + z)(env), -5.75);
  EXPECT_EQ(CompiledExpression(C(1.5))(env), 1.5);
  EXPECT_EQ(CompiledExpression(x / w)(env), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(CompiledExpression(Expression::Unary(Op::kLog, y))(env)));
  EXPECT_EQ(CompiledExpression(Expression::Unary(Op::kSign, y))(env), -1.0);
  EXPECT_EQ(CompiledExpression(Expression::Unary(Op::kSign, w))(env), 0.0);
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kMin, x, y))(env), -3.0);
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kMax, x, y))(env), 2.0);
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kPow, x, C(10.0)))(env), 1024.0);
  EXPECT_EQ(CompiledExpression(x - (y - z))(env), 2.0 - (-3.0 - 0.25));
  EXPECT_EQ(CompiledExpression((x - y) - z)(env), (2.0 + 3.0) - 0.25);
  EXPECT_EQ(CompiledExpression(-x)(env), -2.0);
}

TEST(CompiledExpressionTest, ConstantAndSymbolRightOperandsAreFused) {
  // `m1 * u`: the multiplication reads u from its own instruction, so it costs one instruction
  // more than `m1` alone, like a unary function.
  const int leaf = CompiledExpression(x).size();
  EXPECT_EQ(CompiledExpression(x * y).size(), leaf + 1);
  EXPECT_EQ(CompiledExpression(x + C(1.0)).size(), leaf + 1);
  EXPECT_EQ(CompiledExpression(Expression::Unary(Op::kSin, x)).size(), leaf + 1);
  // A compound right operand needs its own instructions: push z, divide, subtract.
  EXPECT_EQ(CompiledExpression(x * y - z / C(2.0)).size(), CompiledExpression(x * y).size() + 3);
}

TEST(CompiledExpressionTest, SmallIntegerPowersAreCloseToPow) {
  for (double b : {3.0, -2.5, 0.1, 1e-3, -7.25, 1.0 / 3.0}) {
    for (int n = -4; n <= 4; ++n) {
      const double env[] = {b};
      const double compiled =
          CompiledExpression(Expression::Binary(Op::kPow, x, C(n))).Evaluate(env);
      const double exact = std::pow(b, n);
      EXPECT_NEAR(compiled, exact, 4 * std::numeric_limits<double>::epsilon() * std::abs(exact))
          << b << "^" << n;
    }
  }
  const double zero[] = {0.0};
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kPow, x, C(-2.0))).Evaluate(zero),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kPow, x, C(0.0))).Evaluate(zero), 1.0);
  const double nan[] = {std::nan("")};
  EXPECT_EQ(CompiledExpression(Expression::Binary(Op::kPow, x, C(0.0))).Evaluate(nan), 1.0);
  EXPECT_TRUE(
      std::isnan(CompiledExpression(Expression::Binary(Op::kPow, x, C(2.0))).Evaluate(nan)));
}

TEST(CompiledExpressionTest, NonCommutativeOperandsKeepTheirOrder) {
  const std::vector<double> env = {3.0, 2.0, 0.5, -1.0};
  const auto sub = Expression::Unary(Op::kSin, y);
  for (Op op : {Op::kSub, Op::kDiv, Op::kPow, Op::kAtan2}) {
    for (const auto& [a, b] : std::vector<std::pair<Expression, Expression>>{
             {x, y}, {x, C(2.0)}, {C(2.0), x}, {x, sub}, {sub, x}, {sub, sub * z}}) {
      const Expression e = Expression::Binary(op, a, b);
      EXPECT_TRUE(SameDouble(CompiledExpression(e)(env), Reference(e, env))) << e.ToString();
    }
  }
}

TEST(CompiledExpressionTest, DeepExpressionsUseAHeapStack) {
  for (int depth : {CompiledExpression::kMaxInlineStack - 2, CompiledExpression::kMaxInlineStack,
                    CompiledExpression::kMaxInlineStack + 1, 200, kMaxTreeDepth - 2}) {
    for (Op op : {Op::kAdd, Op::kSub, Op::kMul, Op::kAtan2}) {
      const Expression e = RightChain(depth, op);
      const CompiledExpression c(e);
      for (const std::vector<double>& env :
           {std::vector<double>{0.5, -1.0, 2.0, 0.25}, std::vector<double>{1.0, 1.0, 1.0, 1.0}}) {
        EXPECT_TRUE(SameDouble(c(env), Reference(e, env))) << "depth " << depth;
      }
    }
  }
  // A deep left-nested chain needs no stack but many instructions.
  Expression left = x;
  while (left.depth() + 2 <= kMaxTreeDepth) left = Expression::Unary(Op::kSin, left) + y;
  ASSERT_GE(left.depth(), kMaxTreeDepth - 1);
  const std::vector<double> env = {0.5, 0.001, 0.0, 0.0};
  EXPECT_TRUE(SameDouble(CompiledExpression(left)(env), Reference(left, env)));
}

// Compiling walks the tree with a heap stack of tasks: trees at the depth limit, left- and
// right-deep, compile and run on a 1 MiB stack (AddressSanitizer's larger frames included).
TEST(CompiledExpressionTest, TreesAtTheDepthLimitCompileOnASmallStack) {
  testing::RunOnStack(testing::kOneMebibyte, [] {
    for (Op op : {Op::kAdd, Op::kSub, Op::kMul, Op::kDiv, Op::kMin, Op::kAtan2}) {
      const Expression right = RightChain(kMaxTreeDepth - 2, op);
      Expression left = x;
      while (left.depth() < kMaxTreeDepth) {
        left = Expression::Binary(op, left, Expression::Unary(Op::kSin, y));
      }
      for (const Expression& e : {right, left}) {
        ASSERT_GE(e.depth(), kMaxTreeDepth - 1);
        const std::vector<double> env = {0.5, -1.0, 2.0, 0.25};
        EXPECT_TRUE(SameDouble(CompiledExpression(e)(env), e.Evaluate(env)));
      }
    }
  });
}

TEST(CompiledExpressionTest, CopiesEvaluateIndependently) {
  CompiledExpression a(x + y);
  const CompiledExpression b = a;
  a = CompiledExpression(x * y);
  const std::vector<double> env = {2.0, 5.0, 0.0, 0.0};
  EXPECT_EQ(a(env), 10.0);
  EXPECT_EQ(b(env), 7.0);
}

/// A random environment mixing ordinary values, zeros, negative values and large magnitudes.
std::vector<double> RandomEnvironment() {
  std::vector<double> env;
  for (int i = 0; i < 4; ++i) {
    switch (*GenInt(0, 5)) {
      case 0:
        env.push_back(*rc::gen::element(0.0, -0.0, 1.0, -1.0, 0.5));
        break;
      case 1:
        env.push_back(*GenReal(-1e6, 1e6));
        break;
      case 2:
        env.push_back(*rc::gen::element(1e300, -1e-300, 710.0, 1e-320));
        break;
      default:
        env.push_back(*GenReal(-5.0, 5.0));
        break;
    }
  }
  return env;
}

// A subexpression shared by several parents is computed once: the chain e_{k+1} = e_k * e_k + e_k
// has 2^k leaves when expanded but k distinct nodes, and the program stays linear in k.
TEST(CompiledExpressionTest, SharedSubexpressionsAreComputedOnce) {
  Expression e = x + y;
  double expected = 0.3 + 0.4;
  for (int k = 0; k < 12; ++k) {
    e = e * e + e;
    expected = expected * expected + expected;
  }
  const CompiledExpression c(e);
  EXPECT_LT(c.size(), 12 * 8);
  const std::vector<double> env = {0.3, 0.4};
  EXPECT_EQ(c(env), e.Evaluate(env));  // the tree walk (4096 leaves) gives the same bits
  EXPECT_EQ(c(env), expected);
  // Sixty levels: 2^60 leaves expanded; Substitute and FoldConstants keep the sharing.
  for (int k = 0; k < 48; ++k) e = E2(e);
  const Expression renamed = e.Substitute([](const std::string&, int slot) {
    return std::optional<Expression>(Expression::Symbol(slot == 0 ? "a" : "b", 1 - slot));
  });
  const CompiledExpression big(renamed.FoldConstants());
  EXPECT_LT(big.size(), 60 * 8);
  const std::vector<double> small = {1e-3, 0.0};  // a = x (slot 1), b = y (slot 0)
  EXPECT_TRUE(std::isfinite(big(small)));
}

RC_GTEST_PROP(CompiledExpressionProperty, EvaluatesLikeTheTreeBitForBit, ()) {
  const Expression e = *GenExpression(6);
  const CompiledExpression c(e);
  const bool exact = !HasSmallIntegerPower(e);
  RC_CLASSIFY(!exact, "small integer power");
  for (int k = 0; k < 8; ++k) {
    const std::vector<double> env = RandomEnvironment();
    const double actual = c.Evaluate(env.data());
    RC_ASSERT(SameDouble(actual, Reference(e, env)));
    if (exact) RC_ASSERT(SameDouble(actual, e.Evaluate(env)));
  }
}

// Random DAGs: two random expressions, each used several times (shared nodes), give the same
// bits compiled as walked.
RC_GTEST_PROP(CompiledExpressionProperty, SharedSubexpressionsEvaluateLikeTheTree, ()) {
  const Expression e = *GenExpression(4);
  const Expression f = *GenExpression(4);
  RC_PRE(!HasSmallIntegerPower(e) && !HasSmallIntegerPower(f));
  const Expression ef = e * f;
  const Expression dag =
      Expression::Binary(Op::kMin, ef + e, ef - f) / (Expression::Unary(Op::kAbs, e) + ef);
  const CompiledExpression c(dag);
  for (int k = 0; k < 8; ++k) {
    const std::vector<double> env = RandomEnvironment();
    RC_ASSERT(SameDouble(c.Evaluate(env.data()), dag.Evaluate(env)));
  }
}

RC_GTEST_PROP(CompiledExpressionProperty, PowersInsideExpressionsEvaluateLikeTheTree, ()) {
  // Small integer powers of compound bases, combined with other operations on either side.
  const Expression power = Expression::Binary(Op::kPow, *GenExpression(3),
                                              C(*GenInt(-4, 5) * *rc::gen::element(1.0, -1.0)));
  const Op op =
      *rc::gen::element(Op::kAdd, Op::kSub, Op::kMul, Op::kDiv, Op::kMin, Op::kAtan2, Op::kPow);
  const Expression other = *GenExpression(2);
  const Expression e = *GenInt(0, 2) == 0 ? Expression::Binary(op, power, other)
                                          : Expression::Binary(op, other, power);
  const CompiledExpression c(e);
  for (int k = 0; k < 8; ++k) {
    const std::vector<double> env = RandomEnvironment();
    RC_ASSERT(SameDouble(c.Evaluate(env.data()), Reference(e, env)));
  }
}

RC_GTEST_PROP(CompiledExpressionProperty, SmallIntegerPowersAreWithinFourUlpsOfPow, ()) {
  const int n = *GenInt(-4, 5);
  const double b =
      *rc::gen::element(1.0, -1.0) * *GenReal(0.0, 1.0) * std::pow(10.0, *GenInt(-40, 41));
  const Expression e = Expression::Binary(Op::kPow, x * C(1.0), C(n));  // compound base too
  for (const Expression& power : {Expression::Binary(Op::kPow, x, C(n)), e}) {
    const double env[] = {b};
    const double compiled = CompiledExpression(power).Evaluate(env);
    const double exact = std::pow(b, n);
    RC_LOG() << b << "^" << n << ": " << compiled << " vs " << exact << "\n";
    if (std::isfinite(exact) && exact != 0.0) {
      RC_ASSERT(std::abs(compiled - exact) <=
                4 * std::numeric_limits<double>::epsilon() * std::abs(exact));
    } else {
      RC_ASSERT(SameDouble(compiled, exact));
    }
  }
}

RC_GTEST_PROP(CompiledExpressionProperty, DeepRandomExpressionsEvaluateLikeTheTree, ()) {
  // Nest random expressions as right operands deeper than the inline stack.
  const int depth =
      *GenInt(CompiledExpression::kMaxInlineStack - 4, 3 * CompiledExpression::kMaxInlineStack);
  Expression e = *GenExpression(2);
  for (int i = 0; i < depth; ++i) {
    const Op op = *rc::gen::element(Op::kAdd, Op::kSub, Op::kMul, Op::kDiv, Op::kMin, Op::kMax,
                                    Op::kAtan2, Op::kPow);
    Expression lhs = *GenExpression(2);
    if (*GenInt(0, 4) == 0) e = Expression::Unary(Op::kSin, e);
    e = Expression::Binary(op, lhs, e.is_constant() || e.is_symbol() ? -e + x : e);
  }
  const CompiledExpression c(e);
  for (int k = 0; k < 4; ++k) {
    std::vector<double> env;
    for (int i = 0; i < 4; ++i) env.push_back(*GenReal(-2.0, 2.0));
    RC_ASSERT(SameDouble(c(env), Reference(e, env)));
  }
}

}  // namespace
}  // namespace hybrid
