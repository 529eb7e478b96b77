// Tests of the steps both explorations share (solvers/reachability/exploration_steps.h), with
// answers worked out by hand.

#include "solvers/reachability/exploration_steps.h"

#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "tests/test_utilities/polyhedra.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;

using testing::Plane;
using testing::Rectangle;
using testing::SameSet;

TEST(ExplorationSteps, BoxesRuleOutOnlyWhatCertainlyMisses) {
  const Box unit = BoxOf(Rectangle(0, 1, 0, 1));
  // x >= 2 (-x + 2 <= 0) misses [0, 1]^2; x >= 1 touches it; x + y == 3 misses, x + y == 2 not.
  EXPECT_TRUE(CertainlyMisses(unit, {{{-1, 0}, 2, Kind::kLessEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {{{-1, 0}, 1, Kind::kLessEqual}}));
  EXPECT_TRUE(CertainlyMisses(unit, {{{1, 1}, -3, Kind::kEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {{{1, 1}, -2, Kind::kEqual}}));
  EXPECT_FALSE(CertainlyMisses(unit, {}));
  // [0, 2]^2 may contain [0, 1]^2, not the other way round.
  const Box twice = BoxOf(Rectangle(0, 2, 0, 2));
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
  const ConvexPolyhedron flowed = Flow(loc, Rectangle(0, 0, 0, 1), nullptr, meter);
  EXPECT_TRUE(SameSet(flowed, Rectangle(0, 3, 0, 1)));
  EXPECT_GT(meter.used(), 0u);
  // Within `extra` (x <= 2, a horizon's kind) it stops there.
  const ConvexPolyhedron extra = Plane({{{1, 0}, -2, Kind::kLessEqual}});
  const ConvexPolyhedron bounded = Flow(loc, Rectangle(0, 0, 0, 1), &extra, meter);
  EXPECT_TRUE(SameSet(bounded, Rectangle(0, 2, 0, 1)));
  // Forgetting a dead dimension (y) leaves it unconstrained.
  loc.dead = {1};
  const ConvexPolyhedron forgotten = Forgetting(loc, Rectangle(0, 0, 0, 1), meter);
  EXPECT_TRUE(forgotten.Contains(Rectangle(0, 0, -5, 5)));
}

TEST(ExplorationSteps, AJumpKeepsItsGuardAndResetsAndEntersInsideTheInvariant) {
  // From [0, 3] x [0, 1] through guard x >= 2 with y := y + 1: [2, 3] x [1, 2]; into a location
  // whose invariant is y <= 1.5: [2, 3] x [1, 1.5]. Through guard x >= 4: nothing.
  LinearEdge edge;
  edge.guard = {{{-1, 0}, 2, Kind::kLessEqual}};
  edge.guard_set = Plane(edge.guard);
  edge.resets = {{1, AffineMap{{0, 1}, 1}}};
  ReachMeter meter(1'000'000, 60);
  const std::optional<ConvexPolyhedron> jumped = Jump(edge, Rectangle(0, 3, 0, 1), meter);
  ASSERT_TRUE(jumped.has_value());
  EXPECT_TRUE(SameSet(*jumped, Rectangle(2, 3, 1, 2)));
  LinearLocation target;
  target.invariant = {{{0, 1}, -1.5, Kind::kLessEqual}};
  target.invariant_set = Plane(target.invariant);
  const std::optional<ConvexPolyhedron> entered = Entering(target, *jumped, meter);
  ASSERT_TRUE(entered.has_value());
  EXPECT_TRUE(SameSet(*entered, Rectangle(2, 3, 1, 1.5)));
  // An invariant that holds on all of it (y <= 2): the set as it is; none of an empty set.
  target.invariant = {{{0, 1}, -2, Kind::kLessEqual}};
  target.invariant_set = Plane(target.invariant);
  const std::optional<ConvexPolyhedron> inside = Entering(target, *jumped, meter);
  ASSERT_TRUE(inside.has_value());
  EXPECT_TRUE(SameSet(*inside, Rectangle(2, 3, 1, 2)));
  EXPECT_FALSE(Entering(target, ConvexPolyhedron::Empty(2), meter).has_value());
  // An invariant it misses, a guard it misses.
  target.invariant = {{{0, 1}, -0.5, Kind::kLessEqual}};
  target.invariant_set = Plane(target.invariant);
  EXPECT_FALSE(Entering(target, *jumped, meter).has_value());
  edge.guard = {{{-1, 0}, 4, Kind::kLessEqual}};
  edge.guard_set = Plane(edge.guard);
  EXPECT_FALSE(Jump(edge, Rectangle(0, 3, 0, 1), meter).has_value());
}

}  // namespace
}  // namespace hybrid
