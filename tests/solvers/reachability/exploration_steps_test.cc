// Tests of the steps both explorations share (solvers/reachability/exploration_steps.h), with
// answers worked out by hand.

#include "solvers/reachability/exploration_steps.h"

#include <gtest/gtest.h>

#include <vector>

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;

ConvexPolyhedron Plane(const std::vector<LinearConstraint>& constraints) {
  ConvexPolyhedron p = ConvexPolyhedron::Universe(2);
  for (const LinearConstraint& c : constraints) p.AddConstraint(c);
  return p;
}

// The box [x0, x1] x [y0, y1].
ConvexPolyhedron Box2(double x0, double x1, double y0, double y1) {
  return Plane({{{-1, 0}, x0, Kind::kLessEqual},
                {{1, 0}, -x1, Kind::kLessEqual},
                {{0, -1}, y0, Kind::kLessEqual},
                {{0, 1}, -y1, Kind::kLessEqual}});
}

TEST(ExplorationSteps, BoxesRuleOutOnlyWhatCertainlyMisses) {
  const Box unit = BoxOf(Box2(0, 1, 0, 1));
  // x >= 2 (-x + 2 <= 0) misses [0, 1]^2; x >= 1 touches it; x + y == 3 misses, x + y == 2 not.
  EXPECT_TRUE(CertainlyMisses(unit, {{{-1, 0}, 2, Kind::kLessEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {{{-1, 0}, 1, Kind::kLessEqual}}));
  EXPECT_TRUE(CertainlyMisses(unit, {{{1, 1}, -3, Kind::kEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {{{1, 1}, -2, Kind::kEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {}));
  // [0, 2]^2 may contain [0, 1]^2, not the other way round.
  const Box twice = BoxOf(Box2(0, 2, 0, 2));
  EXPECT_TRUE(MayContain(twice, unit));
  EXPECT_FALSE(MayContain(unit, twice));
}

TEST(ExplorationSteps, FlowLetsTimePassInsideTheInvariant) {
  // x' = 1, y' = 0 inside x <= 3, from the segment x = 0, 0 <= y <= 1: [0, 3] x [0, 1].
  LinearLocation loc;
  loc.invariant = {{{1, 0}, -3, Kind::kLessEqual}};
  loc.elapse_invariant = loc.invariant;
  loc.invariant_set = Plane(loc.invariant);
  loc.elapse_set = loc.invariant_set;
  loc.rates = Plane({{{1, 0}, -1, Kind::kEqual}, {{0, 1}, 0, Kind::kEqual}});
  ReachMeter meter(1'000'000, 60);
  const ConvexPolyhedron flowed = Flow(loc, Box2(0, 0, 0, 1), nullptr, meter);
  EXPECT_TRUE(flowed.Contains(Box2(0, 3, 0, 1)));
  EXPECT_TRUE(Box2(0, 3, 0, 1).Contains(flowed));
  EXPECT_GT(meter.used(), 0u);
  // Within `extra` (x <= 2, a horizon's kind) it stops there.
  const ConvexPolyhedron extra = Plane({{{1, 0}, -2, Kind::kLessEqual}});
  const ConvexPolyhedron bounded = Flow(loc, Box2(0, 0, 0, 1), &extra, meter);
  EXPECT_TRUE(Box2(0, 2, 0, 1).Contains(bounded));
  EXPECT_TRUE(bounded.Contains(Box2(0, 2, 0, 1)));
  // Forgetting a dead dimension (y) leaves it unconstrained.
  loc.dead = {1};
  const ConvexPolyhedron forgotten = Forgetting(loc, Box2(0, 0, 0, 1), meter);
  EXPECT_TRUE(forgotten.Contains(Box2(0, 0, -5, 5)));
}

}  // namespace
}  // namespace hybrid
