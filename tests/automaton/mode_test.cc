#include "hybrid/automaton/mode.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(ModeTest, FlowAndDiscreteLookUp) {
  Mode m;
  m.name = "m";
  m.flows = {{1, Expression::Constant(2)}};
  m.discrete_values = {{3, -1}};
  EXPECT_EQ(m.FlowOf(1), Expression::Constant(2));
  EXPECT_FALSE(m.FlowOf(0).has_value());  // no flow: the variable is constant in this mode
  EXPECT_EQ(m.DiscreteValueOf(3), -1);
  EXPECT_FALSE(m.DiscreteValueOf(4).has_value());
}

}  // namespace
}  // namespace hybrid
