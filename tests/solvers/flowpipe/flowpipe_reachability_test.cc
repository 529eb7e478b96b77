// Tests of the flowpipe engine against analytic solutions: every recorded box must hold the exact
// solution (soundness) and be close to it (precision), and verdicts must match what the closed
// forms say. The oracles are the closed forms written here, not the engine.
#include "hybrid/flowpipe/flowpipe_reachability.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/system.h"

namespace hybrid {
namespace {

System Load(const std::string& text) { return ParseModel(text, "test.ha"); }

std::vector<CheckResult> CheckAll(const System& system,
                                  FlowpipeReachability::ReachSet* set = nullptr,
                                  FlowpipeReachability::Options options = {}) {
  return FlowpipeReachability(options).Check(system, system.properties(), nullptr, set);
}

// Index of variable `name` in a reach set.
std::size_t Column(const FlowpipeReachability::ReachSet& set, const std::string& name) {
  for (std::size_t i = 0; i < set.variables.size(); ++i) {
    if (set.variables[i] == name) return i;
  }
  ADD_FAILURE() << "no variable " << name;
  return 0;
}

// Whether some box of `set` whose time span holds t holds the point (x, y) (y ignored when
// `ycol` is npos): the union of the boxes is what the engine claims to enclose.
bool Covered(const FlowpipeReachability::ReachSet& set, double t, std::size_t xcol, double x,
             std::size_t ycol = std::string::npos, double y = 0.0) {
  for (const auto& b : set.boxes) {
    if (t < b.t_lo || t > b.t_hi) continue;
    if (x < b.box[xcol].first || x > b.box[xcol].second) continue;
    if (ycol != std::string::npos && (y < b.box[ycol].first || y > b.box[ycol].second)) continue;
    return true;
  }
  return false;
}

// The step these tests fix (the automatic one depends on |df/dx|), for bounds on precision.
FlowpipeReachability::Options FixedStep() {
  FlowpipeReachability::Options options;
  options.step = 1.0 / 32;
  options.max_pieces = 1;
  return options;
}

// x' = -x from x0 in [1, 2]: x(t) = x0 exp(-t). The boxes cover the solutions from both ends at
// every 1/100 of a time unit; every box is at most 2 h |x'| (h = 1/32, |x'| <= 2) wider than the
// range of the solutions over its step (the time terms of a step are bounded apart from the start
// set's).
TEST(FlowpipeReachability, DecayBoxesHoldTheClosedForm) {
  const System s = Load(R"(automaton decay {
    var x;
    mode m { x' = -x; }
    init m { x in [1, 2]; }
    scenario { until 5; }
    property positive: always x > 0;
    property below_start: always x <= 2;
  })");
  FlowpipeReachability::ReachSet set;
  const std::vector<CheckResult> r = CheckAll(s, &set, FixedStep());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
  const std::size_t x = Column(set, "x");
  for (int k = 0; k <= 500; ++k) {
    const double t = k / 100.0;
    for (double x0 : {1.0, 2.0}) EXPECT_TRUE(Covered(set, t, x, x0 * std::exp(-t))) << "t = " << t;
  }
  int checked = 0;
  for (const auto& b : set.boxes) {
    if (!std::isfinite(b.t_hi) || b.t_lo > 5) continue;
    const double lo = std::exp(-b.t_hi), hi = 2 * std::exp(-b.t_lo);
    EXPECT_LE(b.box[x].second - b.box[x].first, hi - lo + 2 * 2.0 / 32)
        << "t in [" << b.t_lo << ", " << b.t_hi << "]";
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

// The harmonic oscillator x' = y, y' = -x rotates its start box: from [0.9, 1.1] x [-0.1, 0.1]
// the exact solutions x0 cos t + y0 sin t, y0 cos t - x0 sin t of the four corners are covered
// every 1/50 for ten time units (a full turn and a half), and no box grows much beyond the
// rotated box's hull (width 0.2 sqrt 2 = 0.28).
TEST(FlowpipeReachability, OscillatorBoxesHoldTheRotation) {
  const System s = Load(R"(automaton spin {
    var x; var y;
    mode m { x' = y; y' = -x; }
    init m { x in [0.9, 1.1]; y in [-0.1, 0.1]; }
    property inside: always x^2 + y^2 <= 1.5 within 10;
  })");
  FlowpipeReachability::ReachSet set;
  const std::vector<CheckResult> r = CheckAll(s, &set, FixedStep());
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  const std::size_t x = Column(set, "x"), y = Column(set, "y");
  for (int k = 0; k <= 500; ++k) {
    const double t = k / 50.0;
    for (double x0 : {0.9, 1.1}) {
      for (double y0 : {-0.1, 0.1}) {
        const double ex = x0 * std::cos(t) + y0 * std::sin(t);
        const double ey = y0 * std::cos(t) - x0 * std::sin(t);
        EXPECT_TRUE(Covered(set, t, x, ex, y, ey)) << "t = " << t;
      }
    }
  }
  for (const auto& b : set.boxes) {
    EXPECT_LT(b.box[x].second - b.box[x].first, 0.45) << "t = " << b.t_lo;
  }
}

// A ball dropped from exactly h0: the drop height is attained, so `never h > h0` holds only with
// an exact bound (rounding outward blindly would lose it); with the fixpoint of the bounces it
// is proved for all time. The first impact speed sqrt(2 g h0) = 14.007 bounds every later speed
// (proved with the margin of a refined step: g h / 8 = 0.077).
TEST(FlowpipeReachability, BallNeverRisesAboveItsDropHeight) {
  const System s = Load(R"(automaton ball {
    param g = 9.81; param e = 0.8; param h0 = 10;
    var h; var v;
    mode falling { h' = v; v' = -g; inv h >= 0; }
    mode resting { inv h >= 0; }
    transition bounce: falling -> falling { guard h <= 0 and v < -0.01; reset v := -e * v; }
    transition stop: falling -> resting { guard h <= 0 and v <= 0 and v >= -0.01; reset h := 0, v := 0; }
    init falling { h = h0; v = 0; }
    property drop: never h > h0;
    property speed: always v <= 14.1 and v >= -14.1;
    property too_slow: always v <= 11;
  })");
  const std::vector<CheckResult> r = CheckAll(s, nullptr, FixedStep());
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_FALSE(r[0].within.has_value()) << r[0].reason;  // for all time
  EXPECT_EQ(r[1].verdict, Verdict::kProved) << r[1].reason;
  // 0.8 * sqrt(2 * 9.81 * 10) = 11.2 > 11 after the first bounce: never proved.
  EXPECT_EQ(r[2].verdict, Verdict::kUnknown) << r[2].reason;
}

// `within T`: x' = -x from 1 stays at or above 0.5 until ln 2 = 0.693.
TEST(FlowpipeReachability, WithinBoundsTheQuestion) {
  const System s = Load(R"(automaton decay {
    var x;
    mode m { x' = -x; }
    init m { x = 1; }
    property early: always x >= 0.5 within 0.6;
    property late: always x >= 0.5 within 0.8;
  })");
  const std::vector<CheckResult> r = CheckAll(s);
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kUnknown) << r[1].reason;
}

// x' = -x + u, u in [-1, 1], from 0: the reachable set is |x| <= 1 - exp(-t) < 1 for all time
// (an invariant box proves a bound 10% above: a step's time terms add 2 h |x'|, h = 1/32), while
// any bound below 1 fails eventually.
TEST(FlowpipeReachability, InputsAreCoveredForAllTime) {
  const System s = Load(R"(automaton driven {
    var x;
    input u in [-1, 1];
    mode m { x' = -x + u; }
    init m { x = 0; }
    property bounded: always x <= 1.1 and x >= -1.1;
    property tight: always x <= 0.9;
    property early: always x <= 0.1 within 0.1;
  })");
  const std::vector<CheckResult> r = CheckAll(s, nullptr, FixedStep());
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_FALSE(r[0].within.has_value()) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kUnknown) << r[1].reason;
  // 1 - exp(-0.1) = 0.0952 <= 0.1.
  EXPECT_EQ(r[2].verdict, Verdict::kProved) << r[2].reason;
}

// An uncertain parameter is covered over its whole range: x' = -k x, k in [1, 2], from 1:
// x(1) in [exp(-2), exp(-1)] = [0.135, 0.368].
TEST(FlowpipeReachability, UncertainParametersAreCovered) {
  const System s = Load(R"(automaton decay {
    param k = 1.5 in [1, 2];
    var x;
    var t;
    mode m { x' = -k * x; t' = 1; inv t <= 1; }
    init m { x = 1; t = 0; }
    property above: always x >= 0.13;
    property not_above: always x >= 0.14;
  })");
  const std::vector<CheckResult> r = CheckAll(s);
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  EXPECT_EQ(r[1].verdict, Verdict::kUnknown) << r[1].reason;
}

// With no fixpoint and no `within`, a bounded exploration says how far it went.
TEST(FlowpipeReachability, BoundedProofsSayTheirHorizon) {
  const System s = Load(R"(automaton vdp {
    var x; var y;
    mode m { x' = y; y' = (1 - x^2) * y - x; }
    init m { x in [1.25, 1.3]; y in [2.35, 2.4]; }
    scenario { until 3; }
    property bounded: always y <= 4;
  })");
  const std::vector<CheckResult> r = CheckAll(s);
  EXPECT_EQ(r[0].verdict, Verdict::kProved) << r[0].reason;
  ASSERT_TRUE(r[0].within.has_value()) << r[0].reason;
  EXPECT_EQ(*r[0].within, 3.0);
}

TEST(FlowpipeReachability, HandlesSaysWhichFlowIsNotPolynomial) {
  const System s = Load(R"(automaton pendulum {
    var a; var w;
    mode swing { a' = w; w' = -sin(a); }
    init swing { a = 1; w = 0; }
    property p: always a <= 2;
  })");
  std::string why;
  EXPECT_FALSE(FlowpipeReachability::Handles(s, s.properties(), &why));
  EXPECT_NE(why.find("sin(a)"), std::string::npos) << why;
  EXPECT_NE(why.find("swing"), std::string::npos) << why;
  // Asked anyway (--method flowpipe), it answers unknown at once, saying why.
  const std::vector<CheckResult> r = CheckAll(s);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].verdict, Verdict::kUnknown);
  EXPECT_NE(r[0].reason.find("sin(a)"), std::string::npos) << r[0].reason;
}

TEST(FlowpipeReachability, BadOptionsAreRefused) {
  const System s = Load(
      R"(automaton a { var x; mode m { x' = 1; } init m { x = 0; } property p: always x >= 0; })");
  FlowpipeReachability::Options options;
  options.order = 0;
  EXPECT_THROW(FlowpipeReachability(options).Check(s, s.properties()), std::invalid_argument);
  options.order = 6;
  options.max_steps = 0;
  EXPECT_THROW(FlowpipeReachability(options).Check(s, s.properties()), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
