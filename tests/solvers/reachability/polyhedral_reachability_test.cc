// Tests of exact polyhedral reachability (include/hybrid/reachability/polyhedral_reachability.h) on
// small models whose verdicts are known analytically: proved bounds, violations and witnesses whose
// traces the simulator replays, a rectangular rate, an uncertain parameter, a simultaneous swap
// and a long chain of jumps; and its deterministic budget: models whose reachable set never
// converges stop at the budget, with the same verdict, reason and state count on every run, also
// while other threads load the machine (ConvexPolyhedron: convex_polyhedron_test.cc).

#include "hybrid/reachability/polyhedral_reachability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/properties.h"
#include "tests/test_utilities/trace_states.h"

namespace hybrid {
namespace {

using testing::AtTarget;
using testing::Named;
using testing::Replayed;

System Parse(std::string_view text) { return ParseModel(text, "test.ha"); }

// Checks the named properties of `system` together; results in order.
std::vector<CheckResult> Check(const System& system, const std::vector<std::string>& names) {
  std::vector<Property> properties;
  for (const std::string& name : names) properties.push_back(Named(system, name));
  return PolyhedralReachability().Check(system, properties);
}

// x' = u with u in [0, 1] from x = 0; an urgent transition stops x at 5.
constexpr std::string_view kLimitedModel = R"(
automaton limited {
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  mode stop { }
  transition limit: run -> stop { guard x >= 5; }
  init run { x = 0; }
  property below_5: always x <= 5;
  property never_above_5: never x > 5;
  property below_3: always x <= 3;
  property gets_to_4: reach x >= 4;
  property negative: reach x < -1;
  property slow_start: always x <= 2 within 2;
  property quick_start: always x <= 1.5 within 2;
}
)";

TEST(PolyhedralReachability, ProvesTheBoundAnUrgentJumpKeeps) {
  const System system = Parse(kLimitedModel);
  const auto r = Check(system, {"below_5", "never_above_5", "negative"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
  EXPECT_EQ(r[2].verdict, Verdict::kUnreachable) << r[2].reason;
  for (const CheckResult& result : r) {
    EXPECT_EQ(result.method, "reach");
    EXPECT_FALSE(result.trace.has_value());
  }
}

TEST(PolyhedralReachability, ViolationAndWitnessReplay) {
  const System system = Parse(kLimitedModel);
  const auto r = Check(system, {"below_3", "gets_to_4"});
  ASSERT_EQ(r[0].verdict, Verdict::kViolated) << r[0].reason;
  ASSERT_EQ(r[1].verdict, Verdict::kReachable) << r[1].reason;
  const Trace violation = Replayed(system, Named(system, "below_3"), r[0]);
  EXPECT_GT(AtTarget(system, violation, "x"), 3.0);
  const Trace witness = Replayed(system, Named(system, "gets_to_4"), r[1]);
  EXPECT_GE(AtTarget(system, witness, "x"), 4.0);
  // Step inputs within the bounds, starting at 0.
  ASSERT_EQ(violation.inputs.inputs.size(), 1u);
  const InputSignal& u = violation.inputs.inputs[0];
  EXPECT_EQ(u.shape, InputSignal::Shape::kStep);
  ASSERT_FALSE(u.points.empty());
  EXPECT_EQ(u.points.front().first, 0.0);
  for (const auto& [t, v] : u.points) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
  }
}

TEST(PolyhedralReachability, BoundedPropertiesUseAClock) {
  // x <= t: x stays at most 2 until time 2, but can pass 1.5 before.
  const System system = Parse(kLimitedModel);
  const auto r = Check(system, {"slow_start", "quick_start"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  ASSERT_EQ(r[1].verdict, Verdict::kViolated) << r[1].reason;
  const Trace replayed = Replayed(system, Named(system, "quick_start"), r[1]);
  EXPECT_GT(AtTarget(system, replayed, "x"), 1.5);
  EXPECT_LE(replayed.inputs.until, 2.0);
}

// A tick each time unit counted by y, forever: infinitely many symbolic states.
constexpr std::string_view kCounterModel = R"(
automaton counter {
  var x, y;
  mode a { x' = 1; y' = 0; inv x <= 1; }
  transition tick: a -> a { guard x >= 1; reset x := 0, y := y + 1; }
  init a { x = 0; y = 0; }
  property few_ticks: always y <= 3 within 3.5;
  property ever_few: always y <= 3;
}
)";

TEST(PolyhedralReachability, HorizonBoundsTheExploration) {
  const System system = Parse(kCounterModel);
  PolyhedralReachability::Options options;
  options.max_states = 200;
  const std::vector<Property> properties = {Named(system, "few_ticks"), Named(system, "ever_few")};
  const auto r = PolyhedralReachability(options).Check(system, properties);
  // Within 3.5 there are 4 symbolic states: a fixpoint.
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  ASSERT_EQ(r[1].verdict, Verdict::kViolated) << r[1].reason;
  const Trace replayed = Replayed(system, Named(system, "ever_few"), r[1]);
  EXPECT_GE(AtTarget(system, replayed, "y"), 4.0);
  EXPECT_EQ(replayed.schedule.size(), 4u);
}

// x' in [1, 2] for one time unit (clock t), then stop: x ends in [1, 2].
constexpr std::string_view kRectangularModel = R"(
automaton rectangular {
  var x, t;
  mode a { x' in [1, 2]; t' = 1; inv t <= 1; }
  mode b { }
  transition done: a -> b { guard t >= 1; }
  init a { x = 0; t = 0; }
  property at_most_2: always x <= 2;
  property at_least_1_after: never in b and x < 1;
  property reaches_1_9: reach x >= 1.9;
  property slow_end: reach in b and x <= 1.1;
  property above_2: reach x > 2;
}
)";

TEST(PolyhedralReachability, RectangularRates) {
  const System system = Parse(kRectangularModel);
  const auto r =
      Check(system, {"at_most_2", "at_least_1_after", "reaches_1_9", "slow_end", "above_2"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
  ASSERT_EQ(r[2].verdict, Verdict::kReachable) << r[2].reason;
  ASSERT_EQ(r[3].verdict, Verdict::kReachable) << r[3].reason;
  EXPECT_EQ(r[4].verdict, Verdict::kUnreachable) << r[4].reason;
  const Trace fast = Replayed(system, Named(system, "reaches_1_9"), r[2]);
  EXPECT_GE(AtTarget(system, fast, "x"), 1.9);
  const Trace slow = Replayed(system, Named(system, "slow_end"), r[3]);
  EXPECT_LE(AtTarget(system, slow, "x"), 1.1);
  EXPECT_GE(AtTarget(system, slow, "x"), 1.0);
  ASSERT_EQ(slow.schedule.size(), 1u);
  EXPECT_DOUBLE_EQ(slow.schedule[0].time, 1.0);
}

// The limit at an uncertain c in [0, 10] (nominal 5).
constexpr std::string_view kUncertainModel = R"(
automaton bounded {
  param c = 5 in [0, 10];
  var x;
  mode run { x' = 1; }
  mode stop { }
  transition limit: run -> stop { guard x >= c; }
  init run { x = 0; }
  property below_10: always x <= 10;
  property below_7: always x <= 7;
  property below_c: always x <= c;
}
)";

TEST(PolyhedralReachability, UncertainParameterIsCoveredAndChosen) {
  const System system = Parse(kUncertainModel);
  const auto r = Check(system, {"below_10", "below_7", "below_c"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[2].verdict, Verdict::kProved) << r[2].reason;
  ASSERT_EQ(r[1].verdict, Verdict::kViolated) << r[1].reason;
  // Only c > 7 violates it: the trace sets c there, and its replay ends above 7.
  ASSERT_EQ(r[1].trace->parameters.size(), 1u);
  EXPECT_EQ(r[1].trace->parameters[0].first, "c");
  EXPECT_GT(r[1].trace->parameters[0].second, 7.0);
  EXPECT_LE(r[1].trace->parameters[0].second, 10.0);
  const Trace replayed = Replayed(system, Named(system, "below_7"), r[1]);
  EXPECT_GT(AtTarget(system, replayed, "x"), 7.0);
}

// x rises to 1 and stays (its invariant): x >= 1 is reached exactly at the boundary, where no run
// reaches it with margin. RATE is replaced below: 1, or an uncertain parameter's r, whose range
// widens the rates (the states met are not exact any more).
constexpr std::string_view kTouchModel = R"(
automaton touch {
  param r = 1 in [1, 2];
  var x;
  mode run { x' = RATE; inv x <= 1; }
  init run { x = 0; }
  property reaches_one: reach x >= 1;
  property below_two: always x <= 2;
}
)";

TEST(PolyhedralReachability, SaysWhenItsExactStatesMeetAPropertyWithoutARun) {
  for (const std::string rate : {"1", "r"}) {
    const std::string model(kTouchModel);
    const std::size_t at = model.find("RATE");
    const System system = Parse(model.substr(0, at) + rate + model.substr(at + 4));
    const auto r = Check(system, {"reaches_one", "below_two"});
    EXPECT_EQ(r[0].verdict, Verdict::kUnknown) << r[0].reason;
    EXPECT_EQ(r[0].states_met, rate == "1") << rate << ": " << r[0].reason;
    EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
    EXPECT_FALSE(r[1].states_met);
  }
}

// x rises to 1 with y = 5, then x and y are swapped at once.
constexpr std::string_view kSwapModel = R"(
automaton swap {
  var x, y;
  mode a { x' = 1; y' = 0; inv x <= 1; }
  mode b { x' = 0; y' = 0; }
  transition go: a -> b { guard x >= 1; reset x := y, y := x; lazy; }
  init a { x = 0; y = 5; }
  property y_stays_small: never in b and y > 1;
  property x_is_5: never in b and (x < 5 or x > 5);
  property swapped: reach in b and x >= 4.5 and y <= 1.5;
}
)";

TEST(PolyhedralReachability, SimultaneousResetInAModel) {
  const System system = Parse(kSwapModel);
  const auto r = Check(system, {"y_stays_small", "x_is_5", "swapped"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
  ASSERT_EQ(r[2].verdict, Verdict::kReachable) << r[2].reason;
  const Trace replayed = Replayed(system, Named(system, "swapped"), r[2]);
  EXPECT_DOUBLE_EQ(AtTarget(system, replayed, "x"), 5.0);
  EXPECT_DOUBLE_EQ(AtTarget(system, replayed, "y"), 1.0);
  ASSERT_EQ(replayed.schedule.size(), 1u);
  EXPECT_DOUBLE_EQ(replayed.schedule[0].time, 1.0);
}

// A lazy jump anywhere in x in [1, 10]; the target needs it early.
constexpr std::string_view kLazyModel = R"(
automaton early {
  var x;
  mode a { x' = 1; inv x <= 10; }
  mode b { x' = 0; }
  transition go: a -> b { guard x >= 1; lazy; }
  init a { x = 0; }
  property stops_early: reach in b and x <= 1.5;
}
)";

TEST(PolyhedralReachability, LazyJumpsAreScheduled) {
  // The simulator alone would jump at the invariant's boundary, x = 10; the trace's schedule
  // makes it jump where the run needs, with x in [1, 1.5].
  const System system = Parse(kLazyModel);
  const auto r = Check(system, {"stops_early"});
  ASSERT_EQ(r[0].verdict, Verdict::kReachable) << r[0].reason;
  const Trace replayed = Replayed(system, Named(system, "stops_early"), r[0]);
  ASSERT_EQ(replayed.schedule.size(), 1u);
  EXPECT_EQ(replayed.schedule[0].name, "go");
  EXPECT_EQ(replayed.schedule[0].transitions, (std::vector<std::pair<int, int>>{{0, 0}}));
  EXPECT_GE(replayed.schedule[0].time, 1.0);
  EXPECT_LE(replayed.schedule[0].time, 1.5);
  EXPECT_LE(AtTarget(system, replayed, "x"), 1.5);
}

// A chain of n + 1 modes m_i (x' = 1, x <= i + 1) left at x >= i + 1.
std::string Chain(int n) {
  std::ostringstream out;
  out << "automaton chain {\n  var x in [0, " << n << "];\n";
  for (int i = 0; i <= n; ++i) out << "  mode m" << i << " { x' = 1; inv x <= " << i + 1 << "; }\n";
  for (int i = 0; i < n; ++i) {
    out << "  transition t" << i << ": m" << i << " -> m" << i + 1 << " { guard x >= " << i + 1
        << "; }\n";
  }
  out << "  init m0 { x = 0; }\n  property bounded: always x <= " << n + 1 << ";\n"
      << "  property exceeded: always x <= " << n << ";\n  property far: reach x >= " << n
      << " - 0.5;\n}\n";
  return out.str();
}

TEST(PolyhedralReachability, LongChainIsConcretisedExactly) {
  constexpr int kModes = 300;
  const System system = Parse(Chain(kModes));
  const auto r = Check(system, {"bounded", "exceeded", "far"});
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  ASSERT_EQ(r[1].verdict, Verdict::kViolated) << r[1].reason;
  ASSERT_EQ(r[2].verdict, Verdict::kReachable) << r[2].reason;
  // The witness jumps once per unit of time, t_i at i + 1; the violation runs through all modes.
  const Trace& far = *r[2].trace;
  ASSERT_EQ(far.schedule.size(), static_cast<size_t>(kModes - 1));
  for (int i = 0; i < kModes - 1; ++i) {
    EXPECT_DOUBLE_EQ(far.schedule[static_cast<size_t>(i)].time, i + 1.0);
    EXPECT_EQ(far.schedule[static_cast<size_t>(i)].name, "t" + std::to_string(i));
    EXPECT_EQ(far.schedule[static_cast<size_t>(i)].transitions,
              (std::vector<std::pair<int, int>>{{0, i}}));
  }
  EXPECT_EQ(r[1].trace->schedule.size(), static_cast<size_t>(kModes));
  const Trace replayed = Replayed(system, Named(system, "exceeded"), r[1]);
  EXPECT_GT(AtTarget(system, replayed, "x"), kModes);
}

// ---------------------------------------------------------------------------------------------
// The deterministic budget.

// One mode, two variables, a reachable set that never converges: a clock x reset every time unit
// beside a clock y never reset, so each time unit adds a symbolic state (all at the one location,
// each compared with every one stored before).
constexpr std::string_view kRampModel = R"(
automaton ramp {
  var x, y;
  mode a { x' = 1; y' = 1; inv x <= 1; }
  transition tick: a -> a { guard x >= 1; reset x := 0; }
  init a { x = 0; y = 0; }
  property y_nonnegative: always y >= 0;
}
)";

// One mode, two clocks of incommensurate periods (1 and 1.41421356) reset independently: their
// offset takes ever new values, and the states' bounding boxes overlap, so every new state is
// compared polyhedron to polyhedron with many stored ones.
constexpr std::string_view kDriftModel = R"(
automaton drift {
  var x, y;
  mode a { x' = 1; y' = 1; inv x <= 1 and y <= 1.41421356; }
  transition tick: a -> a { guard x >= 1; reset x := 0; }
  transition tock: a -> a { guard y >= 1.41421356; reset y := 0; }
  init a { x = 0; y = 0; }
  property bounded: always x <= 1 and y <= 1.5;
}
)";

// What one check of `property` gave: verdict, reason and what it spent.
struct Outcome {
  CheckResult result;
  PolyhedralReachability::Usage usage;
};

Outcome CheckWithin(const System& system, const std::string& property,
                    PolyhedralReachability::Options options) {
  Outcome out;
  out.result =
      PolyhedralReachability(options).Check(system, {Named(system, property)}, &out.usage).at(0);
  return out;
}

// The exact exploration alone (no hulls: those prove both non-converging models' properties
// through their widening, HullExploration's tests) within `budget_seconds`.
PolyhedralReachability::Options Budget(double budget_seconds) {
  PolyhedralReachability::Options options;
  options.budget = budget_seconds;
  options.hull_units = 0;
  return options;
}

TEST(PolyhedralReachability, NonConvergingOneModeModelsStopAtTheDeterministicBudget) {
  for (const auto& [model, property] :
       {std::pair{kRampModel, "y_nonnegative"}, std::pair{kDriftModel, "bounded"}}) {
    const System system = Parse(model);
    const Outcome small = CheckWithin(system, property, Budget(0.02));
    EXPECT_EQ(small.result.verdict, Verdict::kUnknown) << small.result.reason;
    EXPECT_NE(small.result.reason.find("stopped by its deterministic budget (2000000 reach units "
                                       "= 0.02 budget seconds) before a fixpoint"),
              std::string::npos)
        << small.result.reason;
    EXPECT_EQ(small.result.reason.find("safety net"), std::string::npos) << small.result.reason;
    EXPECT_EQ(small.usage.stop, PolyhedralReachability::Usage::Stop::kBudget);
    EXPECT_EQ(small.usage.units_total, 2'000'000u);
    EXPECT_GE(small.usage.units_used, small.usage.units_total);
    EXPECT_GT(small.usage.states, 10);
    // The reason gives the state count.
    EXPECT_NE(small.result.reason.find("(" + std::to_string(small.usage.states) +
                                       " symbolic states in 1 locations)"),
              std::string::npos)
        << small.result.reason;
    // Twice the budget goes further (the count, not the time, stops it).
    const Outcome larger = CheckWithin(system, property, Budget(0.04));
    EXPECT_EQ(larger.result.verdict, Verdict::kUnknown);
    EXPECT_GT(larger.usage.states, small.usage.states);
  }
}

// Options::pause: one turn of another engine once the exploration has used pause_units, whose
// definite answers decide their properties; an exploration that ends first never pauses.
TEST(PolyhedralReachability, PausesOnceForAnotherEnginesTurnAndTakesItsDefiniteAnswers) {
  const System ramp = Parse(kRampModel);  // never converges: the pause comes
  for (const Verdict answer : {Verdict::kProved, Verdict::kUnknown}) {
    PolyhedralReachability::Options options = Budget(0.02);
    options.pause_units = 100'000;
    int calls = 0;
    options.pause = [&](const System& system, const std::vector<Property>& open) {
      ++calls;
      EXPECT_EQ(&system, &ramp);
      EXPECT_EQ(open.size(), 1u);
      CheckResult r;
      r.property = open.at(0).name;
      r.kind = open.at(0).kind;
      r.method = "other";
      r.verdict = answer;
      r.reason = "the other engine's answer";
      return std::vector<CheckResult>{r};
    };
    const Outcome out = CheckWithin(ramp, "y_nonnegative", options);
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(out.result.verdict, answer) << out.result.reason;
    if (answer == Verdict::kProved) {  // decided: the exploration stops there
      EXPECT_EQ(out.result.method, "other");
      EXPECT_EQ(out.result.reason, "the other engine's answer");
      EXPECT_LT(out.usage.units_used, out.usage.units_total);
      EXPECT_GE(out.usage.units_used, options.pause_units);
    } else {  // not decided: it goes on to its budget
      EXPECT_EQ(out.result.method, "reach");
      EXPECT_NE(out.result.reason.find("stopped by its deterministic budget"), std::string::npos)
          << out.result.reason;
      EXPECT_GE(out.usage.units_used, out.usage.units_total);
    }
  }
  const System limited = Parse(kLimitedModel);  // a fixpoint long before the pause
  PolyhedralReachability::Options options;
  options.pause_units = 100'000'000;
  int calls = 0;
  options.pause = [&](const System&, const std::vector<Property>&) {
    ++calls;
    return std::vector<CheckResult>{};
  };
  EXPECT_EQ(CheckWithin(limited, "below_5", options).result.verdict, Verdict::kProved);
  EXPECT_EQ(calls, 0);
}

// Runs `check` while `threads` other threads burn CPU (none: unloaded).
template <typename F>
auto UnderLoad(int threads, F check) {
  std::atomic<bool> stop{false};
  std::vector<std::thread> burners;
  for (int i = 0; i < threads; ++i) {
    burners.emplace_back([&stop] {
      volatile unsigned long long spin = 0;
      while (!stop.load(std::memory_order_relaxed)) spin = spin + 1;
    });
  }
  auto result = check();
  stop = true;
  for (std::thread& t : burners) t.join();
  return result;
}

// The same check gives the same verdict, reason, state count and units whether the machine is
// loaded or not (a test of determinism, not of speed: the CPU-time safety net, far beyond, does
// not fire, and nothing here reads a clock).
TEST(PolyhedralReachability, SameCheckSameOutcomeUnderLoad) {
  const unsigned cores = std::max(2u, std::thread::hardware_concurrency());
  for (const auto& [model, property] :
       {std::pair{kDriftModel, "bounded"}, std::pair{kRampModel, "y_nonnegative"}}) {
    const System system = Parse(model);
    const auto check = [&] { return CheckWithin(system, property, Budget(0.05)); };
    const Outcome quiet = UnderLoad(0, check);
    const Outcome loaded = UnderLoad(static_cast<int>(cores), check);
    EXPECT_EQ(quiet.result.verdict, loaded.result.verdict);
    EXPECT_EQ(quiet.result.reason, loaded.result.reason);
    EXPECT_EQ(quiet.usage.states, loaded.usage.states);
    EXPECT_EQ(quiet.usage.units_used, loaded.usage.units_used);
    EXPECT_EQ(quiet.usage.stop, PolyhedralReachability::Usage::Stop::kBudget);
    EXPECT_EQ(loaded.usage.stop, PolyhedralReachability::Usage::Stop::kBudget);
  }
  // A check that ends in verdicts (a violation with its replayed trace, a fixpoint) too.
  const System limited = Parse(kLimitedModel);
  const auto check = [&] {
    PolyhedralReachability::Usage usage;
    const auto r = PolyhedralReachability().Check(
        limited, {Named(limited, "below_5"), Named(limited, "below_3")}, &usage);
    return std::pair{r, usage};
  };
  const auto quiet = UnderLoad(0, check);
  const auto loaded = UnderLoad(static_cast<int>(cores), check);
  ASSERT_EQ(quiet.first.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(quiet.first[i].verdict, loaded.first[i].verdict);
    EXPECT_EQ(quiet.first[i].reason, loaded.first[i].reason);
  }
  EXPECT_EQ(quiet.first[0].verdict, Verdict::kProved);
  EXPECT_EQ(quiet.first[1].verdict, Verdict::kViolated);
  EXPECT_EQ(quiet.second.units_used, loaded.second.units_used);
  EXPECT_EQ(quiet.second.states, loaded.second.states);
  EXPECT_EQ(quiet.second.stop, PolyhedralReachability::Usage::Stop::kNone);
}

// When the CPU-time safety net stops the exploration, the reason says it was not the budget.
TEST(PolyhedralReachability, TheSafetyNetSaysItIsNotTheBudget) {
  const System system = Parse(kRampModel);
  PolyhedralReachability::Options options = Budget(1000);
  options.cpu_seconds = 1e-9;  // passed before the first expansion
  const Outcome out = CheckWithin(system, "y_nonnegative", options);
  EXPECT_EQ(out.result.verdict, Verdict::kUnknown);
  EXPECT_EQ(out.usage.stop, PolyhedralReachability::Usage::Stop::kSafetyNet);
  EXPECT_NE(out.result.reason.find("stopped by the CPU-time safety net"), std::string::npos)
      << out.result.reason;
  EXPECT_NE(out.result.reason.find("not by its deterministic budget"), std::string::npos)
      << out.result.reason;
  EXPECT_NE(out.result.reason.find("this verdict may differ on another machine"), std::string::npos)
      << out.result.reason;
  EXPECT_LT(out.usage.units_used, out.usage.units_total);
}

TEST(PolyhedralReachability, BudgetOutOfRangeIsRefused) {
  const System system = Parse(kLimitedModel);
  for (const double budget : {0.0, -1.0, std::nan(""), double{INFINITY}, 2e6}) {
    EXPECT_THROW(CheckWithin(system, "below_5", Budget(budget)), std::invalid_argument) << budget;
  }
}

// Properties with different horizons are explored apart, each with an equal share of what is
// left of the one budget.
TEST(PolyhedralReachability, HorizonsShareTheBudget) {
  std::string text(kRampModel);
  text.insert(text.rfind('}'), "  property y_nonnegative_long: always y >= 0 within 1000000;\n");
  const System system = Parse(text);
  PolyhedralReachability::Usage usage;
  const auto r =
      PolyhedralReachability(Budget(0.02))
          .Check(system, {Named(system, "y_nonnegative"), Named(system, "y_nonnegative_long")},
                 &usage);
  for (const CheckResult& result : r) {
    EXPECT_EQ(result.verdict, Verdict::kUnknown) << result.reason;
    EXPECT_NE(result.reason.find("stopped by its deterministic budget (this exploration's share, "),
              std::string::npos)
        << result.reason;
  }
  // The first (no horizon) had half; the second what was left of the 2000000 units.
  EXPECT_NE(r[0].reason.find("share, 1000000 of 2000000 reach units = 0.02 budget seconds)"),
            std::string::npos)
      << r[0].reason;
  EXPECT_EQ(usage.stop, PolyhedralReachability::Usage::Stop::kBudget);
  EXPECT_GE(usage.units_used, usage.units_total);
}

}  // namespace
}  // namespace hybrid
