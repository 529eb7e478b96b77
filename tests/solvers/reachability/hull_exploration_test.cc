// Tests of reachability on convex hulls (solvers/reachability/hull_exploration.h), through
// PolyhedralReachability::Check, on models whose verdicts are known by hand: what the hulls
// prove (Fischer's protocol with its lock kept apart by value; a bound that only the widening
// reaches), and what they must leave to the exact exploration (a relation their hull loses, a
// violation).

#include "solvers/reachability/hull_exploration.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "tests/test_utilities/properties.h"

namespace hybrid {
namespace {

using testing::Named;

constexpr std::string_view kByHull = "fixpoint of polyhedral reachability on convex hulls";
constexpr std::string_view kExact = "fixpoint of exact polyhedral reachability:";

// Property `property` of model `text` (the hulls' first turn of `hull_units`; 0: no hull).
CheckResult CheckOne(std::string_view text, const std::string& property,
                     std::uint64_t hull_units = 100'000'000, double budget = 5.0) {
  const System system = ParseModel(text, "test.ha");
  PolyhedralReachability::Options options;
  options.hull_units = hull_units;
  options.budget = budget;
  return PolyhedralReachability(options).Check(system, {Named(system, property)}).at(0);
}

bool Says(const CheckResult& r, std::string_view what) {
  return r.reason.find(what) != std::string::npos;
}

// Fischer's protocol, two processes with drifting clocks (x' in [1, 2]): a process stays in req
// at most delta / 1 = 1 time unit and waits at least Delta / 2 before its check, so mutual
// exclusion holds iff Delta / 2 > 1 (Delta = 2.1 here; DELTA is replaced below). The lock k
// is a variable (0: free, i: written by process i) that no flow changes: the hulls keep its
// values apart, as a model with one location per lock value would.
constexpr std::string_view kFischer = R"(
automaton lock {
  var k in [0, 2];
  mode m {}
  transition set_1: m -> m { reset k := 1; label set_1; lazy; }
  transition mine_1: m -> m { guard k == 1; label mine_1; lazy; }
  transition other_1: m -> m { guard k == 2; label other_1; lazy; }
  transition set_2: m -> m { reset k := 2; label set_2; lazy; }
  transition mine_2: m -> m { guard k == 2; label mine_2; lazy; }
  transition other_2: m -> m { guard k == 1; label other_2; lazy; }
  init m { k = 0; }
}
automaton process {
  param Delta = DELTA;
  var x;
  var k;
  mode idle { x' in [1, 2]; }
  mode req { x' in [1, 2]; inv x <= 1; }
  mode wait { x' in [1, 2]; }
  mode cs { x' in [1, 2]; }
  transition request: idle -> req { guard k == 0; reset x := 0; lazy; }
  transition write: req -> wait { reset x := 0; label set; lazy; }
  transition enter: wait -> cs { guard x >= Delta; label mine; lazy; }
  transition retry: wait -> idle { guard x >= Delta; label other; lazy; }
  transition release: cs -> idle { reset k := 0; lazy; }
  init idle { x = 0; k = 0; }
}
system fischer {
  share k;
  instance L = lock;
  instance P1 = process { set = L.set_1; mine = L.mine_1; other = L.other_1; }
  instance P2 = process { set = L.set_2; mine = L.mine_2; other = L.other_2; }
  property mutex: never in P1.cs and in P2.cs;
  property enters: reach in P1.cs;
}
)";

std::string FischerWith(std::string_view delta) {
  std::string text(kFischer);
  text.replace(text.find("DELTA"), 5, delta);
  return text;
}

TEST(HullExploration, ProvesFischersMutualExclusionWithTheLockKeptApartByValue) {
  const CheckResult r = CheckOne(FischerWith("2.1"), "mutex");
  EXPECT_EQ(r.verdict, Verdict::kProved) << r.reason;
  EXPECT_TRUE(Says(r, kByHull)) << r.reason;
  // Without the hull the exact exploration proves it too.
  const CheckResult exact = CheckOne(FischerWith("2.1"), "mutex", 0);
  EXPECT_EQ(exact.verdict, Verdict::kProved) << exact.reason;
  EXPECT_TRUE(Says(exact, kExact)) << exact.reason;
}

TEST(HullExploration, NeverProvesAViolatedPropertyAndLeavesItsRunToTheExactExploration) {
  // Delta = 1.9 < 2: both processes can be in cs; the hulls meet it, the exact exploration finds
  // the run and the simulator replays it.
  const CheckResult r = CheckOne(FischerWith("1.9"), "mutex");
  EXPECT_EQ(r.verdict, Verdict::kViolated) << r.reason;
  ASSERT_TRUE(r.trace.has_value());
  const CheckResult reached = CheckOne(FischerWith("2.1"), "enters");
  EXPECT_EQ(reached.verdict, Verdict::kReachable) << reached.reason;
}

// Two entries into `a`, (x, y) = (0, 1) and (1, 0), both flowing along (1, 1): x - y stays -1 or
// 1, so x == y never holds in `a`; the hull of the two entries contains x - y = 0.
constexpr std::string_view kTwoDiagonals = R"(
automaton two {
  var x, y;
  mode s { }
  mode a { x' = 1; y' = 1; inv x <= 3; }
  transition s -> a { reset x := 0, y := 1; }
  transition s -> a { reset x := 1, y := 0; }
  init s { x = 5; y = 5; }
}
system two_diagonals {
  instance T = two;
  property apart: never in T.a and T.x == T.y;
}
)";

TEST(HullExploration, LeavesWhatItsHullLosesToTheExactExploration) {
  const CheckResult r = CheckOne(kTwoDiagonals, "apart");
  EXPECT_EQ(r.verdict, Verdict::kProved) << r.reason;
  EXPECT_TRUE(Says(r, kExact)) << r.reason;
}

// y is halved and raised by 1 at every lap (y := y / 2 + 1), from [0, 1/2]: after n laps y lies
// in [2 - 2^(1-n), 2 - 3 * 2^(-n-1)], so y >= 0 always, y < 2 always, and y > 1.9 after 5 laps.
// The exact exploration never ends (each lap a new set); the hulls of y's sets approach [0, 2)
// and end only through the widening, which drops the upper bound.
constexpr std::string_view kHalving = R"(
automaton halving {
  var x, y;
  mode lap { x' = 1; inv x <= 1; }
  transition lap -> lap { guard x == 1; reset x := 0, y := y / 2 + 1; }
  init lap { x = 0; y in [0, 0.5]; }
}
system halving {
  instance H = halving;
  property nonnegative: always H.y >= 0;
  property below_two: always H.y < 2;
  property below_1_9: always H.y <= 1.9;
}
)";

TEST(HullExploration, EndsThroughTheWideningWhereTheExactExplorationCannot) {
  const CheckResult r = CheckOne(kHalving, "nonnegative", 100'000'000, 0.5);
  EXPECT_EQ(r.verdict, Verdict::kProved) << r.reason;
  EXPECT_TRUE(Says(r, kByHull)) << r.reason;
  const CheckResult exact = CheckOne(kHalving, "nonnegative", 0, 0.5);
  EXPECT_EQ(exact.verdict, Verdict::kUnknown) << exact.reason;
  // The widened hull meets y >= 2, which no run reaches: no verdict, never `violated`.
  EXPECT_EQ(CheckOne(kHalving, "below_two", 100'000'000, 0.5).verdict, Verdict::kUnknown);
  const CheckResult violated = CheckOne(kHalving, "below_1_9", 100'000'000, 0.5);
  EXPECT_EQ(violated.verdict, Verdict::kViolated) << violated.reason;
}

// n counts laps up to 10 (n := n + 1 while n <= 9, from [0, 1/2]), so n <= 10 always; y is
// halved and raised by 1 at every lap, as in kHalving, so the exact exploration never ends. The
// hulls' first widening (after 5 growths) drops n's upper bound with y's, and then meets n > 10;
// the later one (after 32) comes when n's hull has reached [0, 10], which the widening keeps.
constexpr std::string_view kCounting = R"(
automaton counting {
  var x, n, y;
  mode lap { x' = 1; inv x <= 1; }
  transition count: lap -> lap { guard x == 1 and n <= 9; reset x := 0, n := n + 1; }
  transition halve: lap -> lap { guard x == 1; reset x := 0, y := y / 2 + 1; }
  init lap { x = 0; n in [0, 0.5]; y in [0, 0.5]; }
}
system counting {
  instance C = counting;
  property at_most_ten: always C.n <= 10;
  property at_most_9_5: always C.n <= 9.5;
}
)";

TEST(HullExploration, WidensLaterWhereTheFirstWideningLosesTheProperty) {
  const CheckResult r = CheckOne(kCounting, "at_most_ten");
  EXPECT_EQ(r.verdict, Verdict::kProved) << r.reason;
  EXPECT_TRUE(Says(r, kByHull)) << r.reason;
  EXPECT_EQ(CheckOne(kCounting, "at_most_ten", 0, 0.5).verdict, Verdict::kUnknown);
  // n = 10 after 10 counts from 0: violated, with the exact exploration's run.
  const CheckResult violated = CheckOne(kCounting, "at_most_9_5");
  EXPECT_EQ(violated.verdict, Verdict::kViolated) << violated.reason;
}

}  // namespace
}  // namespace hybrid
