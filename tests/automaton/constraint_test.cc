#include "hybrid/automaton/constraint.h"

#include <gtest/gtest.h>

#include <vector>

namespace hybrid {
namespace {

Comparison XRel(Relation r) { return {Expression::Symbol("x", 0), r, Expression::Constant(1)}; }

// On the boundary (x = 1) and within / beyond the tolerance.
TEST(ConstraintTest, StrictAndNonStrictDifferOnlyOnTheBoundary) {
  const std::vector<double> on = {1.0}, near = {1.0 + 1e-10}, above = {2.0}, below = {0.0};
  EXPECT_TRUE(XRel(Relation::kLessEqual).Holds(on));
  EXPECT_FALSE(XRel(Relation::kLess).Holds(on));
  EXPECT_TRUE(XRel(Relation::kGreaterEqual).Holds(on));
  EXPECT_FALSE(XRel(Relation::kGreater).Holds(on));
  EXPECT_TRUE(XRel(Relation::kEqual).Holds(on));
  EXPECT_FALSE(XRel(Relation::kLessEqual).Holds(near));
  EXPECT_TRUE(XRel(Relation::kLessEqual).Holds(near, 1e-9));
  EXPECT_FALSE(XRel(Relation::kLess).Holds(near, 1e-9));
  EXPECT_TRUE(XRel(Relation::kEqual).Holds(near, 1e-9));
  EXPECT_TRUE(XRel(Relation::kGreater).Holds(above));
  EXPECT_TRUE(XRel(Relation::kLess).Holds(below));
}

TEST(ConstraintTest, ConjunctionAndPrinting) {
  Constraint c;
  EXPECT_TRUE(c.Holds(std::vector<double>{5.0}));
  EXPECT_EQ(c.ToString(), "true");
  c.comparisons = {XRel(Relation::kGreaterEqual), XRel(Relation::kLess)};
  EXPECT_FALSE(c.Holds(std::vector<double>{1.0}));
  EXPECT_EQ(c.ToString(), "x >= 1 and x < 1");
  EXPECT_EQ(XRel(Relation::kEqual).Residual().ToString(), "x - 1");
}

}  // namespace
}  // namespace hybrid
