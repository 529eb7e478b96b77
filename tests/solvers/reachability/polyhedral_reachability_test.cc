// Tests of exact polyhedral reachability (solvers/reachability/): the ConvexPolyhedron operations
// against sets computed by hand (time elapse forward and backward, simultaneous resets and their
// pre-images, strict constraints, suprema and central points, MaximizeLinear), and
// PolyhedralReachability on small models whose verdicts are known analytically: proved bounds,
// violations and witnesses whose traces the simulator replays, a rectangular rate, an uncertain
// parameter, a simultaneous swap and a long chain of jumps.

#include "solvers/reachability/polyhedral_reachability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "automaton/parser.h"
#include "solvers/reachability/convex_polyhedron.h"
#include "solvers/simulation/simulator.h"
#include "solvers/verification/trace.h"
#include "tests/test_utilities/properties.h"
#include "tests/test_utilities/trace_states.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;
using testing::AtTarget;
using testing::Named;
using testing::Replayed;

// The polyhedron of R^2 where every constraint a0 x + a1 y + b REL 0 holds.
ConvexPolyhedron Plane(const std::vector<LinearConstraint>& constraints) {
  ConvexPolyhedron p = ConvexPolyhedron::Universe(2);
  for (const LinearConstraint& c : constraints) p.AddConstraint(c);
  return p;
}

// Whether a and b are the same set.
bool SameSet(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  return a.Contains(b) && b.Contains(a);
}

bool Holds(const ConvexPolyhedron& p, double x, double y) {
  return p.Contains(ConvexPolyhedron::Point(std::vector<double>{x, y}));
}

// The box [x0, x1] x [y0, y1].
ConvexPolyhedron Box(double x0, double x1, double y0, double y1) {
  return Plane({{{-1, 0}, x0, Kind::kLessEqual},
                {{1, 0}, -x1, Kind::kLessEqual},
                {{0, -1}, y0, Kind::kLessEqual},
                {{0, 1}, -y1, Kind::kLessEqual}});
}

TEST(ConvexPolyhedron, TimeElapseOfAPointWithARateBox) {
  // From (0, 0) at x' in [1, 2], y' = 1: {y >= 0, y <= x <= 2 y}.
  ConvexPolyhedron p = ConvexPolyhedron::Point(std::vector<double>{0, 0});
  const ConvexPolyhedron rates = Box(1, 2, 1, 1);
  p.TimeElapse(rates);
  const ConvexPolyhedron expected = Plane({{{0, -1}, 0, Kind::kLessEqual},
                                           {{-1, 1}, 0, Kind::kLessEqual},
                                           {{1, -2}, 0, Kind::kLessEqual}});
  EXPECT_TRUE(SameSet(p, expected));
  EXPECT_TRUE(Holds(p, 1.5, 1));
  EXPECT_FALSE(Holds(p, 0.5, 1));
  EXPECT_FALSE(Holds(p, 3, 1));
  EXPECT_FALSE(Holds(p, -1, -1));
}

TEST(ConvexPolyhedron, TimeElapseBackwardReversesTheRates) {
  // The states from which (2, 1) is reached at x' in [1, 2], y' = 1: (2 - t r, 1 - t), so
  // y <= 1 and 1 - y <= 2 - x <= 2 (1 - y): {y <= 1, x <= 1 + y, x >= 2 y}.
  ConvexPolyhedron p = ConvexPolyhedron::Point(std::vector<double>{2, 1});
  p.TimeElapseBackward(Box(1, 2, 1, 1));
  const ConvexPolyhedron expected = Plane({{{0, 1}, -1, Kind::kLessEqual},
                                           {{1, -1}, -1, Kind::kLessEqual},
                                           {{-1, 2}, 0, Kind::kLessEqual}});
  EXPECT_TRUE(SameSet(p, expected));
  EXPECT_TRUE(Holds(p, 0.5, 0));  // at rate 1.5 for 1
  EXPECT_FALSE(Holds(p, 2.5, 1.5));
}

TEST(ConvexPolyhedron, BoundsPerDimension) {
  using Bounds = std::vector<std::pair<double, double>>;
  EXPECT_EQ(Box(0, 1, 2, 3).Bounds(), (Bounds{{0, 1}, {2, 3}}));
  // A cone from the origin: unbounded above in both dimensions.
  ConvexPolyhedron cone = ConvexPolyhedron::Point(std::vector<double>{0, 0});
  cone.TimeElapse(Box(1, 2, 1, 1));
  EXPECT_EQ(cone.Bounds(), (Bounds{{0, INFINITY}, {0, INFINITY}}));
  // Strict bounds are the same numbers; a line is unbounded both ways; empty is (inf, -inf).
  const ConvexPolyhedron open = Plane({{{1, 0}, -1, Kind::kLess}, {{-1, 0}, 0, Kind::kLess}});
  EXPECT_EQ(open.Bounds(), (Bounds{{0, 1}, {-INFINITY, INFINITY}}));
  EXPECT_EQ(ConvexPolyhedron::Empty(1).Bounds(), (Bounds{{INFINITY, -INFINITY}}));
}

TEST(ConvexPolyhedron, SimultaneousResetsSwap) {
  // x := y, y := x on [0, 1] x [2, 3] gives [2, 3] x [0, 1] (one after the other would give a
  // part of the diagonal).
  ConvexPolyhedron p = Box(0, 1, 2, 3);
  const std::vector<std::pair<int, AffineMap>> swap = {{0, AffineMap{{0, 1}, 0}},
                                                       {1, AffineMap{{1, 0}, 0}}};
  p.Assign(swap);
  EXPECT_TRUE(SameSet(p, Box(2, 3, 0, 1)));
  // Its pre-image is the box it came from.
  p.AssignPreimage(swap);
  EXPECT_TRUE(SameSet(p, Box(0, 1, 2, 3)));
}

TEST(ConvexPolyhedron, ResetPreimages) {
  // x := x + y into {x >= 5}: {x + y >= 5}; y unchanged.
  ConvexPolyhedron p = Plane({{{-1, 0}, 5, Kind::kLessEqual}});
  const std::vector<std::pair<int, AffineMap>> shift = {{0, AffineMap{{1, 1}, 0}}};
  p.AssignPreimage(shift);
  EXPECT_TRUE(SameSet(p, Plane({{{-1, -1}, 5, Kind::kLessEqual}})));
  // x := 2, y := x + 1 into [0, 1] x [3, 4]: x + 1 in [3, 4] (2 is in [0, 1]? no): empty.
  ConvexPolyhedron q = Box(0, 1, 3, 4);
  const std::vector<std::pair<int, AffineMap>> to_two = {{0, AffineMap{{0, 0}, 2}},
                                                         {1, AffineMap{{1, 0}, 1}}};
  q.AssignPreimage(to_two);
  EXPECT_TRUE(q.IsEmpty());
  // x := 0.5, y := x + 1 into the same box: x in [2, 3], y free.
  ConvexPolyhedron r = Box(0, 1, 3, 4);
  const std::vector<std::pair<int, AffineMap>> to_half = {{0, AffineMap{{0, 0}, 0.5}},
                                                          {1, AffineMap{{1, 0}, 1}}};
  r.AssignPreimage(to_half);
  EXPECT_TRUE(SameSet(r, Plane({{{-1, 0}, 2, Kind::kLessEqual}, {{1, 0}, -3, Kind::kLessEqual}})));
}

TEST(ConvexPolyhedron, StrictConstraintsStayStrict) {
  ConvexPolyhedron open = ConvexPolyhedron::Universe(1);
  open.AddConstraint({{1}, -1, Kind::kLess});  // x < 1
  open.AddConstraint({{-1}, 0, Kind::kLess});  // x > 0
  ConvexPolyhedron closed = ConvexPolyhedron::Universe(1);
  closed.AddConstraint({{1}, -1, Kind::kLessEqual});
  closed.AddConstraint({{-1}, 0, Kind::kLessEqual});
  const ConvexPolyhedron one = ConvexPolyhedron::Point(std::vector<double>{1});
  EXPECT_FALSE(open.Contains(one));
  EXPECT_TRUE(closed.Contains(one));
  EXPECT_TRUE(closed.Contains(open));
  EXPECT_FALSE(open.Contains(closed));
  EXPECT_FALSE(open.Intersects(one));
  // x < 1 and x >= 1: empty; x <= 1 and x >= 1: the point 1.
  ConvexPolyhedron none = open;
  none.AddConstraint({{-1}, 1, Kind::kLessEqual});
  EXPECT_TRUE(none.IsEmpty());
  ConvexPolyhedron point = closed;
  point.AddConstraint({{-1}, 1, Kind::kLessEqual});
  EXPECT_TRUE(point.IsPoint());
  // The supremum 1 of x over (0, 1) is not reached, over [0, 1] it is.
  bool attained = true;
  EXPECT_EQ(open.Supremum(std::vector<double>{1}, &attained), 1.0);
  EXPECT_FALSE(attained);
  EXPECT_FALSE(open.RestrictToMaximum(std::vector<double>{1}));
  EXPECT_EQ(closed.Supremum(std::vector<double>{1}, &attained), 1.0);
  EXPECT_TRUE(attained);
  EXPECT_TRUE(closed.RestrictToMaximum(std::vector<double>{1}));
  EXPECT_TRUE(SameSet(closed, one));
  // The central point of (0, 1) is 1/2, inside although both ends are excluded.
  const ConvexPolyhedron middle = open.CentralPoint();
  EXPECT_TRUE(middle.IsPoint());
  EXPECT_TRUE(open.Contains(middle));
  EXPECT_EQ(middle.PointCoordinates(), std::vector<double>{0.5});
}

TEST(ConvexPolyhedron, CentralPointsAreExactAndInside) {
  // The triangle (0, 0), (3, 0), (0, 3): its barycentre (1, 1).
  const ConvexPolyhedron triangle = Plane({{{-1, 0}, 0, Kind::kLessEqual},
                                           {{0, -1}, 0, Kind::kLessEqual},
                                           {{1, 1}, -3, Kind::kLessEqual}});
  EXPECT_EQ(triangle.CentralPoint().PointCoordinates(), (std::vector<double>{1, 1}));
  // The point x = 1/3, y = 0 (3 x - 1 = 0): no double is 1/3, the point is kept exact.
  const ConvexPolyhedron third = Plane({{{3, 0}, -1, Kind::kEqual}, {{0, 1}, 0, Kind::kEqual}});
  const ConvexPolyhedron p = third.CentralPoint();
  EXPECT_TRUE(SameSet(p, third));
  EXPECT_FALSE(third.Contains(ConvexPolyhedron::Point(std::vector<double>{1.0 / 3.0, 0})));
  EXPECT_DOUBLE_EQ(p.PointCoordinates()[0], 1.0 / 3.0);
  // The half-line x >= 2, y = 1: its vertex plus its unit ray, inside it.
  const ConvexPolyhedron half_line =
      Plane({{{-1, 0}, 2, Kind::kLessEqual}, {{0, 1}, -1, Kind::kEqual}});
  EXPECT_EQ(half_line.CentralPoint().PointCoordinates(), (std::vector<double>{3, 1}));
  EXPECT_THROW(ConvexPolyhedron::Empty(2).CentralPoint(), std::logic_error);
}

TEST(MaximizeLinear, SmallProgramHasItsKnownOptimum) {
  // max 3x + 2y s.t. x + y <= 4, x + 3y <= 6, x <= 3, x, y >= 0: at (3, 1), value 11.
  const std::vector<LinearConstraint> rows = {{{1, 1}, -4, Kind::kLessEqual},
                                              {{1, 3}, -6, Kind::kLessEqual},
                                              {{1, 0}, -3, Kind::kLessEqual},
                                              {{-1, 0}, 0, Kind::kLessEqual},
                                              {{0, -1}, 0, Kind::kLessEqual}};
  const std::vector<double> objective = {3, 2};
  const auto x = MaximizeLinear(2, rows, objective);
  ASSERT_TRUE(x.has_value());
  EXPECT_DOUBLE_EQ((*x)[0], 3.0);
  EXPECT_DOUBLE_EQ((*x)[1], 1.0);
  // The same optimum as the polyhedron's supremum.
  ConvexPolyhedron p = Plane(rows);
  EXPECT_EQ(p.Supremum(objective), 11.0);
  // With x + y >= 5 it is infeasible.
  std::vector<LinearConstraint> infeasible = rows;
  infeasible.push_back({{-1, -1}, 5, Kind::kLessEqual});
  EXPECT_FALSE(MaximizeLinear(2, infeasible, objective).has_value());
}

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

}  // namespace
}  // namespace hybrid
