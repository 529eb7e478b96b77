// Tests of PartitionIndex (gripper/partition_index.h) against std::partition_point over the
// predicate's values written out, and of its number of calls.

#include "gripper/partition_index.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hybrid {
namespace {

// For a range [lo, hi) and a predicate true below `cut`: the index std::partition_point gives on
// the predicate's values, and at most ceil(log2(hi - lo + 1)) calls.
RC_GTEST_PROP(PartitionIndexProperty, IsThePartitionPointOfThePredicatesValues, ()) {
  const long lo = *rc::gen::inRange<long>(-50, 50);
  const long hi = lo + *rc::gen::inRange<long>(0, 2000);
  const long cut = *rc::gen::inRange<long>(lo - 5, hi + 5);
  std::vector<bool> values;
  for (long j = lo; j < hi; ++j) values.push_back(j < cut);
  const long expected =
      lo + (std::partition_point(values.begin(), values.end(), [](bool v) { return v; }) -
            values.begin());
  int calls = 0;
  const long got = PartitionIndex(lo, hi, [&](long j) {
    RC_ASSERT(j >= lo);
    RC_ASSERT(j < hi);
    ++calls;
    return j < cut;
  });
  RC_ASSERT(got == expected);
  RC_ASSERT(calls <= static_cast<int>(std::ceil(std::log2(static_cast<double>(hi - lo + 1)))));
}

TEST(PartitionIndex, EmptyRangeAndAllTrueGiveTheEnd) {
  EXPECT_EQ(PartitionIndex(3, 3, [](long) { return false; }), 3);
  EXPECT_EQ(PartitionIndex(0, 10, [](long) { return true; }), 10);
  EXPECT_EQ(PartitionIndex(0, 10, [](long) { return false; }), 0);
}

}  // namespace
}  // namespace hybrid
