// Tests of ReachMeter (solvers/reachability/reach_meter.h): shares, slices, and a slice that an
// exploration left behind not carrying over to the next share.

#include "solvers/reachability/reach_meter.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(ReachMeter, SlicesEndWithinTheShareAndDoNotCarryOver) {
  ReachMeter meter(1000, 60.0);
  meter.ShareAmong(2);  // 500 units
  EXPECT_EQ(meter.share(), 500u);
  meter.SetSlice(100);
  EXPECT_FALSE(meter.Exhausted());
  meter.Boxes(50);  // 2 units each: 100
  EXPECT_TRUE(meter.Exhausted());
  EXPECT_FALSE(meter.ShareExhausted());
  meter.SetSlice(10'000);  // past the share: the share bounds it
  EXPECT_FALSE(meter.Exhausted());
  meter.Boxes(200);  // 500 in all
  EXPECT_TRUE(meter.Exhausted());
  EXPECT_TRUE(meter.ShareExhausted());
  // A slice left set is cleared by the next share.
  meter.SetSlice(1);
  meter.ShareAmong(1);  // the 500 left
  EXPECT_FALSE(meter.Exhausted());
  meter.Boxes(100);
  EXPECT_FALSE(meter.Exhausted());
  meter.ClearSlice();
  EXPECT_EQ(meter.used(), 700u);
}

}  // namespace
}  // namespace hybrid
