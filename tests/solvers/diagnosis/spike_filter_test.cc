#include "hybrid/diagnosis/spike_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<int> Flagged(const std::vector<char>& mask) {
  std::vector<int> out;
  for (size_t k = 0; k < mask.size(); ++k) {
    if (mask[k]) out.push_back(static_cast<int>(k));
  }
  return out;
}

TEST(SpikeMask, CatchesSingleSpikesAndAdjacentPairs) {
  std::vector<double> x(20, 0.0);
  x[3] = 10;
  x[10] = 8, x[11] = -9;  // an adjacent pair, of either sign
  EXPECT_EQ(Flagged(SpikeMask(x, 4.0)), (std::vector<int>{3, 10, 11}));
}

TEST(SpikeMask, CatchesPairsAtTheRunsEnds) {
  std::vector<double> x(12, 1.0);
  x[0] = x[1] = 9;     // the window is shifted inside the run: samples 0..4
  x[10] = x[11] = -7;  // samples 7..11
  EXPECT_EQ(Flagged(SpikeMask(x, 4.0)), (std::vector<int>{0, 1, 10, 11}));
}

TEST(SpikeMask, KeepsStepsRampsAndSmallDeviations) {
  std::vector<double> x;
  for (int k = 0; k < 10; ++k) x.push_back(0.0);
  for (int k = 0; k < 10; ++k) x.push_back(20.0);             // a level step
  for (int k = 1; k <= 10; ++k) x.push_back(20.0 + 5.0 * k);  // a steep ramp, then a level
  for (int k = 0; k < 5; ++k) x.push_back(70.0);
  x[5] = 3.9;  // within the threshold
  EXPECT_TRUE(Flagged(SpikeMask(x, 4.0)).empty());
}

TEST(SpikeMask, SkipsMissingSamplesAndBadThresholds) {
  std::vector<double> x = {0, kNaN, 0, 0, 12, kNaN, 0, 0, 0};
  const std::vector<char> mask = SpikeMask(x, 4.0);
  EXPECT_EQ(Flagged(mask), std::vector<int>{4});  // the window is the non-missing neighbours
  EXPECT_TRUE(Flagged(SpikeMask(x, 0.0)).empty());
  EXPECT_TRUE(Flagged(SpikeMask(x, std::numeric_limits<double>::infinity())).empty());
  EXPECT_TRUE(Flagged(SpikeMask({0, 100}, 1.0)).empty());  // too short for a median
  EXPECT_EQ(SpikeMask({}, 1.0).size(), 0u);
}

}  // namespace
}  // namespace hybrid
