// Tests of shared proofs (solvers/verification/shared_proof.h): names and components are mapped
// from one instance (or product of instances) to another; products of different automata or
// bound differently share nothing; results are copied with the source named in the reason, to
// every result asking the question, and a trace that does not replay for the target leaves
// `unknown`.

#include "solvers/verification/shared_proof.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr std::string_view kModel = R"(
automaton tank {
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  mode stop { }
  transition limit: run -> stop { guard x >= 5; }
  init run { x = 0; }
}
automaton other {
  var x;
  mode run { x' = 1; }
  init run { x = 0; }
}
system pair {
  instance A = tank;
  instance B = tank;
  instance C = other;
  property a_below_5: always A.x <= 5;
  property b_below_5: always B.x <= 5;
  property b_again: always B.x <= 5;
}
)";

TEST(SharedProof, AnInstanceIsRenamedForAnother) {
  const System system = ParseModel(kModel, "pair.ha");
  const SharedProof how = SharedProof::ForInstance(system, 0, 1);
  EXPECT_EQ(how.Rename("A.x"), "B.x");
  EXPECT_EQ(how.Rename("A.u"), "B.u");
  EXPECT_EQ(how.Rename("C.x"), "C.x");
  EXPECT_EQ(how.source(), "instance A");
  EXPECT_EQ(how.target(), "instance B");
}

TEST(SharedProof, ProductsCorrespondOnlyForInstancesOfTheSameAutomata) {
  const System system = ParseModel(kModel, "pair.ha");
  EXPECT_FALSE(SharedProof::ForProducts(system, {0}, {2}).has_value()) << "other automaton";
  EXPECT_FALSE(SharedProof::ForProducts(system, {0, 2}, {1}).has_value()) << "other sizes";
  EXPECT_FALSE(SharedProof::ForProducts(system, {0}, {0}).has_value()) << "the same product";
  const auto how = SharedProof::ForProducts(system, {0}, {1});
  ASSERT_TRUE(how.has_value());
  EXPECT_EQ(how->Rename("A.x"), "B.x");
  EXPECT_EQ(how->source(), "instances A");
  // A component in both products stands for itself.
  const auto with_c = SharedProof::ForProducts(system, {0, 2}, {1, 2});
  ASSERT_TRUE(with_c.has_value());
  EXPECT_EQ(with_c->Rename("A.x"), "B.x");
  EXPECT_EQ(with_c->Rename("C.x"), "C.x");
  EXPECT_EQ(with_c->target(), "instances B, C");
}

// A's job answered result 0; B's job asks the same question for results 1 and 2.
struct Jobs {
  ProofJob a, b;
};

Jobs AskedOfAAndB(const System& system) {
  Jobs jobs;
  jobs.a.component = 0;
  jobs.a.goals.push_back({system.properties()[0], 0, system.properties()[0], {}});
  jobs.b.component = 1;
  jobs.b.goals.push_back({system.properties()[1], 1, system.properties()[1], {2}});
  return jobs;
}

TEST(SharedProof, AVerdictIsCopiedToEveryResultAskingTheQuestion) {
  const System system = ParseModel(kModel, "pair.ha");
  const Jobs jobs = AskedOfAAndB(system);
  std::vector<CheckResult> results(3);
  for (int i = 0; i < 3; ++i) results[i].property = system.properties()[i].name;
  results[0].verdict = Verdict::kProved;
  results[0].reason = "proved by 1-induction";
  SharedProof::ForInstance(system, 0, 1)
      .CopyResults(system, jobs.a, jobs.b, std::chrono::steady_clock::now(), results);
  for (int i : {1, 2}) {
    EXPECT_EQ(results[i].property, system.properties()[i].name);
    EXPECT_EQ(results[i].verdict, Verdict::kProved);
    EXPECT_EQ(results[i].reason,
              "proved by 1-induction (the proof for instance A, an instance of the same "
              "automaton)");
  }
  EXPECT_EQ(results[0].reason, "proved by 1-induction");
}

TEST(SharedProof, ATraceThatDoesNotReplayLeavesUnknown) {
  const System system = ParseModel(kModel, "pair.ha");
  const Jobs jobs = AskedOfAAndB(system);
  std::vector<CheckResult> results(3);
  results[0].verdict = Verdict::kViolated;
  results[0].reason = "counterexample";
  results[0].trace.emplace();  // from the initial state, which breaks nothing
  results[0].trace->inputs.until = 1.0;
  SharedProof::ForInstance(system, 0, 1)
      .CopyResults(system, jobs.a, jobs.b, std::chrono::steady_clock::now(), results);
  for (int i : {1, 2}) {
    EXPECT_EQ(results[i].verdict, Verdict::kUnknown);
    EXPECT_FALSE(results[i].trace.has_value());
    EXPECT_EQ(results[i].reason,
              "the trace found for instance A does not replay for instance B (the proof for "
              "instance A, an instance of the same automaton)");
  }
}

}  // namespace
}  // namespace hybrid
