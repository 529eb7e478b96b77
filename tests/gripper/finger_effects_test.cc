// Effects as changes of the finger automaton: the drive map (play with offset), parameter
// changes, compliance flows, and the extended model's structure.

#include "hybrid/gripper/finger_effects.h"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

using testing::SpecText;

Automaton Finger() { return ParseModel(SpecText("finger"), "finger.ha").components()[0].automaton; }

TEST(DrivePositionsTest, NeutralIsTheIdentityWithinTheRange) {
  const std::vector<double> g = {0, 10, 100, 255, 30, 0};
  EXPECT_EQ(DrivePositions(g, 0, 0), g);
}

TEST(DrivePositionsTest, PlayHoldsTheFingerAfterAReversal) {
  const std::vector<double> g = {0, 50, 100, 95, 90, 80, 85, 100};
  // Closing engaged (q = g); opening: q stays until g + b reaches it; then q = g + b.
  EXPECT_EQ(DrivePositions(g, 10, 0), (std::vector<double>{0, 50, 100, 100, 100, 90, 90, 100}));
}

TEST(DrivePositionsTest, OffsetShiftsAndClips) {
  const std::vector<double> g = {0, 5, 20, 255};
  EXPECT_EQ(DrivePositions(g, 0, 10), (std::vector<double>{0, 0, 10, 245}));
  EXPECT_EQ(DrivePositions(g, 0, -10), (std::vector<double>{10, 15, 30, 255}));
  EXPECT_THROW(DrivePositions(g, -1, 0), std::invalid_argument);
  EXPECT_THROW(DrivePositions(std::vector<double>{NAN}, 0, 0), std::invalid_argument);
}

// The play operator's laws: the drive stays in [g - d, g - d + b] (clipped to the motor range),
// moves only when pushed there, and never moves against the motor (from the first sample on: the
// first sample takes the play up from the open finger at q = 0).
RC_GTEST_PROP(DrivePositionsProperty, PlayLaws, ()) {
  const double b = *rc::gen::inRange(0, 30);
  const double d = *rc::gen::inRange(-20, 21);
  const auto g = *rc::gen::container<std::vector<double>>(
      rc::gen::map(rc::gen::inRange(0, 256), [](int x) { return static_cast<double>(x); }));
  const std::vector<double> q = DrivePositions(g, b, d);
  RC_PRE(!g.empty());
  double last = q[0], last_g = g[0];
  for (size_t k = 0; k < g.size(); ++k) {
    const double lo = std::clamp(g[k] - d, 0.0, 255.0), hi = std::clamp(g[k] - d + b, 0.0, 255.0);
    RC_ASSERT(q[k] >= lo - 1e-12);
    RC_ASSERT(q[k] <= hi + 1e-12);
    if (q[k] != last) RC_ASSERT(q[k] == lo || q[k] == hi);
    if (g[k] >= last_g) RC_ASSERT(q[k] >= last - 1e-12);
    if (g[k] <= last_g) RC_ASSERT(q[k] <= last + 1e-12);
    last = q[k];
    last_g = g[k];
  }
}

TEST(ApplyDynamicEffectsTest, JointRangeScalesTheRate) {
  FingerEffects e;
  e.joint_max[1] = 80;
  const Automaton a = ApplyDynamicEffects(Finger(), e);
  const std::vector<double> env = a.ParameterEnvironment();
  EXPECT_DOUBLE_EQ(env[*a.symbols().Find("theta2_max")], 80.0);
  EXPECT_DOUBLE_EQ(env[*a.symbols().Find("m2")], 0.8);
}

TEST(ApplyDynamicEffectsTest, ComplianceGivesTheBlockedLinkAFlow) {
  FingerEffects e;
  e.compliance[0] = 0.05;
  const Automaton a = ApplyDynamicEffects(Finger(), e);
  const int c1 = *a.symbols().Find("c1"), theta1 = *a.symbols().Find("theta1");
  int blocked = 0;
  for (const Mode& m : a.modes()) {
    if (m.DiscreteValueOf(c1) == 1) {
      ++blocked;
      ASSERT_TRUE(m.FlowOf(theta1).has_value()) << m.name;
      EXPECT_NE(m.FlowOf(theta1)->ToString().find("compliance_link1"), std::string::npos);
    }
  }
  EXPECT_GT(blocked, 0);
  e.compliance[0] = -1;
  EXPECT_THROW(ApplyDynamicEffects(Finger(), e), std::invalid_argument);
  FingerEffects f;
  f.theta3_fraction = 1.5;
  EXPECT_THROW(ApplyDynamicEffects(Finger(), f), std::invalid_argument);
}

TEST(ExtendFingerModelTest, ThreeCopiesOfEachModeAndPrintable) {
  const Automaton finger = Finger();
  FingerEffects e;
  e.backlash = 4;
  e.sensor_bias[2] = 1.5;
  const Automaton x = ExtendFingerModel(finger, e);
  EXPECT_EQ(x.num_modes(), 3 * finger.num_modes());
  EXPECT_EQ(x.num_transitions(), 2 * finger.num_transitions() + 6 * finger.num_modes());
  EXPECT_TRUE(x.symbols().Find("g_motor").has_value());
  EXPECT_TRUE(x.symbols().Find("theta3_measured").has_value());
  EXPECT_FALSE(x.symbols().Find("theta1_measured").has_value());
  EXPECT_EQ(x.properties().size(), finger.properties().size());
  const Automaton back = ParseModel(PrintAutomaton(x), "x.ha").components()[0].automaton;
  EXPECT_TRUE(back == x);
  // The slack copies freeze the finger: only g_motor moves.
  const int gm = *x.symbols().Find("g_motor");
  for (const Mode& m : x.modes()) {
    if (m.name.ends_with("_slack")) {
      ASSERT_EQ(m.flows.size(), 1u) << m.name;
      EXPECT_EQ(m.flows[0].first, gm);
    }
  }
}

// The extended model runs as written: it keeps the finger's scenario (close for 255 s, hold,
// open for 240 s), and with a play of 6 counts the finger stays 6 counts closed when the motor
// is back at 0 (the play of DrivePositions: q = 0 + b).
TEST(ExtendFingerModelTest, KeepsTheScenarioAndRunsWithoutOptions) {
  FingerEffects e;
  e.backlash = 6.0;
  const Automaton extended = ExtendFingerModel(Finger(), e, std::nullopt);
  ASSERT_TRUE(extended.scenario().has_value());
  const System system = ParseModel(PrintAutomaton(extended), "extended.ha");
  const Simulator simulator(system);
  const SimulationResult r = simulator.Run(SimulationOptions{});
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  const auto& names = simulator.variable_names();
  auto at_end = [&](const std::string& name) {
    return r.samples.back().x[std::find(names.begin(), names.end(), name) - names.begin()];
  };
  EXPECT_NEAR(at_end("g_motor"), 0.0, 1e-9);
  EXPECT_NEAR(at_end("g"), 6.0, 1e-6);
  EXPECT_NEAR(at_end("theta1"), 3.0, 1e-6);  // m1 * 6
}

TEST(ExtendFingerModelTest, EarlyMotorNeedsTheFingersStartState) {
  FingerEffects e;
  e.motor_offset = -5;
  EXPECT_THROW(ExtendFingerModel(Finger(), e), std::invalid_argument);
}

TEST(EffectParametersTest, NamesAndNeutralValues) {
  const Automaton finger = Finger();
  const auto all = AllEffectParameters();
  EXPECT_EQ(all.size(), 11u);
  std::vector<std::string> names;
  for (const auto& p : all) names.push_back(ParameterName(p));
  EXPECT_EQ(names,
            (std::vector<std::string>{"backlash", "motor_offset", "theta1_max", "theta2_max",
                                      "theta3_max", "theta1_bias", "theta2_bias", "theta3_bias",
                                      "compliance_link1", "compliance_link2", "theta3_fraction"}));
  EXPECT_DOUBLE_EQ(NeutralValue({Cause::kJointRange, 1}, finger), 90.0);
  EXPECT_DOUBLE_EQ(NeutralValue({Cause::kTheta3Law, 0}, finger), 0.5);
  FingerEffects e;
  SetEffect(e, {Cause::kCompliance, 1}, 0.02);
  EXPECT_DOUBLE_EQ(GetEffect(e, {Cause::kCompliance, 1}, finger), 0.02);
  EXPECT_DOUBLE_EQ(GetEffect(e, {Cause::kJointRange, 0}, finger), 70.0);
  EXPECT_EQ(CauseName(Cause::kTheta3Law), "theta3_law");
}

}  // namespace
}  // namespace hybrid
