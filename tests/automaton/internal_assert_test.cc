// Tests of HYBRID_ASSERT (automaton/internal_assert.h): a holding condition does nothing and
// evaluates once; a broken one throws InternalError naming the invariant and the position.

#include "automaton/internal_assert.h"

#include <gtest/gtest.h>

#include <string>

namespace hybrid {
namespace {

TEST(InternalAssert, HoldingConditionEvaluatedOnce) {
  int calls = 0;
  HYBRID_ASSERT(++calls == 1, "evaluated once");
  EXPECT_EQ(calls, 1);
}

TEST(InternalAssert, BrokenConditionThrowsWithPosition) {
  const int index = 3;
  try {
    HYBRID_ASSERT(index < 2, "the mode index is in range");
    ADD_FAILURE() << "no exception";
  } catch (const InternalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("internal error"), std::string::npos) << what;
    EXPECT_NE(what.find("the mode index is in range"), std::string::npos) << what;
    EXPECT_NE(what.find("index < 2"), std::string::npos) << what;
    EXPECT_NE(what.find("internal_assert_test.cc:"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace hybrid
