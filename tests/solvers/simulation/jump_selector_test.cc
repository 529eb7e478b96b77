// Tests of the discrete step at one instant (solvers/simulation/jump_selector.h): priority among
// enabled transitions, guards in their closure where they crossed, lazy transitions at an
// invariant boundary, synchronisation partners, what the instant reached, and the cause of a jump.

#include "solvers/simulation/jump_selector.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr const char* kModel = R"(
automaton worker {
  var x;
  mode idle { x' = 1; inv x <= 2; }
  mode done { }
  transition strict: idle -> done { guard x > 1; }
  transition plain: idle -> done { guard x >= 1; }
  transition rest: idle -> done { guard x >= 0; lazy; }
  transition sync: idle -> done { guard x >= 0.5; label go; }
  init idle { x = 0; }
}
automaton partner {
  var y;
  mode wait { }
  mode gone { }
  transition answer: wait -> gone { guard y > 1; label go; }
  init wait { y = 0; }
}
system s { share go; instance W = worker; instance P = partner; }
)";

// The selector on kModel with the state (x, y) loaded in the initial modes.
struct Fixture {
  Fixture()
      : system(ParseModel(kModel, "s.ha")),
        model(system),
        run(model, model.ParameterEnvironment({}), {}, options),
        selector(model.components(), run) {
    run.SetModes({0, 0});
  }
  void At(double x, double y) {
    const double state[] = {x, y};
    run.Load(0.0, state);
  }
  // The index of root function `text` (a guard or invariant comparison) of component c.
  int Root(int c, const std::string& text) const {
    for (size_t i = 0; i < run.roots().size(); ++i) {
      if (run.roots()[i].component == c && run.ComparisonOf(run.roots()[i]).text == text) {
        return static_cast<int>(i);
      }
    }
    throw std::invalid_argument("no root function " + text);
  }
  SimulationOptions options;
  System system;
  CompiledModel model;
  RunState run;
  JumpSelector selector;
};

TEST(JumpSelectorTest, UrgentGuardsHoldStrictlyUnlessTheyCrossed) {
  Fixture f;
  f.At(1.0, 0.0);  // W.x > 1 on its boundary; W.x >= 1 holds; the partner blocks `sync`
  EXPECT_EQ(f.selector.Candidates(), (std::vector<Jump>{{{0, 1}}}));
  f.selector.Note({f.Root(0, "W.x > 1")});
  EXPECT_TRUE(f.selector.GuardReached(0, 0));
  EXPECT_EQ(f.selector.Candidates(), (std::vector<Jump>{{{0, 0}}, {{0, 1}}}));
  f.selector.ForgetAll();
  EXPECT_FALSE(f.selector.GuardReached(0, 0));
  EXPECT_EQ(f.selector.Candidates().size(), 1u);
}

TEST(JumpSelectorTest, LazyTransitionsOnlyAtTheInvariantBoundary) {
  Fixture f;
  f.At(0.2, 0.0);
  EXPECT_TRUE(f.selector.Candidates().empty());
  EXPECT_FALSE(f.selector.FirstReachedInvariant());
  f.selector.Note({f.Root(0, "W.x <= 2")});
  EXPECT_EQ(f.selector.FirstReachedInvariant(), "W.x <= 2");
  EXPECT_EQ(f.selector.Candidates(), (std::vector<Jump>{{{0, 2}}}));
  EXPECT_EQ(f.selector.CauseInIteration(f.selector.Candidates()), EventRecord::Cause::kInvariant);
  f.selector.Forget({{0, 2}});
  EXPECT_FALSE(f.selector.FirstReachedInvariant());
  f.selector.ReachInvariant(0, "W.x <= 2");
  EXPECT_EQ(f.selector.FirstReachedInvariant(), "W.x <= 2");
}

TEST(JumpSelectorTest, ALabelledTransitionNeedsItsPartners) {
  Fixture f;
  const std::vector<Jump> both = {{{0, 3}, {1, 0}}, {{1, 0}, {0, 3}}};
  f.At(0.7, 2.0);  // W.sync enabled, and P.answer
  EXPECT_EQ(f.selector.Candidates(), both);
  f.At(0.7, 0.5);  // the partner's guard fails: blocked
  EXPECT_TRUE(f.selector.Candidates().empty());
  // A partner's guard is read strictly, in its closure only where it crossed at this instant.
  f.At(0.7, 1.0);
  EXPECT_TRUE(f.selector.Candidates().empty());
  f.selector.Note({f.Root(1, "P.y > 1")});
  EXPECT_EQ(f.selector.Candidates(), both);
}

TEST(JumpSelectorTest, TheCauseOfAJumpInAnIteration) {
  Fixture f;
  f.At(1.0, 0.0);
  EXPECT_EQ(f.selector.CauseInIteration({}), EventRecord::Cause::kEnabled);
  EXPECT_EQ(f.selector.CauseInIteration(f.selector.Candidates()), EventRecord::Cause::kEnabled);
  f.selector.Note({f.Root(0, "W.x >= 1")});
  EXPECT_EQ(f.selector.CauseInIteration(f.selector.Candidates()), EventRecord::Cause::kCrossing);
}

TEST(JumpSelectorTest, AnUnknownRootFunctionIsABug) {
  Fixture f;
  EXPECT_THROW(f.selector.Note({static_cast<int>(f.run.roots().size())}), InternalError);
  EXPECT_THROW(f.selector.ReachInvariant(2, "W.x <= 2"), InternalError);
}

}  // namespace
}  // namespace hybrid
