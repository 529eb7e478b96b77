#pragma once

#include <Eigen/Core>
#include <array>

#include "hybrid/automaton/expression.h"

namespace hybrid::gripper {

/// A straight segment [a, b] in the finger plane (metres).
struct Segment2 {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
};

/// Link lengths of the planar finger (metres), from docs/gripper_facts.md: proximal
/// (joint 1 to joint 2), medial (joint 2 to joint 3) and distal (joint 3 to the fingertip).
struct FingerLengths {
  double proximal = 0.05715;
  double medial = 0.03894;
  double distal = 0.038;
};

/// Where a finger stands in the plane its objects are described in: a point at finger coordinates
/// (x, y) is at (origin_x + x_scale * x, y). The identity (the default) is the finger's own frame.
/// In the hand (include/hybrid/gripper/hand.h) objects are described in the palm's x-y plane and
/// extruded along z; a finger whose plane is turned by the spread angle phi about the vertical axis
/// sees them through x_scale = -cos(phi) (facing -x): contact with an extruded object happens
/// exactly when the link's projection onto the x-y plane touches the object's section.
struct FingerPlacement {
  double origin_x = 0.0;
  double x_scale = 1.0;
};

/// Planar forward kinematics of one finger in its own frame (or placed, see FingerPlacement).
///
/// Frame: origin at joint 1; +y along the open finger (away from the palm), +x the closing
/// direction (towards the opposite finger). Joint angles are the report's relative angles in
/// degrees; link k points along the absolute angle phi_k = theta1 + ... + thetak, measured from
/// +y towards +x: link k's direction is (sin phi_k, cos phi_k). So the open finger (all 0) is
/// straight up, and in phase 1 (theta3 = -theta1) link 3 stays vertical, as the report says.
///
/// The palm surface is the line y = palm_y() (below joint 1): decision G1 of
/// docs/finger_model.md places it where the fingertip is at the report's self-collision
/// configuration (theta1_max, theta2_max, theta3_min) = (70, 90, -55): y = -0.0269 m with the
/// default lengths.
class FingerGeometry {
 public:
  /// Throws std::invalid_argument (a message for the user) unless all lengths are positive and
  /// finite and the placement is finite with x_scale != 0.
  explicit FingerGeometry(const FingerLengths& lengths = {}, const FingerPlacement& placement = {});

  /// Joint 1, joint 2, joint 3 and the fingertip for joint angles `theta` (degrees), placed.
  std::array<Eigen::Vector2d, 4> Points(const Eigen::Vector3d& theta) const;
  /// Links 1, 2 and 3 as segments between consecutive Points.
  std::array<Segment2, 3> Links(const Eigen::Vector3d& theta) const;
  /// The parts of the links that make contact (decision G2): link 1 whole; links 2 and 3 from
  /// kJointMargin after their joint. A joint belongs to the link it ends: an object touching
  /// the knuckle at joint 3 blocks link 2, and link 3, rotating about that joint, is blocked
  /// only when its own body reaches the object. (With whole links, link 3 would touch the
  /// object at the knuckle for a whole interval of g: a contact with no crossing.)
  std::array<Segment2, 3> ContactSegments(const Eigen::Vector3d& theta) const;
  static constexpr double kJointMargin = 0.002;
  /// Points() in the finger's own frame (placement ignored) as expressions of the joint-angle
  /// expressions `theta` (degrees): {x, y} of joint 1, joint 2, joint 3 and the fingertip.
  std::array<std::array<Expression, 2>, 4> LocalPointExpressions(
      const std::array<Expression, 3>& theta) const;
  /// How far any point of each link (its contact segment included) can move, in the placed
  /// frame, while the joints turn by at most `variation` degrees each (FingerClosedForm::
  /// VariationBound): a point of link k is joint 1 plus sum_{j<k} L_j u(phi_j) plus s u(phi_k)
  /// with phi_j = theta1 + ... + thetaj and |u(p) - u(q)| <= |p - q|, so it moves at most
  /// (L_1 + ... + L_k) (|dtheta_1| + ... + |dtheta_k|) (radians), times max(1, |x_scale|).
  std::array<double, 3> LinkMotionBounds(const Eigen::Vector3d& variation) const;
  /// Height of the palm surface (negative: below joint 1).
  double palm_y() const { return palm_y_; }
  const FingerLengths& lengths() const { return lengths_; }
  const FingerPlacement& placement() const { return placement_; }

 private:
  std::array<Eigen::Vector2d, 4> LocalPoints(const Eigen::Vector3d& theta) const;
  Eigen::Vector2d Place(const Eigen::Vector2d& local) const {
    return {placement_.origin_x + placement_.x_scale * local.x(), local.y()};
  }
  FingerLengths lengths_;
  FingerPlacement placement_;
  double palm_y_;
};

}  // namespace hybrid::gripper
