#include "hybrid/diagnosis/noise_floor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hybrid {
namespace {

using Channel = std::vector<double>;

// The median (the mean of the two middle values of an even count).
double Median(std::vector<double> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  return 0.5 * (*std::max_element(v.begin(), v.begin() + mid) + upper);
}

// The robust second-difference estimate of one channel over `runs` (channel c of each):
// variance and the number of second differences it used.
std::pair<double, int> SecondDifferences(const std::vector<std::vector<Channel>>& runs, int c) {
  std::vector<double> deviations;  // |d - median of the run's d|, all runs
  for (const std::vector<Channel>& run : runs) {
    const Channel& x = run[c];
    std::vector<double> d;
    for (size_t k = 1; k + 1 < x.size(); ++k) {
      if (std::isnan(x[k - 1]) || std::isnan(x[k]) || std::isnan(x[k + 1])) continue;
      d.push_back(x[k + 1] - 2.0 * x[k] + x[k - 1]);
    }
    if (d.empty()) continue;
    const double median = Median(d);
    for (const double v : d) deviations.push_back(std::abs(v - median));
  }
  if (deviations.empty()) return {0.0, 0};
  const int dof = static_cast<int>(deviations.size());
  const double sigma_d = 1.4826 * Median(std::move(deviations));
  return {sigma_d * sigma_d / 6.0, dof};
}

// The pooled within-group variance of channel c over the groups of two or more runs.
std::pair<double, int> PooledWithinGroups(const std::vector<std::vector<Channel>>& runs,
                                          const std::vector<std::vector<int>>& groups, int c) {
  double sum_squares = 0.0;
  int dof = 0;
  for (const std::vector<int>& group : groups) {
    if (group.size() < 2) continue;
    const size_t samples = runs[group.front()][c].size();
    for (size_t i = 0; i < samples; ++i) {
      double sum = 0.0;
      bool complete = true;
      for (const int r : group) {
        const double x = runs[r][c][i];
        complete = complete && !std::isnan(x);
        sum += x;
      }
      if (!complete) continue;
      const double mean = sum / static_cast<double>(group.size());
      for (const int r : group) sum_squares += (runs[r][c][i] - mean) * (runs[r][c][i] - mean);
      dof += static_cast<int>(group.size()) - 1;
    }
  }
  return {dof > 0 ? sum_squares / dof : 0.0, dof};
}

// The groups of repeats, each led by its first run; checks repeat_of and the runs' shapes.
std::vector<std::vector<int>> Groups(const std::vector<DiagnosisRun>& runs,
                                     const std::vector<int>& repeat_of) {
  if (repeat_of.size() != runs.size()) {
    throw std::invalid_argument("EstimateChannelNoise: repeat_of needs one entry per run");
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of(runs.size(), -1);
  for (size_t r = 0; r < runs.size(); ++r) {
    const int first = repeat_of[r];
    if (first < 0 || first > static_cast<int>(r) ||
        (first < static_cast<int>(r) && group_of[first] < 0)) {
      throw std::invalid_argument("EstimateChannelNoise: run " + std::to_string(r) +
                                  " repeats no earlier run (repeat_of " + std::to_string(first) +
                                  ")");
    }
    if (runs[r].channels.size() != runs[0].channels.size() ||
        runs[r].input.size() != runs[first].input.size()) {
      throw std::invalid_argument("EstimateChannelNoise: run '" + runs[r].label +
                                  "' does not have the shape of the run it repeats");
    }
    if (first == static_cast<int>(r)) {
      group_of[r] = static_cast<int>(groups.size());
      groups.push_back({static_cast<int>(r)});
    } else {
      group_of[r] = group_of[first];
      groups[group_of[r]].push_back(static_cast<int>(r));
    }
  }
  return groups;
}

}  // namespace

ChannelNoise EstimateChannelNoise(const std::vector<DiagnosisRun>& runs,
                                  const std::vector<int>& repeat_of, double spike_sigmas) {
  const std::vector<std::vector<int>> groups = Groups(runs, repeat_of);
  const int channels = runs.empty() ? 0 : static_cast<int>(runs[0].channels.size());
  std::vector<std::vector<Channel>> screened;
  for (const DiagnosisRun& run : runs) screened.push_back(run.channels);
  const bool repeated = std::any_of(groups.begin(), groups.end(),
                                    [](const std::vector<int>& g) { return g.size() >= 2; });
  ChannelNoise noise;
  for (int c = 0; c < channels; ++c) {
    const double preliminary = SecondDifferences(screened, c).first;
    for (std::vector<Channel>& run : screened) {
      const std::vector<char> spike = SpikeMask(run[c], spike_sigmas * std::sqrt(preliminary));
      for (size_t k = 0; k < spike.size(); ++k) {
        if (spike[k]) run[c][k] = std::numeric_limits<double>::quiet_NaN();
      }
    }
    const auto [variance, dof] =
        repeated ? PooledWithinGroups(screened, groups, c) : SecondDifferences(screened, c);
    noise.variance.push_back(variance);
    noise.dof.push_back(dof);
  }
  return noise;
}

}  // namespace hybrid
