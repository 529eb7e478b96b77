#include "automaton/spaceex/sx_formula.h"

#include <gtest/gtest.h>

#include <string>

namespace hybrid::spaceex {
namespace {

using Kind = SxFormula::Kind;

std::string Written(const std::string& expression) {
  return WriteExpression(SxFormula::ParseExpression(expression),
                         [](const SxFormula& n) { return n.text; });
}

std::size_t ErrorOffset(const std::string& text) {
  try {
    SxFormula::Parse(text);
  } catch (const FormulaError& e) {
    return e.offset();
  }
  ADD_FAILURE() << "no error for: " << text;
  return 0;
}

TEST(SxFormulaTest, ConjunctionsOfFlowsAndAssignments) {
  const SxFormula f = SxFormula::Parse("x' == v & v' == -g && t' == 1");
  ASSERT_EQ(f.kind, Kind::kAnd);
  const auto atoms = f.Conjuncts();
  ASSERT_EQ(atoms.size(), 3u);
  EXPECT_EQ(atoms[0]->children[0].text, "x");
  EXPECT_TRUE(atoms[0]->children[0].primed);
  EXPECT_EQ(atoms[1]->children[1].kind, Kind::kNegate);
  EXPECT_TRUE(f.HasPrime());
  const SxFormula a = SxFormula::Parse("v := -v * 0.5 & x := x");
  ASSERT_EQ(a.Conjuncts().size(), 2u);
  EXPECT_EQ(a.Conjuncts()[0]->kind, Kind::kAssign);
  EXPECT_FALSE(a.HasPrime());
  EXPECT_TRUE(SxFormula::Parse("true").Conjuncts().empty());
}

TEST(SxFormulaTest, LocationsDisjunctionsAndParentheses) {
  const SxFormula f = SxFormula::Parse("loc(P1) == cs & (loc(P2)==cs | x >= (1 + 2) * 3)");
  ASSERT_EQ(f.kind, Kind::kAnd);
  EXPECT_EQ(f.children[0].kind, Kind::kLocation);
  EXPECT_EQ(f.children[0].text, "P1");
  EXPECT_EQ(f.children[0].children[0].text, "cs");
  ASSERT_EQ(f.children[1].kind, Kind::kOr);
  EXPECT_EQ(f.children[1].children[1].kind, Kind::kCompare);
  EXPECT_EQ(SxFormula::Parse("loc() == on").text, "");
  EXPECT_EQ(SxFormula::Parse("P1.x <= 2").children[0].text, "P1.x");
}

TEST(SxFormulaTest, WritesTheFewestParenthesesThatKeepTheTree) {
  EXPECT_EQ(Written("a - (b - c)"), "a - (b - c)");
  EXPECT_EQ(Written("(a - b) - c"), "a - b - c");
  EXPECT_EQ(Written("-(a * b)"), "-(a * b)");
  EXPECT_EQ(Written("(-a) * b"), "-a * b");
  EXPECT_EQ(Written("a / (b * c)"), "a / (b * c)");
  EXPECT_EQ(Written("(a ^ b) ^ c"), "(a ^ b) ^ c");
  EXPECT_EQ(Written("a ^ b ^ c"), "a ^ b ^ c");
  EXPECT_EQ(Written("2 ^ -3"), "2 ^ (-3)");
  EXPECT_EQ(Written("-x ^ 2"), "-x ^ 2");
  EXPECT_EQ(Written("min(a, b + 1) * +3"), "min(a, b + 1) * 3");
  EXPECT_EQ(Written("1. + 2.e3 + .5"), "1.0 + 2.0e3 + .5");
}

TEST(SxFormulaTest, ErrorsPointAtTheOffendingByte) {
  EXPECT_EQ(ErrorOffset("x' == 1 & y"), 11u);
  EXPECT_EQ(ErrorOffset("x = 1"), 2u);
  EXPECT_EQ(ErrorOffset("x != 1"), 2u);
  EXPECT_EQ(ErrorOffset("x <= 1)"), 6u);
  EXPECT_EQ(ErrorOffset("x <= $"), 5u);
  EXPECT_EQ(ErrorOffset("loc(P1) == 3"), 11u);
  EXPECT_LT(ErrorOffset(std::string(300, '(') + "x"), 300u);  // nested too deeply
  EXPECT_NO_THROW(SxFormula::Parse(std::string(40, '(') + "x == 1" + std::string(40, ')')));
}

}  // namespace
}  // namespace hybrid::spaceex
