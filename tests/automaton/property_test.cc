#include "hybrid/automaton/property.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(PropertyTest, KeywordsAndEquality) {
  EXPECT_EQ(KindKeyword(Property::Kind::kAlways), "always");
  EXPECT_EQ(KindKeyword(Property::Kind::kNever), "never");
  EXPECT_EQ(KindKeyword(Property::Kind::kReach), "reach");
  const Property a{"p", Property::Kind::kNever, Predicate::InMode("m"), 5.0};
  Property b = a;
  EXPECT_EQ(a, b);
  b.horizon.reset();
  EXPECT_FALSE(a == b);
}

}  // namespace
}  // namespace hybrid
