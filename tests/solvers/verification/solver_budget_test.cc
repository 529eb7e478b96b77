// Tests of the solver budget (include/hybrid/verification/solver_budget.h): its size in resource
// units, what it refuses, charging and the observer, and the CPU-time safety net's limits.

#include "hybrid/verification/solver_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace hybrid {
namespace {

TEST(SolverBudget, HoldsItsSecondsInResourceUnits) {
  const SolverBudget budget(2.0);
  EXPECT_EQ(budget.seconds(), 2.0);
  EXPECT_EQ(budget.total(), 2 * kResourceUnitsPerBudgetSecond);
  EXPECT_EQ(budget.used(), 0u);
  EXPECT_EQ(budget.remaining(), budget.total());
  EXPECT_FALSE(budget.safety_stopped());
  // A fraction of a unit is rounded up.
  EXPECT_EQ(SolverBudget(1e-9).total(), 1u);
}

TEST(SolverBudget, RefusesSecondsOutOfRange) {
  EXPECT_THROW(SolverBudget(0.0), std::invalid_argument);
  EXPECT_THROW(SolverBudget(-1.0), std::invalid_argument);
  EXPECT_THROW(SolverBudget(std::nan("")), std::invalid_argument);
  EXPECT_THROW(SolverBudget{std::numeric_limits<double>::infinity()}, std::invalid_argument);
  EXPECT_THROW(SolverBudget(1e7), std::invalid_argument);
  EXPECT_NO_THROW(SolverBudget(1e6));
}

// The last charge may overdraw the budget: nothing is left then, not a negative amount.
TEST(SolverBudget, ChargesAreCountedAndObserved) {
  SolverBudget budget(1.0);
  std::vector<std::uint64_t> seen;
  budget.SetObserver([&seen](const SolverBudget& b) { seen.push_back(b.used()); });
  budget.Charge(1000);
  budget.Charge(kResourceUnitsPerBudgetSecond);
  EXPECT_EQ(budget.used(), 1000 + kResourceUnitsPerBudgetSecond);
  EXPECT_EQ(budget.remaining(), 0u);
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{1000, 1000 + kResourceUnitsPerBudgetSecond}));
  budget.NoteSafetyStop();
  EXPECT_TRUE(budget.safety_stopped());
}

// The safety net's CPU-time limits: 10 s per budget second of a query's units, at least 10 s,
// at most T = max(60 s, 10 s per budget second).
TEST(SolverBudget, SafetyLimitsFollowTheUnits) {
  const SolverBudget small(1.0);
  EXPECT_EQ(small.SafetySeconds(), 60.0);
  EXPECT_EQ(small.SafetyCpuSeconds(0), 10.0);
  EXPECT_EQ(small.SafetyCpuSeconds(3 * kResourceUnitsPerBudgetSecond), 30.0);
  EXPECT_EQ(small.SafetyCpuSeconds(100 * kResourceUnitsPerBudgetSecond), 60.0);
  const SolverBudget large(60.0);
  EXPECT_EQ(large.SafetySeconds(), 600.0);
  EXPECT_EQ(large.SafetyCpuSeconds(25'000'000), 100.0);
  EXPECT_FALSE(large.SafetyExpired());
}

}  // namespace
}  // namespace hybrid
