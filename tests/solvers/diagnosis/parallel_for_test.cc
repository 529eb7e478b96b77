#include "hybrid/diagnosis/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace hybrid {
namespace {

TEST(ParallelFor, CallsEveryIndexOnceWhateverTheThreads) {
  for (int threads : {0, 1, 2, 5}) {
    for (int count : {0, 1, 7, 100}) {
      std::vector<std::atomic<int>> calls(count);
      ParallelFor(count, threads, [&](int i) { ++calls[i]; });
      for (int i = 0; i < count; ++i) EXPECT_EQ(calls[i], 1) << threads << " " << count;
    }
  }
}

TEST(ParallelFor, RethrowsTheFirstErrorAfterTheOthersRan) {
  std::atomic<int> calls{0};
  EXPECT_THROW(ParallelFor(50, 3,
                           [&](int i) {
                             ++calls;
                             if (i == 10) throw std::runtime_error("ten");
                           }),
               std::runtime_error);
  EXPECT_EQ(calls, 50);
}

}  // namespace
}  // namespace hybrid
