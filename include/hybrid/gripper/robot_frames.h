#pragma once

#include <Eigen/Core>
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hybrid::gripper {

/// A revolute joint of the ROS description of the gripper (ros-industrial/robotiq,
/// robotiq_3f_gripper_visualization/cfg/robotiq-3f-gripper_articulated_macro.xacro and
/// robotiq-3f-gripper_finger_articulated_macro.xacro): its name and its limits in radians.
struct RosJoint {
  std::string_view name;
  double lower = 0.0;
  double upper = 0.0;
};

/// The eleven moving joints in the order of that repository's joint-state publisher:
/// palm_finger_1_joint, finger_1_joint_1..3, palm_finger_2_joint, finger_2_joint_1..3,
/// finger_middle_joint_1..3 (docs/robot_frames.md lists each with its source).
std::span<const RosJoint> RosJoints();

/// A sensor_msgs/JointState-like record: joint names and positions in radians, in RosJoints()'
/// order. `position` is within the description's limits (what the model gives, clamped into
/// them); `model_position` is the model's value in the same frame before clamping, and
/// `clamped` names the joints where the two differ.
struct JointState {
  std::vector<std::string> name;
  std::vector<double> position;
  std::vector<double> model_position;
  std::vector<std::string> clamped;
};

/// The hand's configuration in the ROS description's joints (docs/robot_frames.md):
/// `theta[f]` the report's joint angles (theta1, theta2, theta3, degrees, theta3 relative to
/// link 2) of fingers A, B, C; `spread_angle` the model's spread angle phi in degrees (positive:
/// B and C turned towards the centre plane). Finger A is finger_middle (it does not turn on the
/// palm), B is finger_1, C is finger_2; finger_k_joint_i = theta_i in radians (the publisher's
/// convention: no offset, same sign); palm_finger_1_joint = -phi and palm_finger_2_joint = +phi
/// in radians (the publisher's sign: positive palm_finger_1_joint spreads the fingers apart).
/// Values outside the limits are clamped into them (JointState::clamped). Throws
/// std::invalid_argument for a non-finite angle.
JointState RosJointState(const std::array<Eigen::Vector3d, 3>& theta, double spread_angle);

/// The inverse of RosJointState's mapping (before clamping): the report's angles of fingers
/// A, B, C (degrees) and the spread angle (degrees) from joint `names` and `positions`
/// (radians, any order, other joints ignored). palm_finger_2_joint is not read (it mirrors
/// palm_finger_1_joint). Throws std::invalid_argument naming a missing joint or a size mismatch.
std::pair<std::array<Eigen::Vector3d, 3>, double> ReportAngles(std::span<const std::string> names,
                                                               std::span<const double> positions);

}  // namespace hybrid::gripper
