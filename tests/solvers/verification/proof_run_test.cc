// Tests of one proof run (solvers/verification/proof_run.h): on a job the plan made, each goal
// gets its verdict (proved, violated and reachable with a replayed trace, unreachable) in every
// result that asks it, lemmas get none, and with no share of the budget every goal is `unknown`
// with the reason saying so.

#include "solvers/verification/proof_run.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "solvers/verification/proof_plan.h"

namespace hybrid {
namespace {

// x' = u with u in [0, 1] from x = 0; an urgent transition stops x at 5.
constexpr std::string_view kModel = R"(
automaton limited {
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  mode stop { }
  transition limit: run -> stop { guard x >= 5; }
  init run { x = 0; }
  property below_5: always x <= 5;
  property below_3: always x <= 3;
  property gets_to_3: reach x >= 3;
  property negative: reach x < -1;
  property again: always x <= 3;
}
)";

PropertyProver::Options Small() {
  PropertyProver::Options o;
  o.max_depth = 4;
  o.max_induction = 2;
  return o;
}

std::vector<CheckResult> RunTheJob(const System& system, const PropertyProver::Options& options,
                                   SolverBudget& budget, std::uint64_t share) {
  const std::vector<Property> properties(system.properties().begin(), system.properties().end());
  std::vector<CheckResult> results(properties.size());
  const ProofPlan plan(system, properties, options.max_product_modes, results);
  EXPECT_EQ(plan.steps().size(), 1u);
  ProofRun(system, options, budget, std::chrono::steady_clock::now(), results,
           *plan.steps().at(0).job, share)
      .Run();
  return results;
}

TEST(ProofRun, EveryGoalIsDecided) {
  const System system = ParseModel(kModel, "limited.ha");
  const PropertyProver::Options options = Small();
  SolverBudget budget(5.0);
  const std::vector<CheckResult> results = RunTheJob(system, options, budget, budget.total());
  EXPECT_EQ(results[0].verdict, Verdict::kProved) << results[0].reason;
  EXPECT_EQ(results[0].reason.rfind("proved by 1-induction, together with ", 0), 0u)
      << results[0].reason;
  EXPECT_EQ(results[1].verdict, Verdict::kViolated) << results[1].reason;
  ASSERT_TRUE(results[1].trace.has_value());
  EXPECT_NE(results[1].reason.find("replayed by the simulator"), std::string::npos);
  EXPECT_EQ(results[2].verdict, Verdict::kReachable) << results[2].reason;
  ASSERT_TRUE(results[2].trace.has_value());
  EXPECT_EQ(results[3].verdict, Verdict::kUnreachable) << results[3].reason;
  // The question asked twice has one answer, in both results.
  EXPECT_EQ(results[4].verdict, results[1].verdict);
  EXPECT_EQ(results[4].reason, results[1].reason);
  for (const CheckResult& r : results) EXPECT_GE(r.seconds, 0.0);
  EXPECT_GT(budget.used(), 0u);
}

TEST(ProofRun, WithoutAShareEveryGoalIsUnknown) {
  const System system = ParseModel(kModel, "limited.ha");
  SolverBudget budget(5.0);
  const std::vector<CheckResult> results = RunTheJob(system, Small(), budget, 0);
  EXPECT_EQ(budget.used(), 0u);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kUnknown) << r.property;
    EXPECT_NE(r.reason.find("the solver budget (5 budget seconds) ran out"), std::string::npos)
        << r.reason;
  }
}

}  // namespace
}  // namespace hybrid
