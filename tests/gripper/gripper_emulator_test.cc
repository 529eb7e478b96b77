// The gripper emulator (include/hybrid/gripper/gripper_emulator.h): registers checked, activation
// timing from the controller's speed, the free closing of the report (every finger stops against
// the palm at g = 240, theta = (70, 90, -55)), and the model it needs.
#include "hybrid/gripper/gripper_emulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "hybrid/automaton/parser.h"

namespace hybrid::gripper {
namespace {

System GripperModel() {
  return ParseModelFile(std::filesystem::path(HYBRID_SOURCE_DIR) / "spec" / "gripper.ha");
}

TEST(GripperEmulatorTest, ActivatesThenClosesFreeFingersToThePalm) {
  GripperEmulator grip(GripperModel(), {});
  EXPECT_EQ(grip.state().status.gIMC, 0);
  GripperRegisters r;
  r.rACT = 1;
  r.rGTO = 1;
  r.rPR[0] = 255;
  grip.Command(r);
  // The scissor axis moves to the basic position, 137 counts at 255 counts/s (spec/controller.ha
  // at full speed): activation ends within the step after 137/255 s.
  double activated = -1.0;
  for (int k = 0; k < 2000 && activated < 0.0; ++k) {
    if (grip.Step(0.001).status.gIMC == 3) activated = grip.state().time;
  }
  EXPECT_NEAR(activated, 137.0 / 255.0, 0.0011);
  EXPECT_EQ(grip.state().scissor, 137.0);
  // Free fingers close at 255 counts/s and stall against the palm at g = 240 (the report's
  // free-space stop): 240/255 s.
  const GripperState& s = grip.Step(1.0);
  for (int f = 0; f < 3; ++f) {
    EXPECT_NEAR(s.motor[f], 240.0, 1e-9);
    EXPECT_NEAR(s.theta[f][0], 70.0, 1e-9);
    EXPECT_NEAR(s.theta[f][1], 90.0, 1e-9);
    EXPECT_NEAR(s.theta[f][2], -55.0, 1e-9);
    EXPECT_EQ(s.status.gDT[f], 2);
  }
  EXPECT_EQ(s.status.gSTA, 2);
  EXPECT_EQ(s.status.gPO[0], 240);
  EXPECT_EQ(s.simulation, "completed");
  EXPECT_EQ(s.joints.name.size(), 11u);
}

TEST(GripperEmulatorTest, RegistersOutOfRangeAreNamed) {
  GripperEmulator grip(GripperModel(), {});
  GripperRegisters r;
  r.rMOD = 4;
  try {
    grip.Command(r);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "rMOD must be in 0..3 (got 4)");
  }
  r.rMOD = 0;
  r.rSP[3] = -1;
  EXPECT_THROW(grip.Command(r), std::invalid_argument);
  EXPECT_THROW(grip.Step(0.0), std::invalid_argument);
  EXPECT_THROW(grip.Step(std::nan("")), std::invalid_argument);
}

TEST(GripperEmulatorTest, NeedsTheGrippersInstances) {
  const System hand =
      ParseModelFile(std::filesystem::path(HYBRID_SOURCE_DIR) / "spec" / "controlled_hand.ha");
  try {
    GripperEmulator grip(hand, {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no instance named ctlS"), std::string::npos) << e.what();
  }
  EXPECT_THROW(GripperEmulator(GripperModel(), {Obstacle::Parse("circle:0,-0.01,0.02")}),
               std::invalid_argument);
}

}  // namespace
}  // namespace hybrid::gripper

namespace hybrid::gripper {
namespace {

TEST(GripperRegistersTest, FindNamesEveryRegisterAsTheManualDoes) {
  GripperRegisters r;
  EXPECT_EQ(r.Find("rACT"), &r.rACT);
  EXPECT_EQ(r.Find("rICS"), &r.rICS);
  EXPECT_EQ(r.Find("rPRA"), &r.rPR[0]);
  EXPECT_EQ(r.Find("rSPS"), &r.rSP[3]);
  EXPECT_EQ(r.Find("rFRC"), &r.rFR[2]);
  for (const char* bad : {"", "rPR", "rPRD", "rXYA", "gACT", "rACTA"}) {
    EXPECT_EQ(r.Find(bad), nullptr) << bad;
  }
}

}  // namespace
}  // namespace hybrid::gripper
