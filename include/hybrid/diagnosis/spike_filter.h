#pragma once

#include <vector>

namespace hybrid {

/// The default of DiagnosisOptions::spike_sigmas and of EstimateChannelNoise: how many noise
/// standard deviations from its neighbourhood's median make a sample a spike.
inline constexpr double kDefaultSpikeSigmas = 4.0;

/// The one outlier rule of the diagnosis (the noise floor, EstimateChannelNoise, and the test for
/// systematic residuals, DiagnoseModel, both use it). `values` is one channel of one run in
/// measurement order (a residual, or a measured signal), NaN where missing. Sample k is a spike
/// when |values[k] - m_k| > threshold, m_k being the median of its window: the 5 non-missing
/// samples nearest k in order (k and two on each side; at the run's ends the window is shifted
/// to stay inside the run, so it still holds 5 samples when the run has them; a run with fewer
/// non-missing samples has them all as its window). A median of 5 resists 2 spikes, so an
/// adjacent pair of spikes is caught too; a level step (3 samples or more on each side) is not a
/// spike, and neither are three outliers within 5 samples (to the median they are a level). A
/// monotone ramp is not a spike inside a run (the median is the sample itself); at a run's ends,
/// where the window is shifted, a ramp steeper than threshold / 2 per sample is. Returns one flag
/// per sample (1 = spike; missing samples are never spikes). A threshold that is not positive and
/// finite flags nothing.
std::vector<char> SpikeMask(const std::vector<double>& values, double threshold);

}  // namespace hybrid
