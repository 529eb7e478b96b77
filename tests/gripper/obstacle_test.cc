#include "hybrid/gripper/obstacle.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <vector>

#include "hybrid/automaton/compiled_expression.h"

namespace hybrid::gripper {
namespace {

TEST(ObstacleTest, ParsesCirclesAndSegments) {
  const Obstacle c = Obstacle::Parse("circle:0.05,0.08,0.01");
  EXPECT_TRUE(c.is_circle());
  EXPECT_EQ(c.a(), Eigen::Vector2d(0.05, 0.08));
  EXPECT_EQ(c.radius(), 0.01);
  EXPECT_EQ(Obstacle::Parse(c.ToString()), c);
  const Obstacle s = Obstacle::Parse("segment:0.04,0.0,0.04,0.1");
  EXPECT_FALSE(s.is_circle());
  EXPECT_EQ(s.radius(), Obstacle::kDefaultBarRadius);
  EXPECT_EQ(Obstacle::Parse("segment:0.04,0,0.04,0.1,0.002").radius(), 0.002);
  EXPECT_EQ(Obstacle::Parse(s.ToString()), s);
  // Signs and spaces around numbers.
  EXPECT_EQ(Obstacle::Parse("circle: +0.05, 0.08 ,0.01"), c);
  EXPECT_EQ(Obstacle::Parse("circle:-0.05,0.08,0.01").a(), Eigen::Vector2d(-0.05, 0.08));
}

TEST(ObstacleTest, MalformedDescriptionsNameTheColumn) {
  struct Case {
    const char* text;
    int column;
    const char* message;
  };
  for (const Case& c : {Case{"square:1,2,3", 1, "expected 'circle:X,Y,R'"},
                        Case{"circle", 1, "expected 'circle:X,Y,R'"},
                        Case{"circle:0.1,,0.2", 12, "expected a number"},
                        Case{"circle:0.1,abc,0.2", 12, "malformed number 'abc'"},
                        Case{"circle:0.1,0.2x,0.2", 15, "malformed number '0.2x'"},
                        Case{"circle:0.1,0.2", 15, "a circle takes 3 numbers"},
                        Case{"circle:0.1,0.2,0.3,0.4", 20, "a circle takes 3 numbers"},
                        Case{"circle:0.1,0.2,-1", 16, "radius must be > 0"},
                        Case{"circle:0.1,0.2,0", 16, "radius must be > 0"},
                        Case{"circle:1e999,0,1", 8, "out of the range of a double"},
                        Case{"circle:0,0,0.00005", 12, "radius must be at least 0.0001 m"},
                        Case{"segment:0,0,1", 14, "a segment takes 4 or 5 numbers"},
                        Case{"segment:0,0,1,1,0", 17, "radius must be > 0"},
                        Case{"circle:0.1,0.2,0.3,", 20, "expected a number"}}) {
    try {
      Obstacle::Parse(c.text);
      ADD_FAILURE() << c.text << " parsed";
    } catch (const ObstacleParseError& e) {
      EXPECT_EQ(e.column(), c.column) << c.text << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos)
          << c.text << ": " << e.what();
    }
  }
}

TEST(ObstacleTest, DistanceOfACircle) {
  const Obstacle c = Obstacle::Circle({0.0, 0.1}, 0.01);
  EXPECT_NEAR(c.Distance({{-1, 0}, {1, 0}}), 0.09, 1e-15);            // perpendicular foot inside
  EXPECT_NEAR(c.Distance({{0.03, 0.14}, {0.1, 0.14}}), 0.04, 1e-15);  // nearest at an end
  EXPECT_NEAR(c.Distance({{-1, 0.1}, {1, 0.1}}), -0.01, 1e-15);       // through the centre
}

TEST(ObstacleTest, DistanceOfABar) {
  const Obstacle b = Obstacle::Bar({0.0, 0.0}, {0.0, 1.0}, 0.01);
  EXPECT_NEAR(b.Distance({{0.5, 0.5}, {0.5, 0.7}}), 0.49, 1e-15);
  EXPECT_NEAR(b.Distance({{-1, 0.5}, {1, 0.5}}), -0.01, 1e-15);  // crossing the core
  EXPECT_NEAR(b.Distance({{0.1, 1.1}, {0.2, 1.2}}), std::sqrt(0.02) - 0.01, 1e-15);
}

// The guard expression equals the direct computation wherever the link does not cross the core
// (a law over random shapes and links).
RC_GTEST_PROP(ObstacleProperty, DistanceExpressionEqualsDistance, ()) {
  auto coordinate = [] { return *rc::gen::inRange(-1000, 1000) / 5000.0; };
  const double radius = *rc::gen::inRange(1, 200) / 10000.0;
  const bool circle = *rc::gen::arbitrary<bool>();
  const Eigen::Vector2d a(coordinate(), coordinate());
  const Obstacle o =
      circle ? Obstacle::Circle(a, radius) : Obstacle::Bar(a, {coordinate(), coordinate()}, radius);
  const Segment2 link{{coordinate(), coordinate()}, {coordinate(), coordinate()}};
  RC_PRE((link.b - link.a).norm() > 1e-6);
  const Segment2 core{o.a(), o.b()};
  RC_PRE(SegmentDistance(link, core) > 0.0 || circle);
  const Expression e =
      o.DistanceExpression(Expression::Symbol("ax", 0), Expression::Symbol("ay", 1),
                           Expression::Symbol("bx", 2), Expression::Symbol("by", 3));
  const std::vector<double> env = {link.a.x(), link.a.y(), link.b.x(), link.b.y()};
  RC_ASSERT(std::abs(CompiledExpression(e)(env) - o.Distance(link)) <= 1e-12);
}

}  // namespace
}  // namespace hybrid::gripper
