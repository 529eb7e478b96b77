// Tests of a round of k-induction (solvers/verification/induction_round.h), with Z3 directly: an
// invariant the mode's invariant implies survives, one that a step can break is dropped, one
// that holds only together with another survives with it, and without budget every candidate is
// dropped (cut).

#include "solvers/verification/induction_round.h"

#include <gtest/gtest.h>
#include <z3++.h>

#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

// x' = 1 within x <= 5; y = 2 x kept by the flows (y' = 2).
constexpr std::string_view kModel = R"(
automaton clock {
  var x, y;
  mode run { x' = 1; y' = 2; inv x <= 5; }
  init run { x = 0; y = 0; }
  property within_5: always x <= 5;
  property below_3: always x <= 3;
  property y_within_10: always y <= 10;
  property y_twice_x: always y == 2 * x;
}
)";

struct Fixture {
  System system = ParseModel(kModel, "clock.ha");
  std::vector<ProofGoal> goals;
  std::vector<ProofCandidate> candidates;
  z3::context ctx;
  std::optional<SmtEncoding> enc;
  SolverBudget budget{10.0};
  std::optional<QueryMeter> meter;
  Fixture() {
    for (const Property& p : system.properties()) goals.push_back({p, 0, p, {}});
    for (const ProofGoal& g : goals) candidates.push_back(ProofCandidate::Of(g));
    enc.emplace(ctx, system.components()[0].automaton);
    meter.emplace(ctx, budget);
  }
  std::vector<ProofCandidate*> All() {
    std::vector<ProofCandidate*> out;
    for (ProofCandidate& c : candidates) out.push_back(&c);
    return out;
  }
  std::vector<std::string> Names(const std::vector<ProofCandidate*>& cs) const {
    std::vector<std::string> out;
    for (const ProofCandidate* c : cs) out.push_back(c->goal->property.name);
    return out;
  }
};

// within_5 follows from the mode's invariant; y <= 10 holds after a step only together with
// y == 2 x and x <= 5; below_3 fails a step (x = 3 flows on).
TEST(InductionRound, InductiveCandidatesSurviveTogether) {
  Fixture f;
  InductionRound round(*f.enc, *f.meter, 25'000'000, 1, f.All(), f.budget.total());
  round.Run();
  EXPECT_EQ(f.Names(round.Inductive()),
            (std::vector<std::string>{"within_5", "y_within_10", "y_twice_x"}));
  EXPECT_FALSE(round.cut());
  EXPECT_GT(f.budget.used(), 0u);
  // The round decides nothing itself.
  for (const ProofCandidate& c : f.candidates) EXPECT_FALSE(c.decided || c.proved);
}

// Without y == 2 x, y <= 10 is not inductive on its own.
TEST(InductionRound, ACandidateThatNeedsADroppedOneIsDropped) {
  Fixture f;
  InductionRound round(*f.enc, *f.meter, 25'000'000, 1,
                       {&f.candidates[0], &f.candidates[1], &f.candidates[2]}, f.budget.total());
  round.Run();
  EXPECT_EQ(f.Names(round.Inductive()), (std::vector<std::string>{"within_5"}));
}

TEST(InductionRound, WithoutBudgetEveryCandidateIsDropped) {
  Fixture f;
  InductionRound round(*f.enc, *f.meter, 25'000'000, 1, f.All(), 0);
  round.Run();
  EXPECT_TRUE(round.Inductive().empty());
  EXPECT_TRUE(round.cut());
  EXPECT_EQ(f.budget.used(), 0u);
}

}  // namespace
}  // namespace hybrid
