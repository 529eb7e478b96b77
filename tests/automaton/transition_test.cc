#include "hybrid/automaton/transition.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(TransitionTest, DefaultsToUrgentWithTrueGuard) {
  Transition t;
  EXPECT_EQ(t.urgency, Urgency::kUrgent);
  EXPECT_TRUE(t.guard.empty());
  EXPECT_FALSE(t.source.is_valid());
}

TEST(TransitionTest, EqualityCoversEveryField) {
  Transition a;
  a.name = "t";
  a.source = ModeId(0);
  a.target = ModeId(1);
  Transition b = a;
  EXPECT_EQ(a, b);
  b.urgency = Urgency::kLazy;
  EXPECT_FALSE(a == b);
  b = a;
  b.resets.push_back({0, Expression::Constant(1)});
  EXPECT_FALSE(a == b);
}

}  // namespace
}  // namespace hybrid
