#include "hybrid/automaton/scenario.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(ScenarioTest, StepSignalHoldsEachValueFromItsTime) {
  const InputSignal s{0, InputSignal::Shape::kStep, {{0.0, 1.0}, {255.0, 0.0}, {265.0, -1.0}}};
  EXPECT_EQ(s.ValueAt(-1.0), 1.0);
  EXPECT_EQ(s.ValueAt(0.0), 1.0);
  EXPECT_EQ(s.ValueAt(254.999), 1.0);
  EXPECT_EQ(s.ValueAt(255.0), 0.0);
  EXPECT_EQ(s.ValueAt(300.0), -1.0);
}

TEST(ScenarioTest, LinearSignalInterpolatesAndHoldsOutside) {
  const InputSignal s{0, InputSignal::Shape::kLinear, {{0.0, 0.0}, {10.0, 1.0}, {20.0, -1.0}}};
  EXPECT_DOUBLE_EQ(s.ValueAt(-5.0), 0.0);
  EXPECT_DOUBLE_EQ(s.ValueAt(5.0), 0.5);
  EXPECT_DOUBLE_EQ(s.ValueAt(15.0), 0.0);
  EXPECT_DOUBLE_EQ(s.ValueAt(25.0), -1.0);
}

}  // namespace
}  // namespace hybrid
