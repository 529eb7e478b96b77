// Tests of ConvexPolyhedron (solvers/reachability/convex_polyhedron.h), the exact rational
// polyhedra of polyhedral reachability: its operations against sets computed by hand (time
// elapse forward and backward, simultaneous resets and their pre-images, strict constraints,
// suprema and central points, bounds), MaximizeLinear, and the size measure the deterministic
// reachability budget charges (RepresentationBytes).

#include "solvers/reachability/convex_polyhedron.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tests/test_utilities/polyhedra.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;

using testing::Plane;
using testing::Rectangle;
using testing::SameSet;

bool Holds(const ConvexPolyhedron& p, double x, double y) {
  return p.Contains(ConvexPolyhedron::Point(std::vector<double>{x, y}));
}

TEST(ConvexPolyhedron, TimeElapseOfAPointWithARateBox) {
  // From (0, 0) at x' in [1, 2], y' = 1: {y >= 0, y <= x <= 2 y}.
  ConvexPolyhedron p = ConvexPolyhedron::Point(std::vector<double>{0, 0});
  const ConvexPolyhedron rates = Rectangle(1, 2, 1, 1);
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
  p.TimeElapseBackward(Rectangle(1, 2, 1, 1));
  const ConvexPolyhedron expected = Plane({{{0, 1}, -1, Kind::kLessEqual},
                                           {{1, -1}, -1, Kind::kLessEqual},
                                           {{-1, 2}, 0, Kind::kLessEqual}});
  EXPECT_TRUE(SameSet(p, expected));
  EXPECT_TRUE(Holds(p, 0.5, 0));  // at rate 1.5 for 1
  EXPECT_FALSE(Holds(p, 2.5, 1.5));
}

TEST(ConvexPolyhedron, BoundsPerDimension) {
  using Bounds = std::vector<std::pair<double, double>>;
  EXPECT_EQ(Rectangle(0, 1, 2, 3).Bounds(), (Bounds{{0, 1}, {2, 3}}));
  // A cone from the origin: unbounded above in both dimensions.
  ConvexPolyhedron cone = ConvexPolyhedron::Point(std::vector<double>{0, 0});
  cone.TimeElapse(Rectangle(1, 2, 1, 1));
  EXPECT_EQ(cone.Bounds(), (Bounds{{0, INFINITY}, {0, INFINITY}}));
  // Strict bounds are the same numbers; a line is unbounded both ways; empty is (inf, -inf).
  const ConvexPolyhedron open = Plane({{{1, 0}, -1, Kind::kLess}, {{-1, 0}, 0, Kind::kLess}});
  EXPECT_EQ(open.Bounds(), (Bounds{{0, 1}, {-INFINITY, INFINITY}}));
  EXPECT_EQ(ConvexPolyhedron::Empty(1).Bounds(), (Bounds{{INFINITY, -INFINITY}}));
}

TEST(ConvexPolyhedron, SimultaneousResetsThatReadNoOtherWrittenDimension) {
  // x := x / 2 + 1, y := 7 on [0, 1] x [2, 3]: [1, 1.5] x {7}, each map reading the values before.
  ConvexPolyhedron p = Rectangle(0, 1, 2, 3);
  const std::vector<std::pair<int, AffineMap>> maps = {{0, AffineMap{{0.5, 0}, 1}},
                                                       {1, AffineMap{{0, 0}, 7}}};
  p.Assign(maps);
  EXPECT_TRUE(SameSet(p, Rectangle(1, 1.5, 7, 7)));
  // y := x + y, x := 0 reads x, which the other writes: x + y of the values before.
  ConvexPolyhedron q = Rectangle(0, 1, 2, 3);
  const std::vector<std::pair<int, AffineMap>> reading = {{1, AffineMap{{1, 1}, 0}},
                                                          {0, AffineMap{{0, 0}, 0}}};
  q.Assign(reading);
  EXPECT_TRUE(SameSet(q, Rectangle(0, 0, 2, 4)));
}

TEST(ConvexPolyhedron, SimultaneousResetsSwap) {
  // x := y, y := x on [0, 1] x [2, 3] gives [2, 3] x [0, 1] (one after the other would give a
  // part of the diagonal).
  ConvexPolyhedron p = Rectangle(0, 1, 2, 3);
  const std::vector<std::pair<int, AffineMap>> swap = {{0, AffineMap{{0, 1}, 0}},
                                                       {1, AffineMap{{1, 0}, 0}}};
  p.Assign(swap);
  EXPECT_TRUE(SameSet(p, Rectangle(2, 3, 0, 1)));
  // Its pre-image is the box it came from.
  p.AssignPreimage(swap);
  EXPECT_TRUE(SameSet(p, Rectangle(0, 1, 2, 3)));
}

TEST(ConvexPolyhedron, ResetPreimages) {
  // x := x + y into {x >= 5}: {x + y >= 5}; y unchanged.
  ConvexPolyhedron p = Plane({{{-1, 0}, 5, Kind::kLessEqual}});
  const std::vector<std::pair<int, AffineMap>> shift = {{0, AffineMap{{1, 1}, 0}}};
  p.AssignPreimage(shift);
  EXPECT_TRUE(SameSet(p, Plane({{{-1, -1}, 5, Kind::kLessEqual}})));
  // x := 2, y := x + 1 into [0, 1] x [3, 4]: x + 1 in [3, 4] (2 is in [0, 1]? no): empty.
  ConvexPolyhedron q = Rectangle(0, 1, 3, 4);
  const std::vector<std::pair<int, AffineMap>> to_two = {{0, AffineMap{{0, 0}, 2}},
                                                         {1, AffineMap{{1, 0}, 1}}};
  q.AssignPreimage(to_two);
  EXPECT_TRUE(q.IsEmpty());
  // x := 0.5, y := x + 1 into the same box: x in [2, 3], y free.
  ConvexPolyhedron r = Rectangle(0, 1, 3, 4);
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

// The size measure grows with the representation, and is the same for the same operations.
TEST(ConvexPolyhedron, RepresentationBytesGrowWithTheRepresentation) {
  const ConvexPolyhedron square = Rectangle(0, 1, 0, 1);
  // A polygon with more sides: the square with its four corners cut.
  const ConvexPolyhedron octagon = Plane({{{-1, 0}, 0, Kind::kLessEqual},
                                          {{1, 0}, -3, Kind::kLessEqual},
                                          {{0, -1}, 0, Kind::kLessEqual},
                                          {{0, 1}, -3, Kind::kLessEqual},
                                          {{-1, -1}, 1, Kind::kLessEqual},
                                          {{1, 1}, -5, Kind::kLessEqual},
                                          {{1, -1}, -2, Kind::kLessEqual},
                                          {{-1, 1}, -2, Kind::kLessEqual}});
  EXPECT_GT(square.RepresentationBytes(), ConvexPolyhedron::Universe(2).RepresentationBytes());
  EXPECT_GT(octagon.RepresentationBytes(), square.RepresentationBytes());
  // Longer coefficients take more bytes: the same square scaled by a large factor.
  const double big = 1e30;
  EXPECT_GT(Rectangle(0, big, 0, big).RepresentationBytes(), square.RepresentationBytes());
  // More dimensions take more bytes.
  ConvexPolyhedron wider = square;
  wider.AddDimensions(6);
  EXPECT_GT(wider.RepresentationBytes(), square.RepresentationBytes());
  // Deterministic: the same operations give the same figure. It counts what is allocated, so a
  // copy (allocated to fit) may measure less than its original, never more.
  auto made = [] {
    ConvexPolyhedron p = ConvexPolyhedron::Point(std::vector<double>{0, 0});
    p.TimeElapse(Rectangle(1, 2, 1, 1));
    p.Intersect(Rectangle(0, 3, 0, 2));
    (void)p.Bounds();
    return p;
  };
  const ConvexPolyhedron a = made();
  EXPECT_EQ(a.RepresentationBytes(), made().RepresentationBytes());
  const ConvexPolyhedron copy = a;
  EXPECT_LE(copy.RepresentationBytes(), a.RepresentationBytes());
  EXPECT_GT(copy.RepresentationBytes(), square.RepresentationBytes());
}

TEST(ConvexPolyhedron, EmbeddedPlacesEachDimensionAndLeavesTheOthersFree) {
  // {(a, b) : a = 1, 0 <= b <= 2} placed as dimensions 3 and 1 of R^4.
  ConvexPolyhedron p = ConvexPolyhedron::Universe(2);
  p.AddConstraint({{1, 0}, -1, LinearConstraint::Kind::kEqual});
  p.AddConstraint({{0, -1}, 0, LinearConstraint::Kind::kLessEqual});
  p.AddConstraint({{0, 1}, -2, LinearConstraint::Kind::kLessEqual});
  const std::vector<int> to = {3, 1};
  const ConvexPolyhedron e = p.Embedded(4, to);
  EXPECT_EQ(e.dims(), 4);
  const double inside[] = {5, 1.5, -7, 1};
  const double wrong_b[] = {0, 3, 0, 1};
  const double wrong_a[] = {0, 1.5, 0, 2};
  EXPECT_TRUE(e.Contains(ConvexPolyhedron::Point(inside)));
  EXPECT_FALSE(e.Contains(ConvexPolyhedron::Point(wrong_b)));
  EXPECT_FALSE(e.Contains(ConvexPolyhedron::Point(wrong_a)));
  const auto bounds = e.Bounds();
  EXPECT_EQ(bounds[0].first, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(bounds[1], std::make_pair(0.0, 2.0));
  EXPECT_EQ(bounds[3], std::make_pair(1.0, 1.0));
  const std::vector<int> twice = {1, 1};
  const std::vector<int> short_map = {1};
  const std::vector<int> outside = {0, 4};
  EXPECT_THROW(p.Embedded(4, twice), std::invalid_argument);
  EXPECT_THROW(p.Embedded(4, short_map), std::invalid_argument);
  EXPECT_THROW(p.Embedded(4, outside), std::invalid_argument);
  EXPECT_THROW(p.Embedded(1, to), std::invalid_argument);
}

TEST(ConvexPolyhedron, IntersectsAHalfSpaceExactlyAtTheBoundary) {
  // The box [0, 1]^2 against x + y REL 2, which touches it at its corner (1, 1) only.
  const ConvexPolyhedron box = Rectangle(0, 1, 0, 1);
  const auto half = [](Kind kind, double b) { return Plane({{{-1, -1}, b, kind}}); };
  EXPECT_TRUE(box.Intersects(half(Kind::kLessEqual, 2)));               // x + y >= 2: the corner
  EXPECT_FALSE(box.Intersects(half(Kind::kLess, 2)));                   // x + y > 2
  EXPECT_TRUE(box.Intersects(half(Kind::kLess, 1.5)));                  // x + y > 1.5
  EXPECT_FALSE(box.Intersects(half(Kind::kLessEqual, 2.5)));            // x + y >= 2.5
  EXPECT_TRUE(box.Intersects(Plane({{{1, 1}, -2, Kind::kEqual}})));     // x + y == 2
  EXPECT_FALSE(box.Intersects(Plane({{{1, 1}, -2.5, Kind::kEqual}})));  // x + y == 2.5
  EXPECT_FALSE(box.Intersects(Plane({{{1, 1}, 0.5, Kind::kEqual}})));   // x + y == -0.5
  // Either order; an unbounded set; the empty set.
  EXPECT_FALSE(half(Kind::kLess, 2).Intersects(box));
  const ConvexPolyhedron quadrant = Plane({{{-1, 0}, 5, Kind::kLessEqual}});  // x >= 5
  EXPECT_TRUE(quadrant.Intersects(half(Kind::kLess, 2)));
  EXPECT_FALSE(quadrant.Intersects(Plane({{{1, 0}, -4, Kind::kLess}})));  // x < 4
  EXPECT_FALSE(ConvexPolyhedron::Empty(2).Intersects(half(Kind::kLessEqual, 0)));
  EXPECT_FALSE(box.Intersects(ConvexPolyhedron::Empty(2)));
  EXPECT_THROW((void)box.Intersects(ConvexPolyhedron::Universe(3)), std::invalid_argument);
}

// Intersects (which, with a closed set, tests the other's constraints against its generators
// and the one left by the range of its expression) against the intersection made and tested
// for emptiness, and against grid points in both, on random closed sets and random bad parts:
// one half-space (strict, non-strict or an equality), alone or within a box, closed or not.
TEST(ConvexPolyhedron, IntersectsAgreesWithTheIntersectionAndWithPoints) {
  std::mt19937_64 rng(20261130);
  const auto number = [&rng](int lo, int hi) {  // an integer in [lo, hi], halved
    return static_cast<double>(lo + static_cast<int>(rng() % static_cast<unsigned>(hi - lo + 1))) /
           2.0;
  };
  const Kind kinds[] = {Kind::kLess, Kind::kLessEqual, Kind::kEqual};
  int met = 0, missed = 0;
  for (int round = 0; round < 300; ++round) {
    const double x0 = number(-8, 4), y0 = number(-8, 4);
    ConvexPolyhedron state = Rectangle(x0, x0 + number(0, 8), y0, y0 + number(0, 8));
    state.AddConstraint({{number(-4, 4), number(-4, 4)}, number(-8, 8), Kind::kLessEqual});
    ConvexPolyhedron bad = ConvexPolyhedron::Universe(2);
    if (rng() % 2 == 0)
      bad = Rectangle(number(-12, 0), number(0, 12), number(-12, 0), number(0, 12));
    bad.AddConstraint({{number(-4, 4), number(-4, 4)}, number(-8, 8), kinds[rng() % 3]});
    ConvexPolyhedron meet = state;
    meet.Intersect(bad);
    const bool expected = !meet.IsEmpty();
    EXPECT_EQ(state.Intersects(bad), expected) << round;
    EXPECT_EQ(bad.Intersects(state), expected) << round;
    for (double x = -10; x <= 10; x += 0.5) {
      for (double y = -10; y <= 10; y += 0.5) {
        if (Holds(state, x, y) && Holds(bad, x, y)) {
          EXPECT_TRUE(expected) << round << ": (" << x << ", " << y << ") lies in both";
        }
      }
    }
    (expected ? met : missed) += 1;
  }
  EXPECT_GT(met, 50);
  EXPECT_GT(missed, 50);
}

// IntersectsEach by hand, where a relation test in integers could go wrong: a strict bad
// constraint that the state only touches, and bounds that a ray of the state passes.
TEST(ConvexPolyhedron, IntersectsEachAtTheBoundaryAndAlongRays) {
  // The unit square and {x > 0, y - x >= 1}: x > 0 holds on part of the square only, and
  // y - x >= 1 only at (0, 1), where x > 0 fails: disjoint.
  const ConvexPolyhedron square = Rectangle(0, 1, 0, 1);
  const ConvexPolyhedron corner =
      Plane({{{-1, 0}, 0, Kind::kLess}, {{1, -1}, 1, Kind::kLessEqual}});
  // {x > 1}: the square touches it only on its closure: disjoint. {x >= 1}: met.
  const ConvexPolyhedron right = Plane({{{-1, 0}, 1, Kind::kLess}});
  const ConvexPolyhedron right_closed = Plane({{{-1, 0}, 1, Kind::kLessEqual}});
  const std::vector<const ConvexPolyhedron*> square_parts = {&corner, &right, &right_closed};
  EXPECT_EQ(square.IntersectsEach(square_parts), (std::vector<bool>{false, false, true}));
  // The half-line {x >= 1, y = 0}: a point and a ray. It meets x = 2 and x >= 2 further on,
  // misses x = 0 and x <= 0, and lies in x >= 0 and y = 0.
  const ConvexPolyhedron half_line =
      Plane({{{-1, 0}, 1, Kind::kLessEqual}, {{0, 1}, 0, Kind::kEqual}});
  const ConvexPolyhedron at_two = Plane({{{1, 0}, -2, Kind::kEqual}});
  const ConvexPolyhedron past_two = Plane({{{-1, 0}, 2, Kind::kLessEqual}});
  const ConvexPolyhedron at_zero = Plane({{{1, 0}, 0, Kind::kEqual}});
  const ConvexPolyhedron below_zero = Plane({{{1, 0}, 0, Kind::kLessEqual}});
  const ConvexPolyhedron on_axis =
      Plane({{{-1, 0}, 0, Kind::kLessEqual}, {{0, 1}, 0, Kind::kEqual}});
  const std::vector<const ConvexPolyhedron*> line_parts = {&at_two, &past_two, &at_zero,
                                                           &below_zero, &on_axis};
  EXPECT_EQ(half_line.IntersectsEach(line_parts),
            (std::vector<bool>{true, true, false, false, true}));
  // The line y = 1 (a line generator): it meets y = 1 and x >= 5 together, and misses y = 0.
  const ConvexPolyhedron line = Plane({{{0, 1}, -1, Kind::kEqual}});
  const ConvexPolyhedron far = Plane({{{-1, 0}, 5, Kind::kLessEqual}, {{0, 1}, -1, Kind::kEqual}});
  const ConvexPolyhedron floor = Plane({{{0, 1}, 0, Kind::kEqual}});
  const std::vector<const ConvexPolyhedron*> parts = {&far, &floor};
  EXPECT_EQ(line.IntersectsEach(parts), (std::vector<bool>{true, false}));
}

// IntersectsEach (the relation tests in machine integers) against the intersection built and
// tested for emptiness, on random sets in 3 dimensions: bounded or with rays and lines (fewer
// constraints than dimensions), closed or with a strict constraint, with bad parts of 1 to 3
// constraints of each kind, and some coefficients past 2^58 (the exact relation test instead).
TEST(ConvexPolyhedron, IntersectsEachAgreesWithTheIntersection) {
  std::mt19937_64 rng(20261201);
  const auto number = [&rng](int lo, int hi) {  // an integer in [lo, hi], divided by 3
    return static_cast<double>(lo + static_cast<int>(rng() % static_cast<unsigned>(hi - lo + 1))) /
           3.0;
  };
  const auto constraint = [&](Kind kind) {
    LinearConstraint c{{number(-6, 6), number(-6, 6), number(-6, 6)}, number(-12, 12), kind};
    if (rng() % 8 == 0) c.a[rng() % 3] *= 1e19;  // past 2^58
    return c;
  };
  const Kind kinds[] = {Kind::kLess, Kind::kLessEqual, Kind::kEqual};
  int met = 0, missed = 0;
  for (int round = 0; round < 300; ++round) {
    ConvexPolyhedron state = ConvexPolyhedron::Universe(3);
    const int n = 1 + static_cast<int>(rng() % 5);
    for (int k = 0; k < n; ++k) {
      state.AddConstraint(constraint(rng() % 6 == 0 ? Kind::kLess : Kind::kLessEqual));
    }
    std::vector<ConvexPolyhedron> bad;
    for (int part = 0; part < 4; ++part) {
      bad.push_back(ConvexPolyhedron::Universe(3));
      const int m = 1 + static_cast<int>(rng() % 3);
      for (int k = 0; k < m; ++k) bad.back().AddConstraint(constraint(kinds[rng() % 3]));
    }
    std::vector<const ConvexPolyhedron*> parts;
    for (const ConvexPolyhedron& b : bad) parts.push_back(&b);
    const std::vector<bool> meets = state.IntersectsEach(parts);
    ASSERT_EQ(meets.size(), bad.size());
    for (std::size_t k = 0; k < bad.size(); ++k) {
      ConvexPolyhedron both = state;
      both.Intersect(bad[k]);
      EXPECT_EQ(meets[k], !both.IsEmpty()) << round << " part " << k;
      (meets[k] ? met : missed) += 1;
    }
  }
  EXPECT_GT(met, 200);
  EXPECT_GT(missed, 200);
}

// Bounds (one pass over the generators) against the supremum of x and of -x and of y and -y
// (PPL's optimisation), on random sets: bounded or not, closed or with a strict constraint,
// some with a coefficient past 2^58 (Bounds' comparisons in GMP's integers, not 128 bits).
TEST(ConvexPolyhedron, BoundsAgreeWithTheSupremaPerDimension) {
  std::mt19937_64 rng(20261131);
  const auto number = [&rng](int lo, int hi) {  // an integer in [lo, hi], divided by 3
    return static_cast<double>(lo + static_cast<int>(rng() % static_cast<unsigned>(hi - lo + 1))) /
           3.0;
  };
  const Kind kinds[] = {Kind::kLess, Kind::kLessEqual};
  int unbounded = 0;
  for (int round = 0; round < 200; ++round) {
    ConvexPolyhedron p = ConvexPolyhedron::Universe(2);
    for (int k = 0; k < 3; ++k) {
      LinearConstraint c{{number(-6, 6), number(-6, 6)}, number(-12, 12), kinds[rng() % 2]};
      if (rng() % 6 == 0) c.a[rng() % 2] += 1e18;
      p.AddConstraint(c);
    }
    if (rng() % 2 == 0) p.Intersect(Rectangle(-5, 5, -5, 5));
    const auto bounds = p.Bounds();
    if (p.IsEmpty()) {
      EXPECT_EQ(bounds[0], std::make_pair(double{INFINITY}, double{-INFINITY})) << round;
      continue;
    }
    for (int i = 0; i < 2; ++i) {
      std::vector<double> up(2, 0.0), down(2, 0.0);
      up[static_cast<size_t>(i)] = 1.0;
      down[static_cast<size_t>(i)] = -1.0;
      const std::optional<double> sup = p.Supremum(up), neg_inf = p.Supremum(down);
      EXPECT_EQ(bounds[static_cast<size_t>(i)].second, sup ? *sup : INFINITY) << round;
      EXPECT_EQ(bounds[static_cast<size_t>(i)].first, neg_inf ? -*neg_inf : -INFINITY) << round;
      unbounded += sup ? 0 : 1;
    }
  }
  EXPECT_GT(unbounded, 10);
}

TEST(ConvexPolyhedron, ConstraintHullKeepsTheConstraintsEachSetSatisfies) {
  // Two boxes side by side: every constraint that survives is a side of their hull.
  ConvexPolyhedron boxes = Rectangle(0, 1, 0, 1);
  boxes.ConstraintHull(Rectangle(2, 3, 0, 1));
  EXPECT_TRUE(SameSet(boxes, Rectangle(0, 3, 0, 1)));
  // The triangle {x, y >= 0, x + y <= 1} and the segment y = 0, 2 <= x <= 3: x >= 0 and y >= 0
  // hold on both (y >= 0 also as half of the segment's equality), x <= 3 holds on the triangle;
  // x + y <= 1, x >= 2 and y <= 0 each fail on one. So {x >= 0, y >= 0, x <= 3}: it contains
  // (0, 5), which their convex hull does not.
  ConvexPolyhedron t = Plane({{{-1, 0}, 0, Kind::kLessEqual},
                              {{0, -1}, 0, Kind::kLessEqual},
                              {{1, 1}, -1, Kind::kLessEqual}});
  const ConvexPolyhedron segment = Plane(
      {{{0, 1}, 0, Kind::kEqual}, {{-1, 0}, 2, Kind::kLessEqual}, {{1, 0}, -3, Kind::kLessEqual}});
  ConvexPolyhedron convex = t;
  convex.Hull(segment);
  t.ConstraintHull(segment);
  EXPECT_TRUE(SameSet(t, Plane({{{-1, 0}, 0, Kind::kLessEqual},
                                {{0, -1}, 0, Kind::kLessEqual},
                                {{1, 0}, -3, Kind::kLessEqual}})));
  EXPECT_TRUE(t.Contains(convex));
  EXPECT_TRUE(Holds(t, 0, 5));
  EXPECT_FALSE(Holds(convex, 0, 5));
  // The empty set changes nothing; from the empty set, the other set.
  ConvexPolyhedron box = Rectangle(0, 1, 0, 1);
  box.ConstraintHull(ConvexPolyhedron::Empty(2));
  EXPECT_TRUE(SameSet(box, Rectangle(0, 1, 0, 1)));
  ConvexPolyhedron empty = ConvexPolyhedron::Empty(2);
  empty.ConstraintHull(Rectangle(0, 1, 0, 1));
  EXPECT_TRUE(SameSet(empty, Rectangle(0, 1, 0, 1)));
}

TEST(ConvexPolyhedron, LargestCoefficientBitsMeasuresTheIntegerConstraints) {
  // x <= 1/3 is kept as -3x + 1 >= 0 (2 bits); x <= 1/1024 as -1024x + 1 >= 0 (11 bits); x = 5
  // as x - 5 == 0 (3 bits).
  ConvexPolyhedron third = ConvexPolyhedron::Universe(1);
  third.AddConstraint({{3}, -1, Kind::kLessEqual});
  EXPECT_EQ(third.LargestCoefficientBits(), 2u);
  ConvexPolyhedron small = ConvexPolyhedron::Universe(1);
  small.AddConstraint({{1}, -1.0 / 1024, Kind::kLessEqual});
  EXPECT_EQ(small.LargestCoefficientBits(), 11u);
  EXPECT_EQ(ConvexPolyhedron::Point(std::vector<double>{5}).LargestCoefficientBits(), 3u);
}

// The same set made a closed polyhedron (non-strict constraints only) and a not necessarily
// closed one (the same constraints and a strict one that cuts nothing: x < 100, all sets here lie
// in [-10, 10]^2) gives the same results under every operation, in either order of operands:
// the kind (convex_polyhedron.h) changes the cost only. Random sets of a box and a diagonal cut,
// rates and resets; results compared as sets, by their bounds and on a grid of points.
TEST(ConvexPolyhedron, ClosedAndNotNecessarilyClosedGiveTheSameSets) {
  std::mt19937_64 rng(20261129);
  const auto number = [&rng](int lo, int hi) {  // an integer in [lo, hi], halved
    return static_cast<double>(lo + static_cast<int>(rng() % static_cast<unsigned>(hi - lo + 1))) /
           2.0;
  };
  const auto random_set = [&]() {
    const double x0 = number(-8, 4), y0 = number(-8, 4);
    ConvexPolyhedron p = Rectangle(x0, x0 + number(0, 8), y0, y0 + number(0, 8));
    p.AddConstraint({{number(-4, 4), number(-4, 4)}, number(-8, 8), Kind::kLessEqual});
    return p;
  };
  const auto as_nnc = [](ConvexPolyhedron p) {
    p.AddConstraint({{1, 0}, -100, Kind::kLess});  // x < 100: cuts nothing here
    return p;
  };
  const auto same = [](const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
    if (!SameSet(a, b) || a.Bounds() != b.Bounds() || a.IsEmpty() != b.IsEmpty()) return false;
    for (double x = -10; x <= 10; x += 0.75) {
      for (double y = -10; y <= 10; y += 0.75) {
        if (Holds(a, x, y) != Holds(b, x, y)) return false;
      }
    }
    return true;
  };
  const std::vector<std::pair<int, AffineMap>> swap = {{0, {{0, 1}, 0.5}}, {1, {{1, 0}, 0}}};
  const std::vector<std::pair<int, AffineMap>> shift = {{0, {{1, 0}, 1.5}}};
  for (int round = 0; round < 60; ++round) {
    const ConvexPolyhedron p = random_set(), q = random_set();
    ConvexPolyhedron rates = random_set();
    const ConvexPolyhedron pn = as_nnc(p), qn = as_nnc(q);
    ASSERT_TRUE(same(p, pn)) << round;
    for (const ConvexPolyhedron* a : {&p, &pn}) {
      for (const ConvexPolyhedron* b : {&q, &qn}) {
        EXPECT_EQ(a->Contains(*b), p.Contains(q)) << round;
        EXPECT_EQ(a->Intersects(*b), p.Intersects(q)) << round;
        ConvexPolyhedron meet = *a, hull = *a, elapse = *a, back = *a;
        meet.Intersect(*b);
        ConvexPolyhedron expected_meet = p;
        expected_meet.Intersect(q);
        EXPECT_TRUE(same(meet, expected_meet)) << round;
        hull.Hull(*b);
        ConvexPolyhedron expected_hull = p;
        expected_hull.Hull(q);
        EXPECT_TRUE(same(hull, expected_hull)) << round;
        elapse.TimeElapse(*b);
        back.TimeElapseBackward(*b);
        ConvexPolyhedron expected_elapse = p, expected_back = p;
        expected_elapse.TimeElapse(q);
        expected_back.TimeElapseBackward(q);
        EXPECT_TRUE(SameSet(elapse, expected_elapse)) << round;
        EXPECT_TRUE(SameSet(back, expected_back)) << round;
      }
    }
    ConvexPolyhedron a = p, b = pn;
    a.Assign(swap);
    b.Assign(swap);
    EXPECT_TRUE(same(a, b)) << round;
    a.AssignPreimage(shift);
    b.AssignPreimage(shift);
    EXPECT_TRUE(same(a, b)) << round;
    a.Unconstrain(1);
    b.Unconstrain(1);
    EXPECT_TRUE(SameSet(a, b)) << round;
    const std::vector<double> objective = {1, -2};
    bool attained_a = false, attained_b = false;
    EXPECT_EQ(p.Supremum(objective, &attained_a), pn.Supremum(objective, &attained_b)) << round;
    EXPECT_EQ(attained_a, attained_b) << round;
    const std::vector<int> to = {2, 0};
    EXPECT_TRUE(SameSet(p.Embedded(3, to), pn.Embedded(3, to))) << round;
    if (!p.IsEmpty()) {
      EXPECT_TRUE(p.Contains(pn.CentralPoint())) << round;
    }
  }
}

}  // namespace
}  // namespace hybrid
