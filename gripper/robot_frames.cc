#include "hybrid/gripper/robot_frames.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hybrid::gripper {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// The limits of the xacro files named in robot_frames.h (radians).
constexpr double kJoint1Lower = 0.0495, kJoint1Upper = 1.2218;
constexpr double kJoint2Lower = 0.0, kJoint2Upper = 1.5708;
constexpr double kJoint3Lower = -1.2217, kJoint3Upper = -0.0523;

constexpr std::array<RosJoint, 11> kJoints = {{
    {"palm_finger_1_joint", -0.1784, 0.192},
    {"finger_1_joint_1", kJoint1Lower, kJoint1Upper},
    {"finger_1_joint_2", kJoint2Lower, kJoint2Upper},
    {"finger_1_joint_3", kJoint3Lower, kJoint3Upper},
    {"palm_finger_2_joint", -0.192, 0.1784},
    {"finger_2_joint_1", kJoint1Lower, kJoint1Upper},
    {"finger_2_joint_2", kJoint2Lower, kJoint2Upper},
    {"finger_2_joint_3", kJoint3Lower, kJoint3Upper},
    {"finger_middle_joint_1", kJoint1Lower, kJoint1Upper},
    {"finger_middle_joint_2", kJoint2Lower, kJoint2Upper},
    {"finger_middle_joint_3", kJoint3Lower, kJoint3Upper},
}};

// Which model finger (0 = A, 1 = B, 2 = C) drives the finger joints starting at index k of
// kJoints (1: finger_1, 5: finger_2, 8: finger_middle).
constexpr std::array<std::pair<int, int>, 3> kFingerJoints = {{{1, 1}, {5, 2}, {8, 0}}};

}  // namespace

std::span<const RosJoint> RosJoints() { return kJoints; }

JointState RosJointState(const std::array<Eigen::Vector3d, 3>& theta, double spread_angle) {
  std::vector<double> model(kJoints.size());
  model[0] = -spread_angle * kRad;
  model[4] = spread_angle * kRad;
  for (const auto& [first, finger] : kFingerJoints) {
    for (int i = 0; i < 3; ++i) model[first + i] = theta[finger][i] * kRad;
  }
  JointState out;
  for (size_t k = 0; k < kJoints.size(); ++k) {
    if (!std::isfinite(model[k])) {
      throw std::invalid_argument("the angle of " + std::string(kJoints[k].name) +
                                  " is not finite");
    }
    out.name.emplace_back(kJoints[k].name);
    out.model_position.push_back(model[k]);
    out.position.push_back(std::clamp(model[k], kJoints[k].lower, kJoints[k].upper));
    if (out.position.back() != model[k]) out.clamped.emplace_back(kJoints[k].name);
  }
  return out;
}

std::pair<std::array<Eigen::Vector3d, 3>, double> ReportAngles(std::span<const std::string> names,
                                                               std::span<const double> positions) {
  if (names.size() != positions.size()) {
    throw std::invalid_argument("a joint state needs one position per name");
  }
  const auto value = [&](std::string_view joint) {
    const auto it = std::find(names.begin(), names.end(), joint);
    if (it == names.end()) {
      throw std::invalid_argument("the joint state has no joint '" + std::string(joint) + "'");
    }
    return positions[it - names.begin()] / kRad;
  };
  std::array<Eigen::Vector3d, 3> theta;
  for (const auto& [first, finger] : kFingerJoints) {
    for (int i = 0; i < 3; ++i) theta[finger][i] = value(kJoints[first + i].name);
  }
  return {theta, -value(kJoints[0].name)};
}

}  // namespace hybrid::gripper
