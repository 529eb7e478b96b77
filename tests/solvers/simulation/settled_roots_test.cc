// Tests of the settled root functions of exact segments (solvers/simulation/settled_roots.h).

#include "solvers/simulation/settled_roots.h"

#include <gtest/gtest.h>

#include "automaton/internal_assert.h"

namespace hybrid {
namespace {

TEST(SettledRootsTest, SettledAtOneInstantAndEventCount) {
  SettledRoots settled;
  EXPECT_FALSE(settled.IsSettled(0, 0.0, 0));
  settled.Settle(1.0, 2, 3, {0, 2});
  EXPECT_TRUE(settled.IsSettled(0, 1.0, 2));
  EXPECT_FALSE(settled.IsSettled(1, 1.0, 2));
  EXPECT_TRUE(settled.IsSettled(2, 1.0, 2));
  EXPECT_FALSE(settled.IsSettled(3, 1.0, 2));  // no such root function
  EXPECT_FALSE(settled.IsSettled(0, 1.5, 2));  // another instant
  EXPECT_FALSE(settled.IsSettled(0, 1.0, 3));  // a jump since
  // More at the same instant add to the marks; another instant starts afresh.
  settled.Settle(1.0, 2, 3, {1});
  EXPECT_TRUE(settled.IsSettled(0, 1.0, 2));
  EXPECT_TRUE(settled.IsSettled(1, 1.0, 2));
  settled.Settle(2.0, 2, 3, {1});
  EXPECT_FALSE(settled.IsSettled(0, 2.0, 2));
  EXPECT_TRUE(settled.IsSettled(1, 2.0, 2));
}

TEST(SettledRootsTest, AnInputJumpUnsettlesThemAll) {
  SettledRoots settled;
  settled.Settle(1.0, 0, 2, {0, 1});
  settled.Unsettle();
  EXPECT_FALSE(settled.IsSettled(0, 1.0, 0));
  EXPECT_FALSE(settled.IsSettled(1, 1.0, 0));
  settled.Settle(1.0, 0, 2, {1});
  EXPECT_FALSE(settled.IsSettled(0, 1.0, 0));
  EXPECT_TRUE(settled.IsSettled(1, 1.0, 0));
}

TEST(SettledRootsTest, AnUnknownRootFunctionIsABug) {
  SettledRoots settled;
  EXPECT_THROW(settled.Settle(1.0, 0, 2, {2}), InternalError);
}

}  // namespace
}  // namespace hybrid
