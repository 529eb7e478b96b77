#include "hybrid/gripper/finger_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hybrid::gripper {

FingerGeometry::FingerGeometry(const FingerLengths& lengths, const FingerPlacement& placement)
    : lengths_(lengths), placement_(placement) {
  if (!std::isfinite(placement.origin_x) || !std::isfinite(placement.x_scale) ||
      placement.x_scale == 0.0) {
    throw std::invalid_argument("the finger's placement must be finite with x_scale != 0");
  }
  for (double l : {lengths.proximal, lengths.medial, lengths.distal}) {
    if (!(l > 0.0) || !std::isfinite(l)) {
      throw std::invalid_argument("the finger's link lengths must be positive and finite");
    }
  }
  palm_y_ = Points(Eigen::Vector3d(70.0, 90.0, -55.0))[3].y();
}

std::array<Eigen::Vector2d, 4> FingerGeometry::Points(const Eigen::Vector3d& theta) const {
  auto p = LocalPoints(theta);
  for (auto& q : p) q = Place(q);
  return p;
}

std::array<Eigen::Vector2d, 4> FingerGeometry::LocalPoints(const Eigen::Vector3d& theta) const {
  constexpr double kRad = std::numbers::pi / 180.0;
  const double phi1 = theta[0] * kRad;
  const double phi2 = phi1 + theta[1] * kRad;
  const double phi3 = phi2 + theta[2] * kRad;
  std::array<Eigen::Vector2d, 4> p;
  p[0] = Eigen::Vector2d::Zero();
  p[1] = p[0] + lengths_.proximal * Eigen::Vector2d(std::sin(phi1), std::cos(phi1));
  p[2] = p[1] + lengths_.medial * Eigen::Vector2d(std::sin(phi2), std::cos(phi2));
  p[3] = p[2] + lengths_.distal * Eigen::Vector2d(std::sin(phi3), std::cos(phi3));
  return p;
}

std::array<Segment2, 3> FingerGeometry::Links(const Eigen::Vector3d& theta) const {
  const auto p = Points(theta);
  return {Segment2{p[0], p[1]}, Segment2{p[1], p[2]}, Segment2{p[2], p[3]}};
}

std::array<std::array<Expression, 2>, 4> FingerGeometry::LocalPointExpressions(
    const std::array<Expression, 3>& theta) const {
  using E = Expression;
  const E to_rad = E::Constant(std::numbers::pi / 180.0);
  const std::array<E, 3> phi = {theta[0] * to_rad, (theta[0] + theta[1]) * to_rad,
                                (theta[0] + theta[1] + theta[2]) * to_rad};
  const std::array<double, 3> length = {lengths_.proximal, lengths_.medial, lengths_.distal};
  std::array<std::array<E, 2>, 4> p;
  p[0] = {E::Constant(0.0), E::Constant(0.0)};
  for (int k = 0; k < 3; ++k) {
    const E x = E::Constant(length[k]) * E::Unary(Op::kSin, phi[k]);
    const E y = E::Constant(length[k]) * E::Unary(Op::kCos, phi[k]);
    p[k + 1] = {k == 0 ? x : p[k][0] + x, k == 0 ? y : p[k][1] + y};
  }
  return p;
}

std::array<Segment2, 3> FingerGeometry::ContactSegments(const Eigen::Vector3d& theta) const {
  const auto p = LocalPoints(theta);
  std::array<Segment2, 3> links;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector2d a = p[k];
    if (k > 0) a += kJointMargin / (p[k + 1] - p[k]).norm() * (p[k + 1] - p[k]);
    links[k] = Segment2{Place(a), Place(p[k + 1])};
  }
  return links;
}

std::array<double, 3> FingerGeometry::LinkMotionBounds(const Eigen::Vector3d& variation) const {
  const double scale = std::max(1.0, std::abs(placement_.x_scale)) * std::numbers::pi / 180.0;
  const std::array<double, 3> length = {lengths_.proximal, lengths_.medial, lengths_.distal};
  std::array<double, 3> bounds;
  double reach = 0.0, turn = 0.0;
  for (int k = 0; k < 3; ++k) {
    reach += length[k];
    turn += std::abs(variation[k]);
    bounds[k] = scale * reach * turn;
  }
  return bounds;
}

}  // namespace hybrid::gripper
