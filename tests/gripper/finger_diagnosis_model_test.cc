// The finger as a DiagnosisModel (include/hybrid/gripper/finger_diagnosis_model.h): its candidates,
// its shortcut for sensor biases and its pruning of runs a parameter cannot change, checked against
// FingerPredictor itself (whose own tests check it against the closed form).

#include "hybrid/gripper/finger_diagnosis_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

using testing::SpecText;

Automaton Finger() { return ParseModel(SpecText("finger"), "finger.ha").components()[0].automaton; }

// A run closing to g_end then opening to 0, one sample per count, angles 0.
MeasuredRun MotorRun(const std::string& label, int g_end, bool reverse) {
  MeasuredRun run;
  run.label = label;
  for (int g = 0; g <= g_end; ++g) run.g.push_back(g);
  for (int g = g_end - 1; reverse && g >= 0; --g) run.g.push_back(g);
  for (auto& t : run.theta) t.assign(run.g.size(), 0.0);
  for (size_t k = 0; k < run.g.size(); ++k) run.lines.push_back(static_cast<int>(k) + 2);
  return run;
}

class FingerDiagnosisModelTest : public ::testing::Test {
 protected:
  FingerDiagnosisModelTest() : predictor_(Finger(), FingerPredictor::FastOptions()) {
    data_.runs = {MotorRun("closing", 200, false), MotorRun("there_and_back", 200, true)};
    for (const MeasuredRun& run : data_.runs) baseline_.push_back(predictor_.Predict(run, {}));
  }

  int Index(const std::string& name, const FingerDiagnosisModel& model) const {
    for (size_t i = 0; i < model.Parameters().size(); ++i) {
      if (model.Parameters()[i].name == name) return static_cast<int>(i);
    }
    ADD_FAILURE() << "no parameter " << name;
    return 0;
  }

  FingerPredictor predictor_;
  MeasuredData data_;
  std::vector<FingerPrediction> baseline_;
};

TEST_F(FingerDiagnosisModelTest, OffersEveryEffectParameterInOrder) {
  const FingerDiagnosisModel model(predictor_, data_, baseline_);
  const std::vector<EffectParameter> all = AllEffectParameters();
  ASSERT_EQ(model.Parameters().size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    const CandidateParameter& c = model.Parameters()[i];
    EXPECT_EQ(model.effect(static_cast<int>(i)), all[i]);
    EXPECT_EQ(c.name, ParameterName(all[i]));
    EXPECT_EQ(c.cause, CauseName(all[i].cause));
    EXPECT_LT(c.lo, c.hi) << c.name;
    // The model's own value (neutral) lies in the searched range, so "no effect" can be found.
    const double neutral = NeutralValue(all[i], predictor_.finger());
    EXPECT_LE(c.lo, neutral) << c.name;
    EXPECT_GE(c.hi, neutral) << c.name;
    EXPECT_EQ(c.cheap, all[i].cause == Cause::kSensorBias) << c.name;
  }
}

TEST_F(FingerDiagnosisModelTest, PredictsWhatThePredictorPredicts) {
  const FingerDiagnosisModel model(predictor_, data_, baseline_);
  const int backlash = Index("backlash", model), theta2_max = Index("theta2_max", model);
  const int bias = Index("theta3_bias", model);
  const ParameterValues values = {{backlash, 6.0}, {theta2_max, 80.0}, {bias, 2.5}};
  FingerEffects effects;
  effects.backlash = 6.0;
  effects.joint_max[1] = 80.0;
  effects.sensor_bias[2] = 2.5;
  for (int r = 0; r < 2; ++r) {
    const RunPrediction p = model.Predict(r, values);
    const FingerPrediction expected = predictor_.Predict(data_.runs[r], effects);
    ASSERT_EQ(p.channels.size(), 3u);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(p.channels[j], expected.theta[j]) << r << " " << j;
    EXPECT_EQ(p.mode, expected.mode);
    EXPECT_EQ(p.direction, expected.direction);
  }
  // No values: the baseline as given; a later value replaces an earlier one.
  EXPECT_EQ(model.Predict(1, {}).channels[0], baseline_[1].theta[0]);
  EXPECT_EQ(model.Predict(1, {{bias, 1.0}, {bias, 2.5}}).channels[2],
            model.Predict(1, {{bias, 2.5}}).channels[2]);
}

TEST_F(FingerDiagnosisModelTest, ASensorBiasShiftsItsJointOnly) {
  const FingerDiagnosisModel model(predictor_, data_, baseline_);
  const RunPrediction p = model.Predict(0, {{Index("theta1_bias", model), -3.0}});
  for (size_t k = 0; k < baseline_[0].theta[0].size(); ++k) {
    EXPECT_EQ(p.channels[0][k], baseline_[0].theta[0][k] - 3.0);
    EXPECT_EQ(p.channels[1][k], baseline_[0].theta[1][k]);
  }
}

TEST_F(FingerDiagnosisModelTest, BacklashOnlyMattersWhereTheMotorReverses) {
  const FingerDiagnosisModel model(predictor_, data_, baseline_);
  const int backlash = Index("backlash", model);
  const RunPrediction reference = model.Predict(0, {});
  EXPECT_FALSE(model.Affects(backlash, 0, reference));
  EXPECT_TRUE(model.Affects(backlash, 1, reference));
  // And indeed it changes nothing on the closing run.
  EXPECT_EQ(model.Predict(0, {{backlash, 10.0}}).channels, reference.channels);
  EXPECT_NE(model.Predict(1, {{backlash, 10.0}}).channels, model.Predict(1, {}).channels);
}

TEST_F(FingerDiagnosisModelTest, RunsAreTheMeasuredAngles) {
  const FingerDiagnosisModel model(predictor_, data_, baseline_);
  const std::vector<DiagnosisRun> runs = model.Runs();
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[1].label, "there_and_back");
  EXPECT_EQ(runs[1].input, data_.runs[1].g);
  ASSERT_EQ(runs[1].channels.size(), 3u);
  EXPECT_EQ(runs[1].channels[2], data_.runs[1].theta[2]);
}

}  // namespace
}  // namespace hybrid
