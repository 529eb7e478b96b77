#include "hybrid/automaton/expression.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "tests/automaton/stack_budget.h"
#include "tests/test_utilities/random_models.h"

namespace hybrid {

// gtest printers (found by argument-dependent lookup), local to this test program.
[[maybe_unused]] static void PrintTo(const Expression& e, std::ostream* os) { *os << e.ToString(); }
[[maybe_unused]] static void PrintTo(const AffineForm& f, std::ostream* os) {
  *os << FormatNumber(f.constant);
  for (const auto& [slot, c] : f.terms) *os << " + " << FormatNumber(c) << " * #" << slot;
}

namespace {

using ::hybrid::testing::GenExpression;
using ::hybrid::testing::GenInt;
using ::hybrid::testing::GenInterval;
using ::hybrid::testing::GenPointIn;
using ::hybrid::testing::GenReal;
using ::hybrid::testing::GenSmoothExpression;

const Expression x = Expression::Symbol("x", 0);
const Expression y = Expression::Symbol("y", 1);
const Expression z = Expression::Symbol("z", 2);
const Expression w = Expression::Symbol("w", 3);

Expression C(double v) { return Expression::Constant(v); }
Expression Pow(const Expression& a, const Expression& b) {
  return Expression::Binary(Op::kPow, a, b);
}
Expression Fn(Op op, const Expression& a) { return Expression::Unary(op, a); }
Expression Fn(Op op, const Expression& a, const Expression& b) {
  return Expression::Binary(op, a, b);
}

/// Parses `text` as the flow of x in a model declaring x, y, z, w (slots 0..3, as kSymbolNames).
Expression Parse(const std::string& text) {
  const std::string model =
      "automaton t {\n  var x; var y; var z; var w;\n  mode m { x' = " + text +
      "; }\n  init m { x = 0; y = 0; z = 0; w = 0; }\n}\n";
  const Automaton a = ParseAutomaton(model, "expression.ha");
  return a.modes()[0].flows.at(0).second;
}

/// True when `e` or any of its subexpressions evaluates to NaN at `env`: IEEE min, max, sign and
/// pow turn some NaN arguments into numbers, which interval enclosures need not cover.
bool HasNanSubexpression(const Expression& e, std::span<const double> env) {
  if (std::isnan(e.Evaluate(env))) return true;
  for (const Expression& a : e.args()) {
    if (HasNanSubexpression(a, env)) return true;
  }
  return false;
}

// --- construction ----------------------------------------------------------------------------

TEST(ExpressionTest, DefaultIsZero) {
  const Expression e;
  ASSERT_TRUE(e.is_constant());
  EXPECT_EQ(e.constant(), 0.0);
  EXPECT_EQ(e.ToString(), "0");
}

TEST(ExpressionTest, ConstructorsValidateTheirArguments) {
  EXPECT_THROW(Expression::Constant(std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  EXPECT_THROW(Expression::Constant(std::nan("")), std::invalid_argument);
  EXPECT_THROW(Expression::Symbol("", 0), std::invalid_argument);
  EXPECT_THROW(Expression::Symbol("x", -1), std::invalid_argument);
  EXPECT_THROW(Expression::Unary(Op::kAdd, x), std::invalid_argument);
  EXPECT_THROW(Expression::Unary(Op::kConstant, x), std::invalid_argument);
  EXPECT_THROW(Expression::Binary(Op::kSin, x, y), std::invalid_argument);
  EXPECT_THROW(Expression::Binary(Op::kSymbol, x, y), std::invalid_argument);
}

// The message of the std::invalid_argument `f` throws ("" and a failure if none).
std::string InvalidArgumentMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return "";
}

// Messages reach users (through the model API): they name no C++ function.
TEST(ExpressionTest, ConstructorMessagesNameNoCppFunction) {
  EXPECT_EQ(InvalidArgumentMessage([] { Expression::Constant(HUGE_VAL); }),
            "constant inf is not finite");
  EXPECT_EQ(InvalidArgumentMessage([] { Expression::Symbol("", 0); }),
            "a name in an expression is empty");
  EXPECT_EQ(InvalidArgumentMessage([] { Expression::Symbol("x", -1); }), "name 'x' has no slot");
  EXPECT_EQ(InvalidArgumentMessage([] { Expression::Unary(Op::kAdd, x); }),
            "operation does not take one argument");
  EXPECT_EQ(InvalidArgumentMessage([] { Expression::Binary(Op::kSin, x, y); }),
            "operation does not take two arguments");
}

// --- depth -----------------------------------------------------------------------------------

TEST(ExpressionDepthTest, DepthCountsLevels) {
  EXPECT_EQ(x.depth(), 1);
  EXPECT_EQ(C(2.0).depth(), 1);
  EXPECT_EQ((-C(2.0)).depth(), 1);  // folded
  EXPECT_EQ((-x).depth(), 2);
  EXPECT_EQ((x + y).depth(), 2);
  EXPECT_EQ((x + y + z).depth(), 3);
  EXPECT_EQ((x + y * (z - w)).depth(), 4);
  EXPECT_EQ(Fn(Op::kAtan2, x, Fn(Op::kSin, Fn(Op::kSin, y))).depth(), 4);
  EXPECT_EQ(Parse("x + y + z + w").depth(), 4);
  EXPECT_EQ(Parse("((x))").depth(), 1);  // parentheses are not levels
}

// Chains of `n` levels of four shapes, with their values at x computed without the tree.
struct Chain {
  const char* shape;
  Expression e;
  double value;  // at x = kChainX, computed in the same order as the tree
  int leaves;    // occurrences of x
};
constexpr double kChainX = 0.75;

std::vector<Chain> Chains(int n) {
  std::vector<Chain> out;
  Expression sum = x, diff = x, sines = x, mixed = x;
  double diff_value = kChainX, sine_value = kChainX, mixed_value = kChainX;
  for (int i = 1; i < n; ++i) {
    sum = sum + x;    // (x + x) + x ...: left-deep
    diff = x - diff;  // x - (x - (...)): right-deep
    diff_value = kChainX - diff_value;
    sines = Fn(Op::kSin, sines);  // unary chain
    sine_value = std::sin(sine_value);
    mixed = i % 2 == 1 ? mixed * C(2.0) : C(0.5) / mixed;  // both sides deep in turn
    mixed_value = i % 2 == 1 ? mixed_value * 2.0 : 0.5 / mixed_value;
  }
  out.push_back({"left-deep sum", sum, n * kChainX, n});
  out.push_back({"right-deep difference", diff, diff_value, n});
  out.push_back({"nested sines", sines, sine_value, 1});
  out.push_back({"products and quotients", mixed, mixed_value, 1});
  return out;
}

TEST(ExpressionDepthTest, TreesDeeperThanTheLimitCannotBeBuilt) {
  const std::string too_deep = "expression too long or nested too deeply (more than " +
                               std::to_string(kMaxTreeDepth) + " levels)";
  for (const Chain& c : Chains(kMaxTreeDepth)) {
    SCOPED_TRACE(c.shape);
    ASSERT_EQ(c.e.depth(), kMaxTreeDepth);
    EXPECT_EQ(InvalidArgumentMessage([&] { c.e + x; }), too_deep);
    EXPECT_EQ(InvalidArgumentMessage([&] { x* c.e; }), too_deep);
    EXPECT_EQ(InvalidArgumentMessage([&] { -c.e; }), too_deep);
    EXPECT_EQ(InvalidArgumentMessage([&] { Fn(Op::kMin, x, c.e); }), too_deep);
  }
  EXPECT_GT(kMaxTreeDepth, kMaxExpressionDepth);  // room for what solvers derive
}

// Every recursive walk of the tree, at the deepest tree that can exist, on a 1 MiB stack (the
// sanitized test run checks the same under AddressSanitizer, whose frames are larger).
TEST(ExpressionDepthTest, EveryWalkAtTheTreeDepthLimitFitsASmallStack) {
  testing::RunOnStack(testing::kOneMebibyte, [] {
    for (const Chain& c : Chains(kMaxTreeDepth)) {
      SCOPED_TRACE(c.shape);
      const std::vector<double> env = {kChainX};
      EXPECT_DOUBLE_EQ(c.e.Evaluate(env), c.value);
      const Interval enclosure = c.e.EvaluateInterval(std::vector<Interval>{Interval(kChainX)});
      EXPECT_LE(enclosure.lo(), c.e.Evaluate(env));
      EXPECT_GE(enclosure.hi(), c.e.Evaluate(env));
      EXPECT_EQ(c.e.Slots(), std::vector<int>{0});
      const std::string text = c.e.ToString();
      EXPECT_EQ(std::count(text.begin(), text.end(), 'x'), c.leaves);
      const Expression renamed =
          c.e.Substitute([](const std::string&, int) -> std::optional<Expression> { return y; });
      EXPECT_EQ(renamed.Slots(), std::vector<int>{1});
      EXPECT_EQ(renamed.depth(), kMaxTreeDepth);
      EXPECT_FALSE(renamed == c.e);
      const Expression copy = renamed.Substitute(
          [](const std::string&, int) -> std::optional<Expression> { return x; });
      EXPECT_TRUE(copy == c.e);  // equal, but no node shared
      const Expression constant = c.e.Substitute(
          [](const std::string&, int) -> std::optional<Expression> { return C(kChainX); });
      const Expression folded = constant.FoldConstants();
      ASSERT_TRUE(folded.is_constant());
      EXPECT_EQ(folded.constant(), c.e.Evaluate(env));
      (void)c.e.AsAffine();
      // A derivative can be deeper than its expression: built, or refused with the message.
      try {
        EXPECT_LE(c.e.Derivative(0).depth(), kMaxTreeDepth);
      } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "expression too long or nested too deeply (more than " +
                                             std::to_string(kMaxTreeDepth) + " levels)");
      }
    }
  });
}

// The printed text of an expression of every shape at the limit: each operator once, no
// parentheses for a left-deep sum.
TEST(ExpressionDepthTest, DeepSumPrintsFlat) {
  const Expression sum = Chains(kMaxTreeDepth)[0].e;
  EXPECT_EQ(sum.ToString().size(), 4u * kMaxTreeDepth - 3);  // "x + x + ... + x"
  EXPECT_EQ(sum.AsAffine(), (AffineForm{0.0, {{0, double(kMaxTreeDepth)}}}));
  EXPECT_EQ(sum.Derivative(0), C(kMaxTreeDepth));
}

TEST(ExpressionTest, NegationFoldsOnlyConstants) {
  const Expression minus_two = -C(2.0);
  ASSERT_TRUE(minus_two.is_constant());
  EXPECT_EQ(minus_two.constant(), -2.0);
  EXPECT_EQ((-minus_two).constant(), 2.0);
  EXPECT_EQ((-x).op(), Op::kNeg);
  EXPECT_EQ((-(-x)).op(), Op::kNeg);
  EXPECT_EQ((C(1.0) + C(2.0)).op(), Op::kAdd);  // nothing else folds
}

TEST(ExpressionTest, Accessors) {
  const Expression e = Fn(Op::kAtan2, x, C(3.0));
  EXPECT_EQ(e.op(), Op::kAtan2);
  ASSERT_EQ(e.args().size(), 2u);
  EXPECT_TRUE(e.args()[0].is_symbol());
  EXPECT_EQ(e.args()[0].symbol_name(), "x");
  EXPECT_EQ(e.args()[0].slot(), 0);
  EXPECT_EQ(e.args()[1].constant(), 3.0);
  EXPECT_TRUE(x.args().empty());
}

TEST(ExpressionTest, ArityAndFunctionNames) {
  EXPECT_EQ(Arity(Op::kConstant), 0);
  EXPECT_EQ(Arity(Op::kSymbol), 0);
  EXPECT_EQ(Arity(Op::kNeg), 1);
  EXPECT_EQ(Arity(Op::kSign), 1);
  EXPECT_EQ(Arity(Op::kAdd), 2);
  EXPECT_EQ(Arity(Op::kAtan2), 2);
  EXPECT_EQ(FunctionName(Op::kSqrt), "sqrt");
  EXPECT_EQ(FunctionName(Op::kAtan2), "atan2");
  EXPECT_FALSE(FunctionName(Op::kAdd).has_value());
  EXPECT_FALSE(FunctionName(Op::kNeg).has_value());
  EXPECT_EQ(FunctionByName("max", 2), Op::kMax);
  EXPECT_EQ(FunctionByName("abs", 1), Op::kAbs);
  EXPECT_FALSE(FunctionByName("max", 1).has_value());
  EXPECT_FALSE(FunctionByName("sin", 2).has_value());
  EXPECT_FALSE(FunctionByName("cosh", 1).has_value());
}

TEST(ExpressionTest, EqualityIsStructural) {
  EXPECT_EQ(x + C(1.0), Expression::Symbol("x", 0) + Expression::Constant(1.0));
  EXPECT_NE(x + C(1.0), C(1.0) + x);
  EXPECT_NE(Expression::Symbol("x", 0), Expression::Symbol("x", 1));
  EXPECT_NE(Expression::Symbol("x", 0), Expression::Symbol("a", 0));
  EXPECT_NE(x - y, x + y);
  EXPECT_NE(Fn(Op::kMin, x, y), Fn(Op::kMax, x, y));
  EXPECT_NE(C(1.0), C(1.5));
  EXPECT_NE(-x, x);
}

// --- printing --------------------------------------------------------------------------------

TEST(ExpressionPrintTest, PrefixMinusAndPower) {
  EXPECT_EQ((-Pow(x, C(2.0))).ToString(), "-x^2");
  EXPECT_EQ(Pow(-x, C(2.0)).ToString(), "(-x)^2");
  EXPECT_EQ(Pow(x, -y).ToString(), "x^-y");
  EXPECT_EQ(Pow(x, -Pow(y, C(2.0))).ToString(), "x^-y^2");
  EXPECT_EQ((-(-x)).ToString(), "--x");
  EXPECT_EQ((-(x * y)).ToString(), "-(x * y)");
  EXPECT_EQ((-x * y).ToString(), "-x * y");
  EXPECT_EQ((-(x + y)).ToString(), "-(x + y)");
}

TEST(ExpressionPrintTest, Associativity) {
  EXPECT_EQ(((x - y) - z).ToString(), "x - y - z");
  EXPECT_EQ((x - (y - z)).ToString(), "x - (y - z)");
  EXPECT_EQ((x + (y + z)).ToString(), "x + (y + z)");
  EXPECT_EQ(((x / y) / z).ToString(), "x / y / z");
  EXPECT_EQ((x / (y / z)).ToString(), "x / (y / z)");
  EXPECT_EQ((x / (y * z)).ToString(), "x / (y * z)");
  EXPECT_EQ((x * y / z).ToString(), "x * y / z");
  EXPECT_EQ(((x + y) * z).ToString(), "(x + y) * z");
  EXPECT_EQ((x + y * z).ToString(), "x + y * z");
  EXPECT_EQ((x * y + z).ToString(), "x * y + z");
}

TEST(ExpressionPrintTest, PowerIsRightAssociative) {
  EXPECT_EQ(Pow(C(2.0), Pow(C(3.0), C(2.0))).ToString(), "2^3^2");
  EXPECT_EQ(Pow(Pow(C(2.0), C(3.0)), C(2.0)).ToString(), "(2^3)^2");
  EXPECT_EQ(Pow(x * y, z).ToString(), "(x * y)^z");
  EXPECT_EQ(Pow(x, y + z).ToString(), "x^(y + z)");
  EXPECT_EQ(Pow(Fn(Op::kSin, x), C(2.0)).ToString(), "sin(x)^2");
}

TEST(ExpressionPrintTest, NegativeConstants) {
  EXPECT_EQ(C(-2.0).ToString(), "-2");
  EXPECT_EQ((x - C(-2.0)).ToString(), "x - -2");
  EXPECT_EQ((x * C(-2.5)).ToString(), "x * -2.5");
  EXPECT_EQ((C(-2.0) + x).ToString(), "-2 + x");
  EXPECT_EQ(Pow(x, C(-2.0)).ToString(), "x^-2");
  EXPECT_EQ(Pow(C(-2.0), x).ToString(), "(-2)^x");
  EXPECT_EQ((-Pow(C(-2.0), x)).ToString(), "-(-2)^x");
  EXPECT_EQ(C(-0.0).ToString(), "-0");
}

TEST(ExpressionPrintTest, FunctionsAndNumbers) {
  EXPECT_EQ(Fn(Op::kSin, x + C(1.0)).ToString(), "sin(x + 1)");
  EXPECT_EQ(Fn(Op::kMin, x, -y).ToString(), "min(x, -y)");
  EXPECT_EQ(Fn(Op::kAtan2, y, x).ToString(), "atan2(y, x)");
  EXPECT_EQ(Fn(Op::kSign, Fn(Op::kAbs, x)).ToString(), "sign(abs(x))");
  EXPECT_EQ(C(0.1).ToString(), "0.1");
  EXPECT_EQ(C(1e20).ToString(), "1e+20");
  EXPECT_EQ(C(2.5e-8).ToString(), "2.5e-08");
  EXPECT_EQ(C(255.0).ToString(), "255");
  EXPECT_EQ(FormatNumber(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(std::stod(FormatNumber(1.0 / 3.0)), 1.0 / 3.0);
}

TEST(ExpressionPrintTest, PrintedExpressionsParseBack) {
  for (const Expression& e : {-Pow(x, C(2.0)), Pow(-x, C(2.0)), (x - y) - z, x - (y - z),
                              Pow(C(2.0), Pow(C(3.0), C(2.0))), Pow(Pow(C(2.0), C(3.0)), C(2.0)),
                              x - C(-2.0), Pow(C(-2.0), x), Pow(x, C(-0.5)), -(-x), x / (y * z),
                              Fn(Op::kAtan2, -y, x - C(1.0)), C(1.0 / 3.0) * x}) {
    EXPECT_EQ(Parse(e.ToString()), e) << e.ToString();
  }
}

// --- evaluation ------------------------------------------------------------------------------

TEST(ExpressionTest, EvaluateFollowsIeee) {
  const std::vector<double> env = {2.0, 0.0, -1.0, 0.5};
  EXPECT_EQ((x * x + y).Evaluate(env), 4.0);
  EXPECT_EQ((C(1.0) / y).Evaluate(env), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(Fn(Op::kLog, z).Evaluate(env)));
  EXPECT_TRUE(std::isnan(Fn(Op::kSqrt, z).Evaluate(env)));
  EXPECT_EQ(Fn(Op::kSign, z).Evaluate(env), -1.0);
  EXPECT_EQ(Fn(Op::kSign, y).Evaluate(env), 0.0);
  EXPECT_EQ(Fn(Op::kMin, x, z).Evaluate(env), -1.0);
  EXPECT_EQ(Fn(Op::kMax, x, z).Evaluate(env), 2.0);
  EXPECT_EQ(Pow(x, C(3.0)).Evaluate(env), 8.0);
  EXPECT_DOUBLE_EQ(Fn(Op::kAtan2, C(1.0), C(-1.0)).Evaluate(env), 3.0 * std::atan(1.0));
  EXPECT_EQ(Fn(Op::kAbs, z).Evaluate(env), 1.0);
  EXPECT_EQ((-w).Evaluate(env), -0.5);
}

TEST(ExpressionTest, EvaluateIntervalExamples) {
  const std::vector<Interval> box = {Interval(-1.0, 2.0), Interval(0.5, 1.0), Interval(-3.0, -2.0),
                                     Interval(0.0)};
  const Interval sq = (x * x).EvaluateInterval(box);  // dependency problem: [-2, 4]
  EXPECT_TRUE(sq.Contains(Interval(-2.0, 4.0)));
  const Interval p = Pow(x, C(2.0)).EvaluateInterval(box);  // [0, 4]
  EXPECT_TRUE(p.Contains(Interval(0.0, 4.0)));
  EXPECT_GE(p.lo(), -1e-300);
  EXPECT_LE(p.hi(), 4.0 + 1e-12);
  const Interval s = Fn(Op::kSign, z).EvaluateInterval(box);
  EXPECT_EQ(s, Interval(-1.0));
  const Interval s2 = Fn(Op::kSign, x).EvaluateInterval(box);
  EXPECT_EQ(s2, Interval(-1.0, 1.0));
  const Interval q = (C(1.0) / x).EvaluateInterval(box);
  EXPECT_EQ(q, Interval::Entire());
  const Interval r = (C(1.0) / y).EvaluateInterval(box);
  EXPECT_TRUE(r.Contains(Interval(1.0, 2.0)));
  EXPECT_LE(r.width(), 1.0 + 1e-12);
}

// --- Slots, AsAffine, Derivative, Substitute, FoldConstants -----------------------------------

TEST(ExpressionTest, Slots) {
  EXPECT_EQ(C(3.0).Slots(), std::vector<int>{});
  EXPECT_EQ(x.Slots(), std::vector<int>{0});
  EXPECT_EQ((w + Fn(Op::kSin, x) * w).Slots(), (std::vector<int>{0, 3}));
  EXPECT_EQ(Fn(Op::kAtan2, z, y - x).Slots(), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(Expression::Symbol("q", 17).Slots(), std::vector<int>{17});
}

TEST(ExpressionAffineTest, Examples) {
  // 2 * (x + 3) / 4 = 0.5 x + 1.5
  EXPECT_EQ((C(2.0) * (x + C(3.0)) / C(4.0)).AsAffine(), (AffineForm{1.5, {{0, 0.5}}}));
  EXPECT_EQ((x - x).AsAffine(), (AffineForm{0.0, {}}));
  EXPECT_EQ((y + x).AsAffine(), (AffineForm{0.0, {{0, 1.0}, {1, 1.0}}}));
  EXPECT_EQ((C(3.0) - (y - C(2.0) * x)).AsAffine(), (AffineForm{3.0, {{0, 2.0}, {1, -1.0}}}));
  EXPECT_EQ((-(x - C(1.0))).AsAffine(), (AffineForm{1.0, {{0, -1.0}}}));
  EXPECT_EQ(Pow(x, C(1.0)).AsAffine(), (AffineForm{0.0, {{0, 1.0}}}));
  EXPECT_EQ((Fn(Op::kSin, C(0.0)) + Pow(C(2.0), C(3.0)) * z).AsAffine(),
            (AffineForm{0.0, {{2, 8.0}}}));
  EXPECT_EQ((C(0.0) * x + w).AsAffine(), (AffineForm{0.0, {{3, 1.0}}}));
  EXPECT_EQ(C(7.0).AsAffine(), (AffineForm{7.0, {}}));
}

TEST(ExpressionAffineTest, NonAffine) {
  EXPECT_FALSE((x * y).AsAffine().has_value());
  EXPECT_FALSE(Fn(Op::kSin, x).AsAffine().has_value());
  EXPECT_FALSE(Pow(x, C(2.0)).AsAffine().has_value());
  EXPECT_FALSE((C(1.0) / x).AsAffine().has_value());
  EXPECT_FALSE((x / C(0.0)).AsAffine().has_value());
  EXPECT_FALSE((x / (C(2.0) - C(2.0))).AsAffine().has_value());
  EXPECT_FALSE(Fn(Op::kAbs, x).AsAffine().has_value());
  EXPECT_FALSE(Fn(Op::kMin, x, C(1.0)).AsAffine().has_value());
  EXPECT_FALSE((x + Fn(Op::kLog, C(-1.0))).AsAffine().has_value());  // NaN constant
}

TEST(ExpressionDerivativeTest, Examples) {
  EXPECT_EQ(C(5.0).Derivative(0), C(0.0));
  EXPECT_EQ(x.Derivative(0), C(1.0));
  EXPECT_EQ(x.Derivative(1), C(0.0));
  EXPECT_EQ((x * y).Derivative(0), y);
  EXPECT_EQ((x * y).Derivative(1), x);
  EXPECT_EQ((x + y).Derivative(2), C(0.0));
  EXPECT_EQ(Fn(Op::kSin, x).Derivative(0), Fn(Op::kCos, x));
  EXPECT_EQ(Fn(Op::kSin, y).Derivative(0), C(0.0));
  EXPECT_EQ(Fn(Op::kExp, x).Derivative(0), Fn(Op::kExp, x));
  EXPECT_EQ(Fn(Op::kAbs, x).Derivative(0), Fn(Op::kSign, x));
  EXPECT_EQ(Fn(Op::kSign, x).Derivative(0), C(0.0));
  EXPECT_EQ((-x).Derivative(0), C(-1.0));
  EXPECT_EQ((x - y).Derivative(1), C(-1.0));
}

TEST(ExpressionDerivativeTest, Values) {
  const std::vector<double> env = {2.0, 3.0, 0.5, -1.0};
  EXPECT_DOUBLE_EQ(Pow(x, C(3.0)).Derivative(0).Evaluate(env), 12.0);
  EXPECT_DOUBLE_EQ(Pow(x, y).Derivative(0).Evaluate(env), 3.0 * 4.0);            // y x^(y-1)
  EXPECT_DOUBLE_EQ(Pow(x, y).Derivative(1).Evaluate(env), 8.0 * std::log(2.0));  // x^y log x
  EXPECT_DOUBLE_EQ((x / y).Derivative(1).Evaluate(env), -2.0 / 9.0);
  EXPECT_DOUBLE_EQ(Fn(Op::kLog, x).Derivative(0).Evaluate(env), 0.5);
  EXPECT_DOUBLE_EQ(Fn(Op::kSqrt, x).Derivative(0).Evaluate(env), 0.5 / std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(Fn(Op::kTan, z).Derivative(2).Evaluate(env),
                   1.0 / (std::cos(0.5) * std::cos(0.5)));
  EXPECT_DOUBLE_EQ(Fn(Op::kCos, x * y).Derivative(0).Evaluate(env), -3.0 * std::sin(6.0));
  // atan2(y, x): d/dy = x / (x^2 + y^2), d/dx = -y / (x^2 + y^2).
  EXPECT_DOUBLE_EQ(Fn(Op::kAtan2, y, x).Derivative(1).Evaluate(env), 2.0 / 13.0);
  EXPECT_DOUBLE_EQ(Fn(Op::kAtan2, y, x).Derivative(0).Evaluate(env), -3.0 / 13.0);
  // Subgradients of min and max: the derivative of the active argument.
  EXPECT_EQ(Fn(Op::kMin, x, y).Derivative(0).Evaluate(env), 1.0);
  EXPECT_EQ(Fn(Op::kMin, x, y).Derivative(1).Evaluate(env), 0.0);
  EXPECT_EQ(Fn(Op::kMax, x, y).Derivative(0).Evaluate(env), 0.0);
  EXPECT_EQ(Fn(Op::kMax, x, y).Derivative(1).Evaluate(env), 1.0);
  EXPECT_EQ(Fn(Op::kMax, x, x).Derivative(0).Evaluate(env), 1.0);
  EXPECT_EQ(Fn(Op::kAbs, w).Derivative(3).Evaluate(env), -1.0);
}

TEST(ExpressionTest, Substitute) {
  const Expression e = x * Fn(Op::kSin, y) + x;
  const Expression s = e.Substitute([](const std::string& name, int) -> std::optional<Expression> {
    if (name == "x") return C(2.0) + z;
    return std::nullopt;
  });
  EXPECT_EQ(s, (C(2.0) + z) * Fn(Op::kSin, y) + (C(2.0) + z));
  EXPECT_EQ(e.Substitute([](const std::string&, int) { return std::optional<Expression>(); }), e);
}

TEST(ExpressionTest, FoldConstants) {
  EXPECT_EQ((C(2.0) * C(3.0) + x).FoldConstants(), C(6.0) + x);
  EXPECT_EQ((x * (C(1.0) + C(1.0))).FoldConstants(), x * C(2.0));
  EXPECT_EQ(Fn(Op::kSin, Pow(C(2.0), C(-1.0))).FoldConstants(), C(std::sin(0.5)));
  EXPECT_EQ((x + C(1.0) * C(2.0)).FoldConstants(), x + C(2.0));
  // Non-finite results stay unfolded, but a finite result above them folds.
  EXPECT_EQ((C(1.0) / C(0.0)).FoldConstants(), C(1.0) / C(0.0));
  EXPECT_EQ(Fn(Op::kLog, C(-1.0)).FoldConstants(), Fn(Op::kLog, C(-1.0)));
  EXPECT_EQ(Fn(Op::kSign, Fn(Op::kLog, C(0.0))).FoldConstants(), C(-1.0));
  EXPECT_EQ(Fn(Op::kMin, C(1.0) / C(0.0), C(2.0) + C(1.0)).FoldConstants(), C(3.0));
  EXPECT_EQ((x * Fn(Op::kExp, -(C(1.0) / C(0.0)))).FoldConstants(), x * C(0.0));
}

// --- properties ------------------------------------------------------------------------------

RC_GTEST_PROP(ExpressionProperty, PrintThenParseGivesTheSameTree, ()) {
  const Expression e = *GenExpression(5);
  const std::string text = e.ToString();
  RC_LOG() << text << "\n";
  const Expression parsed = Parse(text);
  RC_ASSERT(parsed == e);
  RC_ASSERT(parsed.ToString() == text);
}

RC_GTEST_PROP(ExpressionProperty, IntervalEvaluationEnclosesPointEvaluation, ()) {
  const Expression e = *GenExpression(4);
  const double scale = *rc::gen::element(1.0, 4.0, 100.0);
  std::vector<Interval> box;
  for (int i = 0; i < 4; ++i) box.push_back(*GenInterval(scale));
  const Interval enclosure = e.EvaluateInterval(box);
  int checked = 0;
  for (int k = 0; k < 16; ++k) {
    std::vector<double> point;
    for (const Interval& side : box) point.push_back(*GenPointIn(side));
    const double v = e.Evaluate(point);
    if (!std::isfinite(v) || HasNanSubexpression(e, point)) continue;
    ++checked;
    RC_ASSERT(enclosure.Contains(v));
  }
  RC_CLASSIFY(checked == 0, "no finite point");
}

RC_GTEST_PROP(ExpressionProperty, DerivativeMatchesCentralDifferences, ()) {
  const Expression e = *GenSmoothExpression(4);
  const int slot = *GenInt(0, 4);
  std::vector<double> point;
  for (int i = 0; i < 4; ++i) point.push_back(*GenReal(-2.0, 2.0));
  const double d = e.Derivative(slot).Evaluate(point);
  RC_ASSERT(std::isfinite(d));
  const auto f = [&](double offset) {
    std::vector<double> p = point;
    p[slot] += offset;
    return e.Evaluate(p);
  };
  const auto central = [&](double h) { return (f(h) - f(-h)) / (2.0 * h); };
  const double h = 1e-6 * std::max(1.0, std::abs(point[slot]));
  const double fd = central(h);
  const double magnitude = std::max(std::abs(f(h)), std::abs(f(-h)));
  const double tolerance = 1e-5 * (1.0 + std::abs(d)) + 1e-8 * magnitude;
  // Where the function varies too fast for the difference quotient to have converged (huge
  // higher derivatives of nested powers), compare nothing rather than a wrong reference.
  const bool converged = std::abs(fd - central(4.0 * h)) <= tolerance;
  RC_CLASSIFY(!converged, "difference quotient not converged");
  if (converged) RC_ASSERT(std::abs(d - fd) <= tolerance);
}

RC_GTEST_PROP(ExpressionProperty, DerivativeOfAnUnreadSlotIsZero, ()) {
  const Expression e = *GenExpression(4);
  const std::vector<int> slots = e.Slots();
  for (int slot = 0; slot < 6; ++slot) {
    if (std::find(slots.begin(), slots.end(), slot) != slots.end()) continue;
    RC_ASSERT(e.Derivative(slot) == Expression::Constant(0.0));
  }
}

/// Expressions that are affine by construction: sums, differences and negations of constant
/// multiples of symbols, divisions by non-zero constants, constant subexpressions.
Expression RandomAffine(int depth) {
  if (depth <= 0 || *GenInt(0, 4) == 0) {
    if (*GenInt(0, 3) == 0) return Expression::Constant(*testing::GenConstant());
    const int slot = *GenInt(0, 4);
    return Expression::Symbol(testing::kSymbolNames[slot], slot);
  }
  switch (*GenInt(0, 8)) {
    case 0:
      return -RandomAffine(depth - 1);
    case 1:
      return RandomAffine(depth - 1) + RandomAffine(depth - 1);
    case 2:
      return RandomAffine(depth - 1) - RandomAffine(depth - 1);
    case 3:
      return C(*GenInt(-4, 5) / 2.0) * RandomAffine(depth - 1);
    case 4:
      return RandomAffine(depth - 1) * C(*GenInt(1, 20) / 4.0);
    case 5:
      return RandomAffine(depth - 1) / C(*rc::gen::element(2.0, 3.0, -0.5, 10.0));
    case 6:
      return Pow(RandomAffine(depth - 1), C(1.0));
    default:
      return Fn(Op::kCos, C(*GenInt(0, 4))) * RandomAffine(depth - 1);
  }
}

/// The largest finite magnitude of `e` and its subexpressions at `env`: evaluating `e` may lose
/// about eps times this to cancellation (x + 1e20 - 1e20), which an affine form does not.
double LargestMagnitude(const Expression& e, std::span<const double> env) {
  const double v = std::abs(e.Evaluate(env));
  double m = std::isfinite(v) ? v : 0.0;
  for (const Expression& a : e.args()) m = std::max(m, LargestMagnitude(a, env));
  return m;
}

void CheckAffineForm(const Expression& e, const AffineForm& form) {
  for (size_t i = 0; i < form.terms.size(); ++i) {
    RC_ASSERT(form.terms[i].second != 0.0);
    if (i > 0) RC_ASSERT(form.terms[i - 1].first < form.terms[i].first);
  }
  for (int k = 0; k < 8; ++k) {
    std::vector<double> point;
    for (int i = 0; i < 4; ++i) point.push_back(*GenReal(-100.0, 100.0));
    const double expected = e.Evaluate(point);
    if (!std::isfinite(expected)) continue;
    double value = form.constant;
    double scale = std::abs(form.constant);
    for (const auto& [slot, c] : form.terms) {
      value += c * point[slot];
      scale += std::abs(c * point[slot]);
    }
    scale = std::max(scale, LargestMagnitude(e, point));
    RC_ASSERT(std::abs(value - expected) <= 1e-9 * (1.0 + scale + std::abs(expected)));
  }
}

RC_GTEST_PROP(ExpressionProperty, AffineFormsEvaluateLikeTheExpression, ()) {
  const Expression e = *GenExpression(4);
  const auto form = e.AsAffine();
  RC_CLASSIFY(form.has_value(), "affine");
  if (form) CheckAffineForm(e, *form);
}

RC_GTEST_PROP(ExpressionProperty, AffineExpressionsHaveAnAffineForm, ()) {
  const Expression e = *rc::gen::exec([] { return RandomAffine(5); });
  RC_LOG() << e.ToString() << "\n";
  const auto form = e.AsAffine();
  RC_ASSERT(form.has_value());
  CheckAffineForm(e, *form);
}

RC_GTEST_PROP(ExpressionProperty, FoldConstantsKeepsValuesAndSlots, ()) {
  const Expression e = *GenExpression(5);
  const Expression folded = e.FoldConstants();
  RC_ASSERT(folded.Slots() == e.Slots());
  if (e.Slots().empty()) RC_ASSERT(folded.is_constant() || !std::isfinite(e.Evaluate({})));
  std::vector<double> point;
  for (int i = 0; i < 4; ++i) point.push_back(*GenReal(-3.0, 3.0));
  const double a = e.Evaluate(point);
  const double b = folded.Evaluate(point);
  RC_ASSERT((a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b)));
}

RC_GTEST_PROP(ExpressionProperty, SlotsAreTheSymbolsRead, ()) {
  const Expression e = *GenExpression(5);
  const std::vector<int> slots = e.Slots();
  RC_ASSERT(std::is_sorted(slots.begin(), slots.end()));
  RC_ASSERT(std::adjacent_find(slots.begin(), slots.end()) == slots.end());
  // Replacing every symbol by a constant leaves no slots; replacing one slot removes exactly it.
  const Expression closed =
      e.Substitute([](const std::string&, int) -> std::optional<Expression> { return C(1.0); });
  RC_ASSERT(closed.Slots().empty());
  for (int slot : slots) {
    const Expression without = e.Substitute([slot](const std::string&, int s) {
      return s == slot ? std::optional<Expression>(C(2.0)) : std::nullopt;
    });
    std::vector<int> expected = slots;
    std::erase(expected, slot);
    RC_ASSERT(without.Slots() == expected);
  }
}

}  // namespace
}  // namespace hybrid
