// The independent rig simulator (tests/test_utilities/robotiq_rig.h) against numbers worked out
// by hand from the report's tables (section 4, m1 = 70/140 = 0.5, m2 = 90/100 = 0.9,
// c = 43 - (-55) = 98) and the controller's documented behaviour (section 2).

#include "tests/test_utilities/robotiq_rig.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace hybrid::testing {
namespace {

constexpr double kTol = 1e-9;

void ExpectAngles(const std::array<double, 3>& got, double t1, double t2, double t3) {
  EXPECT_NEAR(got[0], t1, kTol);
  EXPECT_NEAR(got[1], t2, kTol);
  EXPECT_NEAR(got[2], t3, kTol);
}

TEST(RobotiqRig, FreeSpaceTable41) {
  const RigFinger f;
  const RigObject none;
  ExpectAngles(RigAngles(0, f, none), 0, 0, 0);
  ExpectAngles(RigAngles(50, f, none), 25, 0, -25);   // phase 1: m1 g, 0, -m1 g
  ExpectAngles(RigAngles(110, f, none), 55, 0, -55);  // end of phase 1
  ExpectAngles(RigAngles(120, f, none), 60, 0, -55);  // phase 1': theta3 at its minimum
  ExpectAngles(RigAngles(140, f, none), 70, 0, -55);
  ExpectAngles(RigAngles(200, f, none), 70, 54, -55);  // phase 2: m2 (g - 140)
  ExpectAngles(RigAngles(240, f, none), 70, 90, -55);
  ExpectAngles(RigAngles(250, f, none), 70, 90, -55);  // the palm: stopped at 240
  EXPECT_DOUBLE_EQ(RigStopPosition(f, none), 240);
}

TEST(RobotiqRig, ContactOnLink1Table) {
  const RigFinger f;
  const RigObject object{30.0, std::nullopt};
  ExpectAngles(RigAngles(20, f, object), 10, 0, -10);   // before contact: free
  ExpectAngles(RigAngles(60, f, object), 15, 27, -42);  // 0 < g - gob <= 100
  // g - gob > 100: theta3 = min(43, -55 + 98 (g - gob - 100) / (255 - g))
  ExpectAngles(RigAngles(150, f, object), 15, 90, -55 + 98.0 * 20 / 105);
  // theta3 reaches 43 half way between g_s = 130 and 255.
  EXPECT_DOUBLE_EQ(RigStopPosition(f, object), 192.5);
  ExpectAngles(RigAngles(192.5, f, object), 15, 90, 43);
  ExpectAngles(RigAngles(230, f, object), 15, 90, 43);
}

TEST(RobotiqRig, ContactOnLink2Table) {
  const RigFinger f;
  // gob <= 140: theta1 = m1 gob, theta2 = 0, theta3 from theta3_min.
  const RigObject early{std::nullopt, 120.0};
  ExpectAngles(RigAngles(150, f, early), 60, 0, -55 + 98.0 * 30 / 105);
  EXPECT_DOUBLE_EQ(RigStopPosition(f, early), 187.5);
  // 140 < gob: theta1 = theta1_max, theta2 = m2 (gob - 140).
  const RigObject late{std::nullopt, 200.0};
  ExpectAngles(RigAngles(220, f, late), 70, 54, -55 + 98.0 * 20 / 35);
  EXPECT_DOUBLE_EQ(RigStopPosition(f, late), 227.5);
}

// The report's link-2 table starts phase 3 at theta3_min; with gob2 = 50 theta3 was -25 there,
// so the table jumps. Like the model (docs/finger_model.md, C2), the rig continues from -25.
TEST(RobotiqRig, Link2ContactInPhase1ContinuesFromTheta3) {
  const RigFinger f;
  const RigObject object{std::nullopt, 50.0};
  ExpectAngles(RigAngles(50, f, object), 25, 0, -25);
  ExpectAngles(RigAngles(100, f, object), 25, 0, -25 + 68.0 * 50 / 155);
}

TEST(RobotiqRig, Theta3FractionMovesTheStop) {
  RigFinger f;
  f.theta3_fraction = 0.25;
  const RigObject object{30.0, std::nullopt};
  EXPECT_DOUBLE_EQ(RigStopPosition(f, object), 130 + 0.25 * 125);
  EXPECT_NEAR(RigAngles(130 + 0.25 * 125, f, object)[2], 43, kTol);
}

TEST(RobotiqRig, JointRangeScalesTheRates) {
  RigFinger f;
  f.theta2_max = 80;  // m2 = 0.8
  ExpectAngles(RigAngles(200, f, {}), 70, 48, -55);
}

TEST(RobotiqRig, ControllerStopsAtThePalmAndWaitsForAMoreOpenRequest) {
  const RigFinger f;
  const std::vector<double> requests = {100, 200, 250, 255, 245, 239, 100};
  const auto run = RigRun(requests, f, {}, {}, {});
  const std::vector<double> position = {100, 200, 240, 240, 240, 239, 100};
  for (size_t k = 0; k < run.size(); ++k) {
    EXPECT_DOUBLE_EQ(run[k].position, position[k]) << k;
    EXPECT_DOUBLE_EQ(run[k].request, requests[k]);
  }
  ExpectAngles(run[4].theta, 70, 90, -55);
  ExpectAngles(run[5].theta, 70, 89.1, -55);  // reopening follows the table at 239
  ExpectAngles(run[6].theta, 50, 0, -50);
}

TEST(RobotiqRig, ControllerStopsWhereLink3Stops) {
  const RigFinger f;
  const RigObject object{30.0, std::nullopt};
  const auto run = RigRun({150, 255, 200, 150}, f, object, {}, {});
  EXPECT_DOUBLE_EQ(run[1].position, 193);  // 192.5 reported in whole counts
  EXPECT_DOUBLE_EQ(run[1].drive, 192.5);
  EXPECT_DOUBLE_EQ(run[2].drive, 192.5);  // a request beyond the stop: still stopped
  ExpectAngles(run[3].theta, 15, 90, -55 + 98.0 * 20 / 105);
}

TEST(RobotiqRig, BacklashDelaysTheFingerAfterAReversal) {
  RigEffects e;
  e.backlash = 10;
  const auto run = RigRun({100, 95, 85, 90, 100}, RigFinger{}, {}, e, {});
  EXPECT_DOUBLE_EQ(run[0].drive, 100);
  EXPECT_DOUBLE_EQ(run[1].drive, 100);  // inside the play
  EXPECT_DOUBLE_EQ(run[2].drive, 95);   // pulled back: p + b
  EXPECT_DOUBLE_EQ(run[3].drive, 95);   // closing again: the play first
  EXPECT_DOUBLE_EQ(run[4].drive, 100);
}

TEST(RobotiqRig, MotorOffsetDrivesTheFingerLateAndMovesTheMotorStop) {
  RigEffects e;
  e.motor_offset = 5;
  const auto run = RigRun({3, 100, 255}, RigFinger{}, {}, e, {});
  EXPECT_DOUBLE_EQ(run[0].drive, 0);
  EXPECT_DOUBLE_EQ(run[1].drive, 95);
  EXPECT_DOUBLE_EQ(run[2].position, 245);
  EXPECT_DOUBLE_EQ(run[2].drive, 240);
}

TEST(RobotiqRig, ComplianceYieldsOnlyWhileBlocked) {
  const RigObject object{30.0, std::nullopt};
  const std::array<double, 2> k = {0.1, 0.0};
  EXPECT_NEAR(RigAngles(20, RigFinger{}, object, k)[0], 10, kTol);
  EXPECT_NEAR(RigAngles(80, RigFinger{}, object, k)[0], 15 + 5, kTol);
  // Link 3 follows the driven motion only: -(15 + 0.9 * 20) = -33 at q = 50, not -(17 + 18).
  EXPECT_NEAR(RigAngles(50, RigFinger{}, object, k)[2], -33, kTol);
}

TEST(RobotiqRig, BiasNoiseAndMissingCells) {
  RigEffects e;
  e.bias = {0, 0, 2.5};
  RigMeasurement m;
  m.noise_deg = 0.3;
  m.missing_fraction = 0.2;
  m.seed = 7;
  const auto requests = RigSweep(0, 255, 1);
  const auto a = RigRun(requests, RigFinger{}, {}, e, m);
  const auto b = RigRun(requests, RigFinger{}, {}, e, m);
  int missing = 0;
  double sum = 0, sum2 = 0;
  int n = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_TRUE(a[k].theta[j] == b[k].theta[j] || std::isnan(a[k].theta[j]));  // seeded
      if (std::isnan(a[k].theta[j])) {
        ++missing;
        continue;
      }
      if (j == 2) {
        const double r = a[k].theta[2] - RigAngles(a[k].drive, RigFinger{}, {})[2] - 2.5;
        sum += r;
        sum2 += r * r;
        ++n;
      }
    }
  }
  EXPECT_NEAR(missing / (3.0 * a.size()), 0.2, 0.05);
  EXPECT_NEAR(sum / n, 0.0, 0.1);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.3, 0.06);
}

// Outliers on theta3 only, of the sizes asked for, some in adjacent pairs; the other angles and
// the noise are those of the run without outliers.
TEST(RobotiqRig, OutliersOnTheta3InPairs) {
  RigMeasurement m;
  m.noise_deg = 0.5;
  m.seed = 9;
  const auto requests = RigSweep(0, 255, 0.25);
  const auto clean = RigRun(requests, RigFinger{}, {}, {}, m);
  m.outlier_fraction = 0.02;
  m.outlier_pair_fraction = 0.5;
  const auto dirty = RigRun(requests, RigFinger{}, {}, {}, m);
  int outliers = 0, pairs = 0;
  for (size_t k = 0; k < clean.size(); ++k) {
    EXPECT_EQ(clean[k].theta[0], dirty[k].theta[0]);
    EXPECT_EQ(clean[k].theta[1], dirty[k].theta[1]);
    const double d = std::abs(dirty[k].theta[2] - clean[k].theta[2]);
    if (d == 0) continue;
    EXPECT_GE(d, 10.0);
    EXPECT_LE(d, 25.0);
    ++outliers;
    if (k > 0 && dirty[k - 1].theta[2] != clean[k - 1].theta[2]) ++pairs;
  }
  EXPECT_NEAR(outliers / static_cast<double>(clean.size()), 0.03, 0.012);  // 2% x 1.5
  EXPECT_GE(pairs, 3);
}

TEST(RobotiqRig, SweepAndCsv) {
  const auto up = RigSweep(250, 255, 2);
  EXPECT_EQ(up, (std::vector<double>{250, 252, 254, 255}));
  const auto down = RigSweep(3, 0, 1.5);
  EXPECT_EQ(down, (std::vector<double>{3, 1.5, 0}));
  const RigObject object{30.0, std::nullopt};
  const auto run = RigRun({20, 60}, RigFinger{}, object, {}, {});
  EXPECT_EQ(RigCsvHeader(true), "run,g,position,theta1,theta2,theta3,gob,contact_link\n");
  EXPECT_EQ(RigCsvRows("a", run, object, 1), "a,20,20,10,0,-10,30,1\na,60,60,15,27,-42,30,1\n");
  EXPECT_THROW(RigCsvRows("a", run, object, 2), std::invalid_argument);
}

TEST(RobotiqRig, ProtocolsCloseReverseAndReopen) {
  const auto one = RigProtocol(255, RigStepping::kOne, 1);
  EXPECT_EQ(one.size(), 511u);  // 0..255 and back
  EXPECT_EQ(one[255], 255);
  EXPECT_EQ(one.back(), 0);
  const auto two = RigProtocol(255, RigStepping::kTwo, 1);
  EXPECT_EQ(two[127], 254);
  EXPECT_EQ(two[128], 255);  // the top is always a request
  const auto irregular = RigProtocol(250, RigStepping::kIrregular, 3, 120.0, 30.0);
  int reversals = 0;
  for (size_t k = 1; k < irregular.size(); ++k) {
    const double step = std::abs(irregular[k] - irregular[k - 1]);
    EXPECT_GT(step, 0.0);
    EXPECT_LE(step, 4.0);
    EXPECT_GE(irregular[k], 0.0);
    EXPECT_LE(irregular[k], 250.0);
    if (k + 1 < irregular.size() &&
        (irregular[k] - irregular[k - 1]) * (irregular[k + 1] - irregular[k]) < 0) {
      ++reversals;
    }
  }
  EXPECT_EQ(reversals, 3);  // up to 120, down to 90, up to 250, down to 0
  EXPECT_NE(std::find(irregular.begin(), irregular.end(), 90.0), irregular.end());
  EXPECT_EQ(RigProtocol(250, RigStepping::kIrregular, 3, 120.0, 30.0), irregular);  // seeded
}

}  // namespace
}  // namespace hybrid::testing
