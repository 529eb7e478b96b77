// The fast path of `hybrid diagnose` (drive map, base automaton, output map) equals the extended
// automaton that `--out-model` writes, simulated on the motor path.

#include "hybrid/gripper/finger_predictor.h"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/gripper/finger_effects.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/robotiq_rig.h"

namespace hybrid {
namespace {

using testing::SpecText;

Automaton Finger() { return ParseModel(SpecText("finger"), "finger.ha").components()[0].automaton; }

MeasuredRun RunAlong(std::vector<double> g, std::optional<double> gob = {},
                     std::optional<int> link = {}) {
  MeasuredRun run;
  run.label = "r";
  run.g = std::move(g);
  for (auto& t : run.theta) t.assign(run.g.size(), 0.0);
  run.gob = gob;
  run.contact_link = link;
  return run;
}

// Integer motor path 0 -> a -> b -> c (one sample per count).
std::vector<double> Path(const std::vector<int>& corners) {
  std::vector<double> g;
  int at = 0;
  for (int c : corners) {
    const int step = c > at ? 1 : -1;
    while (at != c) {
      at += step;
      g.push_back(at);
    }
  }
  return g;
}

// The extended automaton, simulated with u = +-1 along the motor path: the angles at each sample.
std::array<std::vector<double>, 3> SimulateExtended(const FingerPredictor& predictor,
                                                    const MeasuredRun& run,
                                                    const FingerEffects& e) {
  Automaton a = ExtendFingerModel(predictor.finger(), e, predictor.StartState(e));
  if (run.gob) {
    const double gob = std::clamp(*run.gob - e.motor_offset, 0.0, 256.0);
    a.SetParameter("gob" + std::to_string(*run.contact_link), gob);
  }
  // The written model must parse back to the same automaton.
  const std::string text = PrintAutomaton(a);
  const System parsed = ParseModel(text, "extended.ha");
  EXPECT_TRUE(parsed.components()[0].automaton == a);
  const System system = System::Of(a);
  Simulator sim(system);
  SimulationOptions o;
  std::vector<std::pair<double, double>> points;
  double t = 0.0, g = 0.0;
  for (double next : run.g) {
    const double step = next - g;
    if (step != 0.0) {
      const double sign = step > 0 ? 1.0 : -1.0;
      if (points.empty() || points.back().second != sign) points.emplace_back(t, sign);
      t += std::abs(step);
      g = next;
    }
    o.sample_times.push_back(t);
  }
  points.front().first = 0.0;
  points.emplace_back(t, 0.0);
  o.until = t + 1.0;
  o.relative_tolerance = 1e-10;
  o.absolute_tolerance = 1e-12;
  const int u = *sim.system().symbols().Find("u");
  const std::vector<InputSignal> signals = {InputSignal{u, InputSignal::Shape::kStep, points}};
  const SimulationResult r = sim.Run(o, signals);
  EXPECT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  std::array<std::vector<double>, 3> theta;
  const auto& names = sim.variable_names();
  for (int j = 0; j < 3; ++j) {
    const std::string plain = "theta" + std::to_string(j + 1);
    const std::string measured = plain + "_measured";
    auto it = std::find(names.begin(), names.end(), measured);
    if (it == names.end()) it = std::find(names.begin(), names.end(), plain);
    const int index = static_cast<int>(it - names.begin());
    for (const StateSample& s : r.samples) {
      if (s.kind == StateSample::Kind::kSample) theta[j].push_back(s.x[index]);
    }
  }
  return theta;
}

double MaxDifference(const FingerPrediction& p, const std::array<std::vector<double>, 3>& q) {
  double worst = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (p.theta[j].size() != q[j].size()) return INFINITY;
    for (size_t k = 0; k < q[j].size(); ++k) {
      worst = std::max(worst, std::abs(p.theta[j][k] - q[j][k]));
    }
  }
  return worst;
}

TEST(FingerPredictorTest, NeutralEffectsFollowTheModelInFreeSpace) {
  const FingerPredictor predictor(Finger());
  const MeasuredRun run = RunAlong(Path({200, 0}));
  const FingerPrediction p = predictor.Predict(run, {});
  ASSERT_EQ(p.status, SimulationStatus::kCompleted) << p.message;
  // Closing: theta1 = m1 g = g / 2 up to g = 140 (theta3 = -g / 2 until its limit at 110).
  EXPECT_NEAR(p.theta[0][99], 50.0, 1e-6);  // g = 100
  EXPECT_NEAR(p.theta[2][99], -50.0, 1e-6);
  EXPECT_NEAR(p.theta[1][179], 36.0, 1e-6);  // g = 180: theta2 = 0.9 (180 - 140)
  EXPECT_EQ(p.direction[150], 1);
  EXPECT_EQ(p.direction[250], -1);
  EXPECT_EQ(predictor.ModeName(p.mode[99]), "c000_l000");
}

TEST(FingerPredictorTest, BacklashDelaysTheOpeningOnly) {
  const FingerPredictor predictor(Finger());
  const MeasuredRun run = RunAlong(Path({100, 0}));
  FingerEffects e;
  e.backlash = 10;
  const FingerPrediction p = predictor.Predict(run, e);
  ASSERT_EQ(p.status, SimulationStatus::kCompleted) << p.message;
  EXPECT_NEAR(p.theta[0][59], 30.0, 1e-6);  // closing, g = 60: as the model
  // Opening: sample 119 is g = 80; the finger stays at 50 deg until the motor reaches 90.
  EXPECT_NEAR(p.theta[0][109], 50.0, 1e-6);  // g = 90
  EXPECT_NEAR(p.theta[0][119], 45.0, 1e-6);  // g = 80: drive 90
}

TEST(FingerPredictorTest, OffsetShiftsTheCurveAndKeepsTheContactPosition) {
  const FingerPredictor predictor(Finger());
  FingerEffects e;
  e.motor_offset = 8;
  const MeasuredRun run = RunAlong(Path({200}), 150.0, 2);
  const FingerPrediction p = predictor.Predict(run, e);
  ASSERT_EQ(p.status, SimulationStatus::kCompleted) << p.message;
  EXPECT_NEAR(p.theta[0][4], 0.0, 1e-9);    // g = 5 < d: not moving yet
  EXPECT_NEAR(p.theta[0][49], 21.0, 1e-6);  // g = 50: model at 42
  // Link 2 is blocked where the data says, g = 150: theta2 stays at 0.9 (150 - 8 - 140).
  EXPECT_NEAR(p.theta[1][159], 0.9 * 2.0, 1e-6);
}

// The controller's motor path for given stops: held at a stop from its sample while the request
// is not below it, following the request again from the first one below.
TEST(MotorPositionsTest, HoldsAtAStopUntilAMoreOpenRequest) {
  const std::vector<double> requests = {100, 250, 255, 240, 239, 250, 100, 230, 254, 0};
  const std::vector<ControllerStop> stops = {{1, 240.0}, {8, 220.5}};
  EXPECT_EQ(MotorPositions(requests, stops),
            (std::vector<double>{100, 240, 240, 240, 239, 250, 100, 230, 220.5, 0}));
  EXPECT_EQ(MotorPositions(requests, {}), requests);
}

// The report's protocol (requests up to 255, past the stop, and back; one reversal on the way up)
// against the independent rig: the motor is the rig's min(request, stop) and the angles are the
// rig's, for no object, an object on link 1 and one on link 2, with play and offset.
// Both integration settings: the default, and diagnose's FastOptions (looser tolerances, samples
// on the solver's interpolant), within 1e-5 and 1e-3 deg of the rig (motor stops within 1e-6 and
// 1e-3 counts).
class FingerPredictorRigTest : public ::testing::TestWithParam<bool> {};

TEST_P(FingerPredictorRigTest, RequestsPastTheStopFollowTheIndependentRig) {
  const bool fast = GetParam();
  const FingerPredictor predictor(
      Finger(), fast ? FingerPredictor::FastOptions() : FingerPredictor::Options{});
  const double tolerance = fast ? 1e-3 : 1e-5;
  struct Case {
    std::optional<double> gob1, gob2;
    double backlash, offset;
  };
  for (const Case& c : {Case{{}, {}, 0, 0}, Case{80, {}, 0, 0}, Case{{}, 170, 0, 0},
                        Case{60, {}, 6, 0}, Case{{}, 200, 0, 5}, Case{100, {}, 4, -3},
                        Case{{}, 170, 15, 0}, Case{80, {}, 6, 0}, Case{100, {}, 8, 0}}) {
    testing::RigObject object;
    object.gob1 = c.gob1;
    object.gob2 = c.gob2;
    testing::RigEffects rig_effects;
    rig_effects.backlash = c.backlash;
    rig_effects.motor_offset = c.offset;
    const std::vector<double> requests =
        testing::RigProtocol(255, testing::RigStepping::kTwo, 3, 150.0, 30.0);
    const auto samples = testing::RigRun(requests, {}, object, rig_effects, {});
    const int link = c.gob1 ? 1 : c.gob2 ? 2 : 0;
    // The data give the object as the motor position of first contact: drive + offset.
    MeasuredRun run = link ? RunAlong(requests, *(link == 1 ? c.gob1 : c.gob2) + c.offset, link)
                           : RunAlong(requests);
    FingerEffects e;
    e.backlash = c.backlash;
    e.motor_offset = c.offset;
    const FingerPrediction p = predictor.Predict(run, e);
    ASSERT_EQ(p.status, SimulationStatus::kCompleted) << p.message;
    const double motor_stop =
        std::clamp(testing::RigStopPosition({}, object) + c.offset, 0.0, 255.0);
    for (size_t k = 0; k < requests.size(); ++k) {
      SCOPED_TRACE("link " + std::to_string(link) + " request " + std::to_string(requests[k]) +
                   " sample " + std::to_string(k));
      EXPECT_NEAR(p.motor[k], std::min(requests[k], motor_stop), fast ? 1e-3 : 1e-6);
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(p.theta[j][k], samples[k].theta[j], tolerance);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Settings, FingerPredictorRigTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "Fast" : "Default";
                         });

// The law: for random effects, objects and request paths with reversals (which may go past where
// the finger stalls), the predictor equals the extended automaton driven along its motor path
// (ExtendFingerModel, printed and parsed back) within 1e-6 deg.
RC_GTEST_PROP(FingerPredictorProperty, EqualsTheExtendedAutomaton, ()) {
  // Both sides integrate the phase-3 law with CVODE at the same tight tolerances.
  static const FingerPredictor predictor(Finger(), FingerPredictor::Options{1e-10, 1e-12, 4});
  FingerEffects e;
  e.backlash = *rc::gen::inRange(0, 25);
  e.motor_offset = *rc::gen::inRange(-15, 16);
  if (*rc::gen::arbitrary<bool>())
    e.joint_max[*rc::gen::inRange(0, 3)] = *rc::gen::inRange(40, 100);
  if (*rc::gen::arbitrary<bool>()) e.theta3_fraction = *rc::gen::inRange(25, 80) / 100.0;
  if (*rc::gen::arbitrary<bool>())
    e.compliance[*rc::gen::inRange(0, 2)] = *rc::gen::inRange(1, 20) / 100.0;
  if (*rc::gen::arbitrary<bool>())
    e.sensor_bias[*rc::gen::inRange(0, 3)] = *rc::gen::inRange(-50, 50) / 10.0;
  const int link = *rc::gen::inRange(0, 3);  // 0: free space
  const std::vector<int> corners = {*rc::gen::inRange(30, 256), *rc::gen::inRange(0, 200),
                                    *rc::gen::inRange(0, 256)};
  MeasuredRun run = RunAlong(Path(corners));
  RC_PRE(run.g.size() >= 10);
  if (link > 0) {
    run.gob = *rc::gen::inRange(60, 240);
    run.contact_link = link;
  }
  // The run's g are requests; the controller stops the motor where the finger stalls, so the
  // finger's g follows the drive, and the extended automaton is driven along the motor path.
  const FingerPrediction p = predictor.Predict(run, e);
  RC_ASSERT(p.status == SimulationStatus::kCompleted);
  for (size_t k = 0; k < run.g.size(); ++k) RC_ASSERT(p.drive[k] - p.model_g[k] < 1e-3);
  MeasuredRun along_motor = run;
  along_motor.g = p.motor;
  const double diff = MaxDifference(p, SimulateExtended(predictor, along_motor, e));
  RC_ASSERT(diff < 1e-6);
  // Diagnose's settings (FastOptions: looser tolerances, samples on the solver's interpolant)
  // stop the motor at the same samples, and stay within 1e-3 deg.
  static const FingerPredictor fast(Finger(), FingerPredictor::FastOptions());
  const FingerPrediction q = fast.Predict(run, e);
  RC_ASSERT(q.status == SimulationStatus::kCompleted);
  RC_ASSERT(MaxDifference(q, {p.theta[0], p.theta[1], p.theta[2]}) < 1e-3);
}

}  // namespace
}  // namespace hybrid
