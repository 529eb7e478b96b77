#pragma once

#include <vector>

#include "hybrid/diagnosis/diagnosis_model.h"
#include "hybrid/diagnosis/spike_filter.h"

namespace hybrid {

/// The noise floor of each channel: variance (unit^2) and the degrees of freedom it was
/// estimated from (its standard error enters the test for systematic residuals).
struct ChannelNoise {
  std::vector<double> variance;
  std::vector<int> dof;
};

/// Estimates the noise variance of each channel of `runs` (all with the same number of
/// channels), assuming independent noise of equal variance on every sample. `repeat_of[r]` is
/// the index of the first run that run r repeats (the same inputs, so the same true signal at
/// every sample), r itself when it repeats none; runs with the same repeat_of form a group.
///
/// Spikes first: each run's channel is screened with SpikeMask (the rule DiagnoseModel applies to
/// residuals) with threshold `spike_sigmas` times a preliminary, robust noise estimate (the
/// second-difference estimate below, which a few spikes do not move); spikes count as missing.
///
/// With at least one group of two or more runs ("repeated runs"): the pooled within-group
/// variance over those groups, at the samples where every run of the group has the channel: the
/// sum of squared deviations from the group's mean at the sample, divided by
/// dof = the sum over those samples of (runs in the group - 1). Unbiased for Gaussian noise but
/// for the spike screen, which removes the rare genuine samples beyond spike_sigmas of their
/// window's median: at 4 sigmas about 0.1% of Gaussian samples, lowering the variance by a few
/// tenths of a percent.
/// Otherwise ("second differences"): d_k = x[k+1] - 2 x[k] + x[k-1] over consecutive samples of
/// a run where all three are present (Var d = 6 sigma^2 for independent noise on a signal whose
/// second differences are negligible); each run's d are centred on their median, the absolute
/// deviations of all runs are pooled and variance = (1.4826 * their median)^2 / 6 (the median
/// absolute deviation, consistent for Gaussian noise); dof = the number of d used. A signal
/// whose second differences are not negligible against the noise (a fast, curved motion, steps
/// of uneven size) biases it upwards; the median keeps that bias small while such samples are
/// a minority.
/// A channel without any usable sample has variance 0 and dof 0. Throws std::invalid_argument
/// when repeat_of does not have one entry per run, an entry is out of range or names a later
/// run, or the runs do not have the same number of channels, or a group's runs differ in length.
ChannelNoise EstimateChannelNoise(const std::vector<DiagnosisRun>& runs,
                                  const std::vector<int>& repeat_of,
                                  double spike_sigmas = kDefaultSpikeSigmas);

}  // namespace hybrid
