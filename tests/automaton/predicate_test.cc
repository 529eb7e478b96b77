#include "hybrid/automaton/predicate.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hybrid {
namespace {

Predicate X(Relation r, double v) {
  return Predicate::Compare({Expression::Symbol("x", 0), r, Expression::Constant(v)});
}

TEST(PredicateTest, EvaluatesConnectivesAndModes) {
  const std::vector<double> env = {2.0};
  const std::vector<std::string> modes = {"on"};
  EXPECT_TRUE(
      Predicate::And(X(Relation::kGreater, 1), Predicate::InMode("on")).Evaluate(env, modes));
  EXPECT_FALSE(
      Predicate::And(X(Relation::kGreater, 1), Predicate::InMode("off")).Evaluate(env, modes));
  EXPECT_TRUE(Predicate::Or(X(Relation::kLess, 1), Predicate::True()).Evaluate(env, modes));
  EXPECT_TRUE(Predicate::Not(Predicate::False()).Evaluate(env, modes));
}

TEST(PredicateTest, PrintsWithMinimalParentheses) {
  const Predicate a = X(Relation::kLess, 1), b = X(Relation::kGreater, 2),
                  c = Predicate::InMode("m");
  EXPECT_EQ(Predicate::Or(Predicate::And(a, b), c).ToString(), "x < 1 and x > 2 or in m");
  EXPECT_EQ(Predicate::And(Predicate::Or(a, b), c).ToString(), "(x < 1 or x > 2) and in m");
  EXPECT_EQ(Predicate::Not(Predicate::And(a, b)).ToString(), "not (x < 1 and x > 2)");
  EXPECT_EQ(Predicate::And(a, Predicate::And(b, c)).ToString(), "x < 1 and (x > 2 and in m)");
}

TEST(PredicateTest, VisitsComparisonsAndModes) {
  const Predicate p = Predicate::Or(X(Relation::kLess, 1), Predicate::Not(Predicate::InMode("m")));
  int comparisons = 0;
  std::vector<std::string> modes;
  p.ForEachComparison([&](const Comparison&) { ++comparisons; });
  p.ForEachMode([&](const std::string& m) { modes.push_back(m); });
  EXPECT_EQ(comparisons, 1);
  EXPECT_EQ(modes, std::vector<std::string>{"m"});
  EXPECT_EQ(p, Predicate::Or(X(Relation::kLess, 1), Predicate::Not(Predicate::InMode("m"))));
  EXPECT_FALSE(p == Predicate::Or(X(Relation::kLess, 2), Predicate::Not(Predicate::InMode("m"))));
}

}  // namespace
}  // namespace hybrid
