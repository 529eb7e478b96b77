// Tests of VariableLiveness (solvers/reachability/variable_liveness.h): the dead variables of
// small automata, worked out by hand from the definition (a variable is dead at a mode when every
// path from it writes the variable before anything reads it), and the effect on
// PolyhedralReachability: a clock nothing reads no longer keeps the exploration from a fixpoint,
// and a clock a property reads is never forgotten.

#include "solvers/reachability/variable_liveness.h"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "tests/test_utilities/properties.h"

namespace hybrid {
namespace {

using testing::Named;

System Parse(std::string_view text) { return ParseModel(text, "test.ha"); }

// The names of the variables dead at mode `mode` of component `component`.
std::vector<std::string> DeadNames(const System& system, const VariableLiveness& liveness,
                                   int component, std::string_view mode) {
  const Automaton& a = system.components()[static_cast<size_t>(component)].automaton;
  std::vector<std::string> names;
  for (int m = 0; m < a.num_modes(); ++m) {
    if (a.mode(ModeId(m)).name != mode) continue;
    for (const int s : liveness.DeadAt(component, m)) names.push_back(system.symbols()[s].name);
  }
  return names;
}

// One process of Fischer's protocol, alone (so k is private too). By hand, from the definition:
// x is live in req (its invariant reads it) and wait (the guards read it), dead in idle (the only
// way out, request, writes it first) and in cs (release leads to idle, where it is dead, without
// reading or writing it). k is live in idle (request reads it) and wait (enter and retry read
// it), dead in req (write writes it, nothing reads it there) and in cs (release writes it).
constexpr std::string_view kProcess = R"(
automaton p {
  var x;
  var k;
  mode idle { x' = 1; }
  mode req { x' = 1; inv x <= 1; }
  mode wait { x' = 1; }
  mode cs { x' = 1; }
  transition request: idle -> req { guard k == 0; reset x := 0; lazy; }
  transition write: req -> wait { reset x := 0, k := 1; lazy; }
  transition enter: wait -> cs { guard x >= 2 and k == 1; lazy; }
  transition retry: wait -> idle { guard x >= 2 and k >= 2; lazy; }
  transition release: cs -> idle { reset k := 0; lazy; }
  init idle { x = 0; k = 0; }
}
)";

TEST(VariableLiveness, FischersClockIsDeadInIdleAndInTheCriticalSection) {
  const System system = Parse(kProcess);
  const VariableLiveness liveness(system, {});
  using Names = std::vector<std::string>;
  EXPECT_EQ(DeadNames(system, liveness, 0, "idle"), Names{"x"});
  EXPECT_EQ(DeadNames(system, liveness, 0, "req"), Names{"k"});
  EXPECT_EQ(DeadNames(system, liveness, 0, "wait"), Names{});
  EXPECT_EQ(DeadNames(system, liveness, 0, "cs"), (Names{"x", "k"}));
}

TEST(VariableLiveness, ObservedVariablesAreLiveEverywhere) {
  const System system = Parse(kProcess);
  const int x = *system.symbols().Find("x");
  const VariableLiveness liveness(system, {x});
  for (const std::string_view mode : {"idle", "req", "wait", "cs"}) {
    for (const std::string& name : DeadNames(system, liveness, 0, mode)) EXPECT_NE(name, "x");
  }
}

// A variable two components mention is never dead; one reset reading itself is read there; one
// passed on unwritten to a mode that reads it is live before.
TEST(VariableLiveness, SharedSelfReadingAndPassedOnVariablesAreLive) {
  const System system = Parse(R"(
automaton a {
  var x;
  var y;
  var s;
  mode m0 { x' = 1; y' = 1; }
  mode m1 { x' = 1; y' = 1; inv y <= 3; }
  mode m2 { }
  transition t01: m0 -> m1 { reset x := x + 1; lazy; }
  transition t12: m1 -> m2 { reset x := 0, y := 0, s := 1; lazy; }
  transition t20: m2 -> m0 { reset y := 0; lazy; }
  init m0 { x = 0; y = 0; s = 0; }
}
automaton b {
  var s;
  mode n { }
  transition look: n -> n { guard s >= 1; lazy; }
  init n { s = 0; }
}
system both {
  share s;
  instance A = a;
  instance B = b;
}
)");
  const VariableLiveness liveness(system, {});
  // x: read by t01's reset at m0 (live); written by t12 before any read from m1 (dead at m1);
  // m2 -> m0 leaves it unwritten and m0 reads it (live at m2).
  // y: read by m1's invariant (live at m1); t01 passes it on unwritten (live at m0); t20 writes
  // it before m0 and nothing in m2 reads it (dead at m2).
  // s: shared with b, never dead.
  EXPECT_TRUE(DeadNames(system, liveness, 0, "m0").empty());
  EXPECT_EQ(DeadNames(system, liveness, 0, "m1"), std::vector<std::string>{"A.x"});
  EXPECT_EQ(DeadNames(system, liveness, 0, "m2"), std::vector<std::string>{"A.y"});
  EXPECT_TRUE(DeadNames(system, liveness, 1, "n").empty());
}

// x grows by 1 per cycle relative to y (y is reset, x never is): without forgetting x the states
// (x - y = 0, 1, 2, ...) never repeat, so only forgetting reaches a fixpoint, and only while no
// property reads x.
constexpr std::string_view kDrift = R"(
automaton drift {
  var x;
  var y;
  mode run { x' = 1; y' = 1; inv y <= 1; }
  transition tick: run -> run { guard y >= 1; reset y := 0; }
  init run { x = 0; y = 0; }
  property y_bounded: always y <= 1;
  property x_nonnegative: always x >= 0;
  property y_above: always y <= 0.5;
}
)";

TEST(VariableLiveness, ForgettingAnUnreadClockGivesReachabilityAFixpoint) {
  const System system = Parse(kDrift);
  PolyhedralReachability::Options options;
  options.max_states = 200;
  options.hull_units = 0;  // the exact exploration alone
  const PolyhedralReachability engine(options);
  const auto proved = engine.Check(system, {Named(system, "y_bounded")});
  EXPECT_EQ(proved[0].verdict, Verdict::kProved) << proved[0].reason;
  const auto violated = engine.Check(system, {Named(system, "y_above")});
  EXPECT_EQ(violated[0].verdict, Verdict::kViolated) << violated[0].reason;
  // x_nonnegative holds, but it reads x: x is kept and the exploration stops at its bound.
  const auto kept = engine.Check(system, {Named(system, "x_nonnegative")});
  EXPECT_EQ(kept[0].verdict, Verdict::kUnknown) << kept[0].reason;
  EXPECT_NE(kept[0].reason.find("200 symbolic states"), std::string::npos) << kept[0].reason;
  // The hulls (x's states merged, x >= 0 kept) prove it.
  options.hull_units = 1'000'000;
  const auto by_hull =
      PolyhedralReachability(options).Check(system, {Named(system, "x_nonnegative")});
  EXPECT_EQ(by_hull[0].verdict, Verdict::kProved) << by_hull[0].reason;
  EXPECT_NE(by_hull[0].reason.find("convex hulls"), std::string::npos) << by_hull[0].reason;
}

}  // namespace
}  // namespace hybrid
