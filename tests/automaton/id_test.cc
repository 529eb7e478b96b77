#include "hybrid/automaton/id.h"

#include <gtest/gtest.h>

#include <type_traits>
#include <unordered_set>

namespace hybrid {
namespace {

TEST(IdTest, TypedOrderedHashable) {
  static_assert(!std::is_convertible_v<ModeId, TransitionId>);
  EXPECT_FALSE(ModeId().is_valid());
  EXPECT_LT(ModeId(1), ModeId(2));
  std::unordered_set<ModeId> set = {ModeId(3), ModeId(3), ModeId(4)};
  EXPECT_EQ(set.size(), 2u);
}

}  // namespace
}  // namespace hybrid
