#pragma once

#include <Eigen/Core>

namespace hybrid::gripper {

/// The constants of one Robotiq finger shared by the closed form, the geometry and the generated
/// automaton (`spec/finger.ha`): joint ranges in degrees (Klamp't limits, see
/// `../shared/robotiq/kinematics.md`), the motor range in counts, and the report's transmission
/// rates m1 = theta1_max / 140 and m2 = theta2_max / 100 (degrees per count).
struct FingerParameters {
  Eigen::Vector3d theta_min{0.0, 0.0, -55.0};
  Eigen::Vector3d theta_max{70.0, 90.0, 43.0};
  /// Fully closed motor position; the motor range is [0, motor_max].
  double motor_max = 255.0;

  double m1() const { return theta_max[0] / 140.0; }
  double m2() const { return theta_max[1] / 100.0; }
  /// The distal span c = theta3_max - theta3_min of section 4.2.
  double c() const { return theta_max[2] - theta_min[2]; }
};

}  // namespace hybrid::gripper
