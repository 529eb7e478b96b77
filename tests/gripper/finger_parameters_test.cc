// FingerParametersOf (include/hybrid/gripper/finger_parameters.h): the closed form's constants read
// from a finger automaton, as declared or as changed.

#include "hybrid/gripper/finger_parameters.h"

#include <gtest/gtest.h>

#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_closed_form.h"

namespace hybrid::gripper {
namespace {

Automaton BundledFinger() {
  return ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha")
      .components()[0]
      .automaton;
}

TEST(FingerParametersOf, TheBundledFingerHasTheReportsConstants) {
  // The joint ranges of docs/gripper_facts.md (Klamp't limits).
  const FingerParameters p = FingerParametersOf(BundledFinger());
  EXPECT_EQ(p.theta_min, Eigen::Vector3d(0, 0, -55));
  EXPECT_EQ(p.theta_max, Eigen::Vector3d(70, 90, 43));
  EXPECT_EQ(p.theta3_fraction, 0.5);
  EXPECT_EQ(p.motor_max, 255.0);
}

TEST(FingerParametersOf, FollowsChangedParameters) {
  Automaton finger = BundledFinger();
  finger.SetParameter("theta2_max", 80);
  finger.SetParameter("theta3_fraction", 0.3);
  const FingerParameters p = FingerParametersOf(finger);
  EXPECT_EQ(p.theta_max[1], 80.0);
  EXPECT_DOUBLE_EQ(p.m2(), 0.8);
  EXPECT_EQ(p.theta3_fraction, 0.3);
  // The closed form with them: link 2 at 0.8 deg per count; after a link-1 contact at 30, link 2
  // stops at 130 and link 3 reaches its limit 0.3 of the way to 255.
  FingerContacts contacts;
  contacts.gob[0] = 30;
  const FingerClosedForm closed(contacts, p);
  EXPECT_DOUBLE_EQ(closed.At(80).theta[1], 40.0);
  EXPECT_DOUBLE_EQ(closed.stop(), 130 + 0.3 * 125);
}

TEST(FingerParametersOf, AnAutomatonWithoutJointRangesIsRefused) {
  const Automaton tank =
      ParseModel("automaton tank { var h in [0, 1]; mode m { h' = 0; } init m { h = 0; } }", "t.ha")
          .components()[0]
          .automaton;
  try {
    (void)FingerParametersOf(tank);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "automaton 'tank' has no parameter 'theta1_min' (not a finger model like "
                 "spec/finger.ha)");
  }
}

TEST(FingerClosedFormParameters, Theta3FractionOutsideItsRangeIsRefused) {
  FingerParameters p;
  p.theta3_fraction = 0.0;
  EXPECT_THROW(FingerClosedForm({}, p), std::invalid_argument);
  p.theta3_fraction = 1.5;
  EXPECT_THROW(FingerClosedForm({}, p), std::invalid_argument);
  p.theta3_fraction = 1.0;  // a flat law, and a jump to the limit at 255
  EXPECT_THROW(FingerClosedForm({}, p), std::invalid_argument);
  p.theta3_fraction = 0.85;  // the top of the diagnosis's range
  EXPECT_NO_THROW(FingerClosedForm({}, p));
}

}  // namespace
}  // namespace hybrid::gripper
