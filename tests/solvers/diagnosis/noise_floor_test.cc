#include "hybrid/diagnosis/noise_floor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace hybrid {
namespace {

// A run of n samples of a smooth curve (two channels: a ramp and a sine) plus Gaussian noise of
// standard deviation sigma, drawn from `seed`; the same curve for every run.
DiagnosisRun Noisy(int n, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  DiagnosisRun run{"run" + std::to_string(seed), {}, {{}, {}}};
  for (int k = 0; k < n; ++k) {
    run.input.push_back(k);
    run.channels[0].push_back(0.1 * k + noise(rng));
    run.channels[1].push_back(5.0 * std::sin(0.01 * k) + noise(rng));
  }
  return run;
}

// Outliers of 10 to 25 sigma on 2% of the samples of channel 0, 30% of them in adjacent pairs,
// at least 3 good samples apart (three outliers within 5 samples look like a step to the rule).
void AddOutliers(DiagnosisRun& run, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> size(10.0, 25.0), u(0.0, 1.0);
  std::vector<double>& x = run.channels[0];
  for (size_t k = 0; k + 1 < x.size(); ++k) {
    if (u(rng) > 0.02 / 1.3) continue;
    const double sign = u(rng) < 0.5 ? -1.0 : 1.0;
    x[k] += sign * size(rng) * sigma;
    if (u(rng) < 0.3) x[++k] += sign * size(rng) * sigma;
    k += 3;
  }
}

TEST(EstimateChannelNoise, PoolsRepeatedRunsWithinGroups) {
  std::vector<DiagnosisRun> runs;
  for (unsigned s = 1; s <= 4; ++s) runs.push_back(Noisy(2000, 0.5, s));
  const ChannelNoise noise = EstimateChannelNoise(runs, {0, 0, 2, 2});
  ASSERT_EQ(noise.variance.size(), 2u);
  EXPECT_EQ(noise.dof[0], 4000);  // two groups of two runs: one degree of freedom per sample
  EXPECT_NEAR(noise.variance[0], 0.25, 0.25 * 0.08);
  EXPECT_NEAR(noise.variance[1], 0.25, 0.25 * 0.08);
}

TEST(EstimateChannelNoise, UsesSecondDifferencesWithoutRepeats) {
  std::vector<DiagnosisRun> runs;
  for (unsigned s = 1; s <= 3; ++s) runs.push_back(Noisy(2000, 0.5, s));
  const ChannelNoise noise = EstimateChannelNoise(runs, {0, 1, 2});
  EXPECT_EQ(noise.dof[0], 3 * 1998);
  EXPECT_NEAR(noise.variance[0], 0.25, 0.25 * 0.1);
  EXPECT_NEAR(noise.variance[1], 0.25, 0.25 * 0.1);
}

// Outliers (in adjacent pairs too) are spikes for both estimators: the pooled variance would be
// several times too high with them.
TEST(EstimateChannelNoise, LeavesSpikesOut) {
  std::vector<DiagnosisRun> runs;
  for (unsigned s = 1; s <= 4; ++s) {
    runs.push_back(Noisy(2000, 0.5, s));
    AddOutliers(runs.back(), 0.5, 100 + s);
  }
  const ChannelNoise repeated = EstimateChannelNoise(runs, {0, 0, 0, 0});
  EXPECT_NEAR(repeated.variance[0], 0.25, 0.25 * 0.1);
  EXPECT_LT(repeated.dof[0], 3 * 2000);  // the spikes' samples left out
  EXPECT_GT(EstimateChannelNoise(runs, {0, 0, 0, 0}, 1e9).variance[0], 0.25 * 3);  // no rule
  const ChannelNoise differences = EstimateChannelNoise(runs, {0, 1, 2, 3});
  EXPECT_NEAR(differences.variance[0], 0.25, 0.25 * 0.1);
}

// The documented bias of the spike rule: on pure Gaussian noise it removes about 0.1% of the
// samples, lowering the pooled variance by well under 1%.
TEST(EstimateChannelNoise, TheSpikeRuleBarelyBiasesPureNoise) {
  std::vector<DiagnosisRun> runs;
  for (unsigned s = 1; s <= 8; ++s) runs.push_back(Noisy(5000, 1.0, s));
  const std::vector<int> one_group(8, 0);
  const ChannelNoise with = EstimateChannelNoise(runs, one_group);
  const ChannelNoise without = EstimateChannelNoise(runs, one_group, 1e9);
  EXPECT_LE(with.variance[0], without.variance[0]);
  EXPECT_GT(with.variance[0], 0.99 * without.variance[0]);
  EXPECT_GT(with.dof[0], 0.99 * without.dof[0]);
}

TEST(EstimateChannelNoise, MissingSamplesAndRefusals) {
  std::vector<DiagnosisRun> runs = {Noisy(100, 0.5, 1), Noisy(100, 0.5, 2)};
  runs[1].channels[0][10] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(EstimateChannelNoise(runs, {0, 0}).dof[0], 99);
  EXPECT_THROW(EstimateChannelNoise(runs, {0}), std::invalid_argument);
  EXPECT_THROW(EstimateChannelNoise(runs, {1, 1}), std::invalid_argument);  // a later run
  runs[1].input.pop_back();
  runs[1].channels[0].pop_back();
  runs[1].channels[1].pop_back();
  EXPECT_THROW(EstimateChannelNoise(runs, {0, 0}), std::invalid_argument);  // lengths differ
  EXPECT_TRUE(EstimateChannelNoise({}, {}).variance.empty());
}

}  // namespace
}  // namespace hybrid
