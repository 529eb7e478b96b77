// The report's angles in the ROS description's joints (include/hybrid/gripper/robot_frames.h).
#include "hybrid/gripper/robot_frames.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "hybrid/gripper/hand.h"
#include "hybrid/gripper/obstacle.h"

namespace hybrid::gripper {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// The limits as written in ros-industrial/robotiq's xacro files (radians), typed here from
// those files: robotiq-3f-gripper_finger_articulated_macro.xacro (joint_1..3) and
// robotiq-3f-gripper_articulated_macro.xacro (palm_finger_1/2_joint).
const std::map<std::string, std::pair<double, double>>& XacroLimits() {
  static const std::map<std::string, std::pair<double, double>> limits = [] {
    std::map<std::string, std::pair<double, double>> m = {
        {"palm_finger_1_joint", {-0.1784, 0.192}}, {"palm_finger_2_joint", {-0.192, 0.1784}}};
    for (const std::string finger : {"finger_1", "finger_2", "finger_middle"}) {
      m[finger + "_joint_1"] = {0.0495, 1.2218};
      m[finger + "_joint_2"] = {0.0, 1.5708};
      m[finger + "_joint_3"] = {-1.2217, -0.0523};
    }
    return m;
  }();
  return limits;
}

std::map<std::string, double> ByName(const std::vector<std::string>& names,
                                     const std::vector<double>& values) {
  std::map<std::string, double> out;
  for (size_t k = 0; k < names.size(); ++k) out[names[k]] = values[k];
  return out;
}

TEST(RobotFramesTest, JointsAndLimitsAreTheXacros) {
  ASSERT_EQ(RosJoints().size(), XacroLimits().size());
  for (const RosJoint& j : RosJoints()) {
    const auto it = XacroLimits().find(std::string(j.name));
    ASSERT_NE(it, XacroLimits().end()) << j.name;
    EXPECT_EQ(j.lower, it->second.first) << j.name;
    EXPECT_EQ(j.upper, it->second.second) << j.name;
  }
}

// A cylinder grasp in basic mode: the distal links end at theta3 = 43 degrees (0.75 rad), beyond
// the description's joint_3 limit (-0.0523 rad); the joint state stays within every limit, says
// which joints it clamped, and keeps the model's values.
TEST(RobotFramesTest, CylinderGraspIsWithinTheXacroLimits) {
  const Hand hand({Obstacle::Parse("circle:0,0.06,0.02")}, Hand::SpreadPosition(SpreadMode::kBasic),
                  {255.0, 255.0, 255.0});
  std::array<Eigen::Vector3d, 3> theta;
  for (int f = 0; f < 3; ++f) theta[f] = hand.At(f, 255.0).theta;
  ASSERT_NEAR(theta[0][2], 43.0, 1e-9);
  const JointState state = RosJointState(theta, hand.spread_angle());
  const auto position = ByName(state.name, state.position);
  for (const auto& [name, limits] : XacroLimits()) {
    ASSERT_TRUE(position.count(name)) << name;
    EXPECT_GE(position.at(name), limits.first) << name;
    EXPECT_LE(position.at(name), limits.second) << name;
  }
  const auto model = ByName(state.name, state.model_position);
  EXPECT_NEAR(model.at("finger_middle_joint_3"), 43.0 * kRad, 1e-12);
  EXPECT_EQ(position.at("finger_middle_joint_3"), -0.0523);
  const std::vector<std::string> clamped = {"finger_1_joint_3", "finger_2_joint_3",
                                            "finger_middle_joint_3"};
  EXPECT_EQ(state.clamped, clamped);
  EXPECT_NEAR(model.at("finger_middle_joint_1"), theta[0][0] * kRad, 1e-15);
  EXPECT_NEAR(model.at("palm_finger_1_joint"), -hand.spread_angle() * kRad, 1e-15);
  EXPECT_NEAR(model.at("palm_finger_2_joint"), hand.spread_angle() * kRad, 1e-15);
}

// The finger map: A drives finger_middle, B finger_1, C finger_2 (distinct angles per finger).
TEST(RobotFramesTest, FingerMap) {
  const std::array<Eigen::Vector3d, 3> theta = {
      Eigen::Vector3d(10, 20, -5), Eigen::Vector3d(30, 40, -15), Eigen::Vector3d(50, 60, -25)};
  const auto model =
      ByName(RosJointState(theta, 5.0).name, RosJointState(theta, 5.0).model_position);
  EXPECT_NEAR(model.at("finger_middle_joint_1"), 10 * kRad, 1e-15);
  EXPECT_NEAR(model.at("finger_1_joint_2"), 40 * kRad, 1e-15);
  EXPECT_NEAR(model.at("finger_2_joint_3"), -25 * kRad, 1e-15);
  EXPECT_TRUE(RosJointState(theta, 5.0).clamped.empty());
  EXPECT_THROW(RosJointState({Eigen::Vector3d(NAN, 0, 0), theta[1], theta[2]}, 0.0),
               std::invalid_argument);
}

// Round trip: the report's angles (any in the report's ranges) and the spread angle come back
// from the joint state's model positions, in any order of the joints.
RC_GTEST_PROP(RobotFramesProperty, RoundTrip, ()) {
  std::array<Eigen::Vector3d, 3> theta;
  for (auto& t : theta) {
    t = Eigen::Vector3d(*rc::gen::inRange(0, 7001) / 100.0, *rc::gen::inRange(0, 9001) / 100.0,
                        *rc::gen::inRange(-5500, 4301) / 100.0);
  }
  const double phi = *rc::gen::inRange(-1700, 1701) / 100.0;
  JointState state = RosJointState(theta, phi);
  std::reverse(state.name.begin(), state.name.end());
  std::reverse(state.model_position.begin(), state.model_position.end());
  const auto [back, phi_back] = ReportAngles(state.name, state.model_position);
  for (int f = 0; f < 3; ++f) RC_ASSERT((back[f] - theta[f]).cwiseAbs().maxCoeff() < 1e-12);
  RC_ASSERT(std::abs(phi_back - phi) < 1e-12);
}

TEST(RobotFramesTest, ReportAnglesNamesAMissingJoint) {
  const std::vector<std::string> names = {"finger_1_joint_1"};
  const std::vector<double> positions = {0.1};
  try {
    ReportAngles(names, positions);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no joint 'finger_1_joint_2'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReportAngles(names, std::vector<double>{}), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid::gripper
