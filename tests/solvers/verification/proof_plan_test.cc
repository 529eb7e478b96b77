// Tests of the prover's plan (solvers/verification/proof_plan.h): a property of one component
// goes to that component's job with its declared invariants as lemmas; a question asked twice
// is answered once; instances of one automaton asked the same questions share one run; a
// property reading components that share a variable goes to their product, and products of
// instances bound alike share one run; a product too large is `unknown` at once; a property
// reading an input is refused.

#include "solvers/verification/proof_plan.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr std::string_view kTankModel = R"(
automaton tank {
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  mode stop { }
  transition limit: run -> stop { guard x >= 5; }
  init run { x = 0; }
  property declared_bound: always x <= 5;
  property declared_reach: reach in stop;
}
system pair {
  instance A = tank;
  instance B = tank;
  property a_below_5: always A.x <= 5;
  property a_below_3: always A.x <= 3;
  property b_below_5: always B.x <= 5;
  property b_below_3: always B.x <= 3;
  property a_again: always A.x <= 3;
}
)";

// Two pairs of processes, each pair joined by its lock (B's and D's bound to A's and C's).
constexpr std::string_view kTwoMutexModel = R"(
automaton proc {
  param id = 1;
  var x in [0, 10];
  var lock in [0, 2];
  mode idle { x' = 1; inv x <= 3; }
  mode cs { x' = 1; inv x <= 2; }
  transition enter: idle -> cs { guard x >= 1 and lock == 0; reset x := 0, lock := id; }
  transition leave: cs -> idle { guard x >= 1; reset x := 0, lock := 0; }
  init idle { x = 0; lock = 0; }
}
system mutexes {
  instance A = proc;
  instance B = proc { lock = A.lock; }
  instance C = proc;
  instance D = proc { lock = C.lock; }
  property ab: never in A.cs and in B.cs;
  property cd: never in C.cs and in D.cs;
}
)";

std::vector<Property> Asked(const System& system) {
  return {system.properties().begin(), system.properties().end()};
}

TEST(ProofPlan, InstancesOfOneAutomatonShareOneRun) {
  const System system = ParseModel(kTankModel, "tank.ha");
  const std::vector<Property> properties = Asked(system);
  std::vector<CheckResult> results(properties.size());
  const ProofPlan plan(system, properties, 2000, results);
  for (std::size_t i = 0; i < results.size(); ++i) {
    EXPECT_EQ(results[i].property, properties[i].name);
    EXPECT_EQ(results[i].method, "prove");
  }
  ASSERT_EQ(plan.steps().size(), 2u);
  EXPECT_EQ(plan.runs(), 1);
  const ProofPlan::Step& run = plan.steps()[0];
  const ProofPlan::Step& copy = plan.steps()[1];
  EXPECT_EQ(run.from, nullptr);
  EXPECT_EQ(run.job->component, 0);
  EXPECT_EQ(run.job->automaton, &system.components()[0].automaton);
  // Asked: below_5, below_3 (asked twice: once, with `also`); then the declared invariant that
  // is not asked already (a lemma; the declared `reach` is not one). below_5 is the declared
  // bound itself, so it is not added again.
  ASSERT_EQ(run.job->goals.size(), 2u);
  EXPECT_EQ(run.job->goals[0].result, 0);
  EXPECT_EQ(run.job->goals[1].result, 1);
  EXPECT_EQ(run.job->goals[1].also, std::vector<int>{4});
  ASSERT_NE(copy.from, nullptr);
  EXPECT_EQ(copy.from, run.job);
  EXPECT_EQ(copy.job->component, 1);
  ASSERT_TRUE(copy.how.has_value());
  EXPECT_EQ(copy.how->source(), "instance A");
  EXPECT_EQ(copy.how->Rename("A.x"), "B.x");
}

TEST(ProofPlan, LemmasAreTheDeclaredInvariantsNotAsked) {
  const System system = ParseModel(kTankModel, "tank.ha");
  const std::vector<Property> properties = {system.properties()[1]};  // a_below_3
  std::vector<CheckResult> results(1);
  const ProofPlan plan(system, properties, 2000, results);
  ASSERT_EQ(plan.steps().size(), 1u);
  const ProofJob& job = *plan.steps()[0].job;
  ASSERT_EQ(job.goals.size(), 2u);
  EXPECT_EQ(job.goals[1].result, -1);
  EXPECT_EQ(job.goals[1].property.name, "declared_bound");
  // The lemma's original reads the System's slot of A.x.
  EXPECT_NE(job.goals[1].original.predicate.ToString().find("A.x"), std::string::npos)
      << job.goals[1].original.predicate.ToString();
}

TEST(ProofPlan, SharedVariablesGoToProductsAndAlikeProductsShareOneRun) {
  const System system = ParseModel(kTwoMutexModel, "mutexes.ha");
  const std::vector<Property> properties = Asked(system);
  std::vector<CheckResult> results(properties.size());
  const ProofPlan plan(system, properties, 2000, results);
  ASSERT_EQ(plan.steps().size(), 2u);
  EXPECT_EQ(plan.runs(), 1);
  const ProofJob& run = *plan.steps()[0].job;
  EXPECT_EQ(plan.steps()[0].from, nullptr);
  EXPECT_EQ(run.component, -1);
  EXPECT_EQ(run.product_components, (std::vector<int>{0, 1}));
  ASSERT_NE(run.automaton, nullptr);
  EXPECT_EQ(run.to_system.size(), run.automaton->symbols().size());
  const ProofPlan::Step& copy = plan.steps()[1];
  EXPECT_EQ(copy.from, &run);
  EXPECT_EQ(copy.job->product_components, (std::vector<int>{2, 3}));
  ASSERT_TRUE(copy.how.has_value());
  EXPECT_EQ(copy.how->source(), "instances A, B");
  EXPECT_EQ(copy.how->target(), "instances C, D");
}

TEST(ProofPlan, AProductTooLargeIsUnknownAtOnce) {
  const System system = ParseModel(kTwoMutexModel, "mutexes.ha");
  const std::vector<Property> properties = Asked(system);
  std::vector<CheckResult> results(properties.size());
  const ProofPlan plan(system, properties, 1, results);
  EXPECT_TRUE(plan.steps().empty());
  EXPECT_EQ(plan.runs(), 0);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kUnknown);
    EXPECT_NE(r.reason.find("their product is too large"), std::string::npos) << r.reason;
  }
}

TEST(ProofPlan, APropertyReadingAnInputIsRefused) {
  const System system = ParseModel(kTankModel, "tank.ha");
  const int u = system.symbols().Find("A.u").value();
  const std::vector<Property> properties = {
      {"reads_u", Property::Kind::kAlways,
       Predicate::Compare(
           {Expression::Symbol("A.u", u), Relation::kLessEqual, Expression::Constant(1.0)}),
       std::nullopt}};
  std::vector<CheckResult> results(1);
  EXPECT_THROW(ProofPlan(system, properties, 2000, results), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
