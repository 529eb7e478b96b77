// Tests of the prover's jobs (solvers/verification/proof_job.h): a job and a goal start empty,
// and SecondsSince measures from its start.

#include "solvers/verification/proof_job.h"

#include <gtest/gtest.h>

#include <chrono>

namespace hybrid {
namespace {

TEST(ProofJob, StartsWithoutAutomatonOrGoals) {
  const ProofJob job;
  EXPECT_EQ(job.automaton, nullptr);
  EXPECT_EQ(job.component, -1);
  EXPECT_TRUE(job.goals.empty());
  const ProofGoal goal;
  EXPECT_EQ(goal.result, -1);  // a lemma until it answers a result
  EXPECT_TRUE(goal.also.empty());
}

TEST(ProofJob, SecondsSinceCountsFromTheStart) {
  const auto start = std::chrono::steady_clock::now();
  const double a = SecondsSince(start);
  const double b = SecondsSince(start);
  EXPECT_GE(a, 0.0);
  EXPECT_GE(b, a);
  EXPECT_LT(SecondsSince(start - std::chrono::seconds(5)), 5.0 + 60.0);
  EXPECT_GE(SecondsSince(start - std::chrono::seconds(5)), 5.0);
}

}  // namespace
}  // namespace hybrid
