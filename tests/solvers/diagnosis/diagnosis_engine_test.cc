// The diagnosis engine on a model written here (no gripper): a line y = (1 + gain) x + offset,
// plus offsets that apply only while x rises or only while it falls, with two modes (x below or
// above 50). Data are drawn from known truths with Gaussian noise, so
// the right answer is known independently of the engine.

#include "hybrid/diagnosis/diagnosis_engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <stdexcept>

namespace hybrid {
namespace {

constexpr double kSigma = 0.1;

class LineModel : public DiagnosisModel {
 public:
  /// Candidates: some of "offset", "gain", "rising", "falling".
  LineModel(const std::vector<DiagnosisRun>& runs, const std::vector<std::string>& names)
      : runs_(runs) {
    for (const std::string& n : names) {
      parameters_.push_back({n, n, n == "gain" ? -0.5 : -5.0, n == "gain" ? 0.5 : 5.0});
    }
  }

  const std::vector<CandidateParameter>& Parameters() const override { return parameters_; }

  RunPrediction Predict(int run, const ParameterValues& values) const override {
    std::map<std::string, double> v;
    for (const auto& [p, value] : values) v[parameters_[p].name] = value;
    RunPrediction out;
    out.channels.resize(1);
    const std::vector<double>& x = runs_[run].input;
    for (size_t k = 0; k < x.size(); ++k) {
      const bool falling = k > 0 ? x[k] < x[k - 1] : x.size() > 1 && x[1] < x[0];
      out.channels[0].push_back((1.0 + v["gain"]) * x[k] + v["offset"] +
                                (falling ? v["falling"] : v["rising"]));
      out.mode.push_back(x[k] < 50 ? 0 : 1);
      out.direction.push_back(falling ? -1 : 1);
    }
    return out;
  }

  std::string ModeName(int mode) const override { return mode == 0 ? "low" : "high"; }

 private:
  const std::vector<DiagnosisRun>& runs_;
  std::vector<CandidateParameter> parameters_;
};

// Four runs over x = 0..99 (two rising, two falling) measuring truth(x) plus noise.
std::vector<DiagnosisRun> Runs(const std::function<double(double)>& truth, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<DiagnosisRun> runs;
  for (int r = 0; r < 4; ++r) {
    DiagnosisRun run{"run" + std::to_string(r), {}, {{}}};
    for (int k = 0; k < 100; ++k) {
      const double x = r % 2 == 0 ? k : 99 - k;
      run.input.push_back(x);
      run.channels[0].push_back(truth(x) + noise(rng));
    }
    runs.push_back(run);
  }
  return runs;
}

ModelDiagnosis DiagnoseLine(const std::vector<DiagnosisRun>& runs,
                            const std::vector<std::string>& names = {"offset", "gain"}) {
  const LineModel model(runs, names);
  DiagnosisOptions options;
  options.threads = 1;
  return DiagnoseModel(model, runs, ChannelNoise{{kSigma * kSigma}, {1000}}, options);
}

TEST(DiagnoseModel, NamesTheOffsetAndFindsItsValue) {
  const auto runs = Runs([](double x) { return x + 2.0; }, 1);
  const ModelDiagnosis d = DiagnoseLine(runs);
  ASSERT_EQ(d.cause, std::vector<std::string>{"offset"});
  ASSERT_EQ(d.parameters.size(), 1u);
  EXPECT_EQ(d.parameters[0].first, 0);
  // 400 samples of noise 0.1: the mean is known to 0.005; allow 4 standard errors.
  EXPECT_NEAR(d.parameters[0].second, 2.0, 0.02);
  EXPECT_NEAR(d.baseline_mse[0], 4.0 + kSigma * kSigma, 0.05);
  EXPECT_NEAR(d.extended_mse[0], kSigma * kSigma, 0.003);
  EXPECT_EQ(d.candidates.size(), 2u);  // the offset explains everything: no pairs
  EXPECT_TRUE(d.candidates[0].significant);
}

TEST(DiagnoseModel, NamesTwoCausesTogether) {
  // Rising samples read 2 high, falling ones 1 low: "rising" alone leaves the falling residual,
  // which "falling" then explains with it.
  const auto runs = Runs([](double x) { return x; }, 2);
  std::vector<DiagnosisRun> shifted = runs;
  for (DiagnosisRun& run : shifted) {
    const bool falling = run.input[1] < run.input[0];
    for (double& y : run.channels[0]) y += falling ? -1.0 : 2.0;
  }
  const ModelDiagnosis d = DiagnoseLine(shifted, {"rising", "falling"});
  ASSERT_EQ(d.cause, (std::vector<std::string>{"rising", "falling"}));
  ASSERT_EQ(d.parameters.size(), 2u);
  EXPECT_NEAR(d.parameters[0].second, 2.0, 0.03);
  EXPECT_NEAR(d.parameters[1].second, -1.0, 0.03);
  EXPECT_EQ(d.candidates.size(), 3u);  // two singles, then "falling" with "rising"
  EXPECT_NEAR(d.direction_difference[0], 3.0, 0.05);
}

TEST(DiagnoseModel, SaysNoneForPureNoise) {
  const ModelDiagnosis d = DiagnoseLine(Runs([](double x) { return x; }, 3));
  EXPECT_EQ(d.cause, std::vector<std::string>{"none"});
  EXPECT_TRUE(d.parameters.empty());
  EXPECT_FALSE(d.where);
}

TEST(DiagnoseModel, LocatesWhatNoCandidateExplains) {
  // A bump of height 3 on 60 < x < 80 only: neither an offset nor a gain fits it.
  const auto runs = Runs([](double x) { return x + (x > 60 && x < 80 ? 3.0 : 0.0); }, 4);
  const ModelDiagnosis d = DiagnoseLine(runs);
  EXPECT_EQ(d.cause, std::vector<std::string>{"unexplained"});
  ASSERT_TRUE(d.where);
  EXPECT_EQ(d.where->mode, "high");
  EXPECT_GE(d.where->input_min, 55.0);
  EXPECT_LE(d.where->input_max, 85.0);
  // Change points: none at x = 50 (the model switches mode there, the residual does not jump).
  for (const ResidualJump& j : d.change_points) EXPECT_GT(std::abs(j.input - 50.0), 5.0);
}

TEST(DiagnoseModel, RefusesInconsistentInput) {
  const auto runs = Runs([](double x) { return x; }, 5);
  const LineModel model(runs, {"offset"});
  EXPECT_THROW(DiagnoseModel(model, {}, ChannelNoise{{0.01}, {10}}), std::invalid_argument);
  EXPECT_THROW(DiagnoseModel(model, runs, ChannelNoise{{0.01, 0.01}, {10, 10}}),
               std::invalid_argument);
  EXPECT_THROW(DiagnoseModel(model, runs, ChannelNoise{{0.01}, {}}), std::invalid_argument);
  std::vector<DiagnosisRun> ragged = runs;
  ragged[2].channels[0].pop_back();
  EXPECT_THROW(DiagnoseModel(model, ragged, ChannelNoise{{0.01}, {10}}), std::invalid_argument);
}

// A model whose predictions do not have the runs' shape is refused, not read out of bounds.
TEST(DiagnoseModel, RefusesPredictionsOfAnotherShape) {
  class Short : public LineModel {
   public:
    using LineModel::LineModel;
    RunPrediction Predict(int run, const ParameterValues& values) const override {
      RunPrediction p = LineModel::Predict(run, values);
      p.channels[0].pop_back();
      return p;
    }
  };
  const auto runs = Runs([](double x) { return x; }, 6);
  const Short model(runs, {"offset"});
  EXPECT_THROW(DiagnoseModel(model, runs, ChannelNoise{{0.01}, {10}}), std::logic_error);
}

}  // namespace
}  // namespace hybrid
