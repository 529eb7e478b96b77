// Tests of the prover's candidates (solvers/verification/proof_candidate.h): the states that
// break each kind of property, and when a candidate is still worth a path.

#include "solvers/verification/proof_candidate.h"

#include <gtest/gtest.h>

#include <string_view>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr std::string_view kModel = R"(
automaton clock {
  var x;
  mode run { x' = 1; }
  init run { x = 0; }
  property bounded: always x <= 5;
  property never_big: never x > 7;
  property gets_to_3: reach x >= 3;
}
)";

TEST(ProofCandidate, BadStatesFollowTheKind) {
  const System system = ParseModel(kModel, "clock.ha");
  const auto& properties = system.properties();
  ProofGoal always{properties[0], 0, properties[0], {}};
  ProofGoal never{properties[1], 1, properties[1], {}};
  ProofGoal reach{properties[2], 2, properties[2], {}};
  const ProofCandidate a = ProofCandidate::Of(always);
  EXPECT_EQ(a.goal, &always);
  EXPECT_TRUE(a.invariant);
  EXPECT_EQ(a.bad, Predicate::Not(properties[0].predicate));
  const ProofCandidate n = ProofCandidate::Of(never);
  EXPECT_TRUE(n.invariant);
  EXPECT_EQ(n.bad, properties[1].predicate);
  const ProofCandidate r = ProofCandidate::Of(reach);
  EXPECT_FALSE(r.invariant);
  EXPECT_EQ(r.bad, properties[2].predicate);
  EXPECT_FALSE(a.decided || a.refuted || a.proved);
  EXPECT_EQ(a.replays, 0);
}

TEST(ProofCandidate, PendingUntilDecidedOrReplayedEnough) {
  const System system = ParseModel(kModel, "clock.ha");
  ProofGoal goal{system.properties()[0], 0, system.properties()[0], {}};
  ProofCandidate c = ProofCandidate::Of(goal);
  EXPECT_TRUE(c.Pending());
  c.replays = ProofCandidate::kMaxReplays - 1;
  EXPECT_TRUE(c.Pending());
  c.replays = ProofCandidate::kMaxReplays;
  EXPECT_FALSE(c.Pending());
  c.replays = 0;
  c.decided = true;
  EXPECT_FALSE(c.Pending());
}

}  // namespace
}  // namespace hybrid
