// Planar forward kinematics of the finger (include/hybrid/gripper/finger_geometry.h).
#include "hybrid/gripper/finger_geometry.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>

#include "hybrid/automaton/compiled_expression.h"

namespace hybrid::gripper {
namespace {

TEST(FingerGeometryTest, ForwardKinematics) {
  const FingerGeometry f;
  const auto open = f.Points(Eigen::Vector3d::Zero());
  EXPECT_NEAR(open[3].y(), 0.05715 + 0.03894 + 0.038, 1e-15);
  EXPECT_NEAR(open[3].x(), 0.0, 1e-15);
  // Phase 1 keeps link 3 vertical.
  const auto p = f.Points(Eigen::Vector3d(30, 0, -30));
  EXPECT_NEAR(p[3].x(), p[2].x(), 1e-15);
  // Decision G1: the palm is where the fingertip is at (70, 90, -55).
  EXPECT_NEAR(f.palm_y(), -0.0269, 5e-5);
  EXPECT_EQ(f.palm_y(), f.Points(Eigen::Vector3d(70, 90, -55))[3].y());
}

// The expressions used in guards evaluate to Points() (a law over random joint angles).
RC_GTEST_PROP(FingerGeometryProperty, PointExpressionsEqualPoints, ()) {
  const Eigen::Vector3d theta(*rc::gen::inRange(0, 7001) / 100.0,
                              *rc::gen::inRange(0, 9001) / 100.0,
                              *rc::gen::inRange(-5500, 4301) / 100.0);
  const FingerGeometry f;
  const std::array<Expression, 3> symbols = {
      Expression::Symbol("t1", 0), Expression::Symbol("t2", 1), Expression::Symbol("t3", 2)};
  const auto expressions = f.LocalPointExpressions(symbols);
  const auto points = f.Points(theta);
  const std::vector<double> env = {theta[0], theta[1], theta[2]};
  for (int k = 0; k < 4; ++k) {
    for (int axis = 0; axis < 2; ++axis) {
      RC_ASSERT(std::abs(CompiledExpression(expressions[k][axis])(env) - points[k][axis]) <= 1e-15);
    }
  }
}

// Contact segments: link 1 whole, links 2 and 3 shortened by kJointMargin at their joint; a
// placement maps x to origin_x + x_scale x.
TEST(FingerGeometryTest, ContactSegmentsAndPlacement) {
  const Eigen::Vector3d theta(20, 30, -10);
  const FingerGeometry f;
  const auto links = f.Links(theta);
  const auto contact = f.ContactSegments(theta);
  EXPECT_EQ(contact[0].a, links[0].a);
  for (int k = 1; k < 3; ++k) {
    EXPECT_NEAR((contact[k].a - links[k].a).norm(), FingerGeometry::kJointMargin, 1e-15);
    EXPECT_EQ(contact[k].b, links[k].b);
  }
  const FingerGeometry placed({}, FingerPlacement{0.045, -0.5});
  const auto p = placed.Points(theta), q = f.Points(theta);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(p[k].x(), 0.045 - 0.5 * q[k].x(), 1e-15);
    EXPECT_EQ(p[k].y(), q[k].y());
  }
  EXPECT_THROW(FingerGeometry({}, FingerPlacement{0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(FingerGeometry(FingerLengths{0.05, -1, 0.03}), std::invalid_argument);
}

// LinkMotionBounds against the motion measured on sampled configurations: every link's contact
// segment ends (and so every point between them) stay within the bound of where they started
// when the joints turn by at most the given angles, in the placed frame too.
RC_GTEST_PROP(FingerGeometryMotion, LinkMotionBoundsHoldOnSampledTurns, ()) {
  const double scale = *rc::gen::element(1.0, -1.0, -0.8, 1.5);
  const FingerGeometry geometry(FingerLengths{}, FingerPlacement{0.01, scale});
  Eigen::Vector3d start, turn;
  for (int i = 0; i < 3; ++i) {
    start[i] = *rc::gen::inRange(-600, 900) / 10.0;
    turn[i] = *rc::gen::inRange(-300, 300) / 10.0;
  }
  const std::array<double, 3> bound = geometry.LinkMotionBounds(turn);
  const auto from = geometry.ContactSegments(start);
  for (int k = 0; k <= 50; ++k) {
    // Each joint turns monotonically by up to its variation (fractions of each at random).
    Eigen::Vector3d theta = start;
    for (int i = 0; i < 3; ++i) theta[i] += turn[i] * *rc::gen::inRange(0, 1001) / 1000.0;
    const auto to = geometry.ContactSegments(theta);
    for (int l = 0; l < 3; ++l) {
      RC_ASSERT((to[l].a - from[l].a).norm() <= bound[l] + 1e-12);
      RC_ASSERT((to[l].b - from[l].b).norm() <= bound[l] + 1e-12);
    }
  }
  // No turn, no motion; a turn of link 3's joint alone does not move links 1 and 2.
  EXPECT_EQ(geometry.LinkMotionBounds(Eigen::Vector3d::Zero())[2], 0.0);
  const auto distal = geometry.LinkMotionBounds(Eigen::Vector3d(0.0, 0.0, 5.0));
  RC_ASSERT(distal[0] == 0.0 && distal[1] == 0.0 && distal[2] > 0.0);
}

}  // namespace
}  // namespace hybrid::gripper
