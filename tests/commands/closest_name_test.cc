// Tests of the command suggestions (commands/closest_name.h) against distances counted by hand.

#include "commands/closest_name.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hybrid::cli {
namespace {

TEST(ClosestName, EditDistanceCountsEdits) {
  EXPECT_EQ(EditDistance("", ""), 0);
  EXPECT_EQ(EditDistance("abc", ""), 3);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);  // k->s, e->i, +g
  EXPECT_EQ(EditDistance("chekc", "check"), 1);     // one transposition
  EXPECT_EQ(EditDistance("simulat", "simulate"), 1);
  EXPECT_EQ(EditDistance("dot", "dot"), 0);
}

TEST(ClosestName, SuggestsTyposAndPrefixesOnly) {
  const std::vector<std::string> names = {"info",  "dot",    "import", "simulate",
                                          "check", "finger", "hand"};
  EXPECT_EQ(ClosestName("simulat", names), "simulate");
  EXPECT_EQ(ClosestName("sim", names), "simulate");  // a prefix
  EXPECT_EQ(ClosestName("chekc", names), "check");
  EXPECT_EQ(ClosestName("fnger", names), "finger");
  EXPECT_EQ(ClosestName("frobnicate", names), std::nullopt);
  EXPECT_EQ(ClosestName("", names), std::nullopt);
  EXPECT_EQ(ClosestName("xyz", names), std::nullopt);  // dot is 3 edits away, 1 allowed
}

}  // namespace
}  // namespace hybrid::cli
