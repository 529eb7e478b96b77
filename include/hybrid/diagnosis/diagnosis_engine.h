#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/diagnosis/diagnosis_model.h"
#include "hybrid/diagnosis/noise_floor.h"

namespace hybrid {

/// Settings of the diagnosis engine (DiagnoseModel). The defaults are the documented ones
/// (docs/diagnosis.md).
struct DiagnosisOptions {
  /// Huber threshold of the robust loss, in noise standard deviations.
  double huber = 3.0;
  /// A candidate is significant when its held-out loss (leave-one-run-out, in units of the noise
  /// variance, i.e. chi-square units) is lower than the reference's by more than this.
  double significance = 25.0;
  /// Two held-out losses closer than this (chi-square units) are a tie, broken by BIC.
  double tie = 2.0;
  /// A residual is systematic when its held-out mean square exceeds the noise floor by more than
  /// `systematic_sigmas` standard errors plus `systematic_margin` (relative).
  double systematic_sigmas = 4.0;
  double systematic_margin = 0.05;
  /// Grid points of the coarse grid over a parameter's range (the bracketing search then adds
  /// points around its starts, DiagnoseModel step 2).
  int grid_points = 9;
  /// The same for the second parameter of a pair (the first one fixed).
  int pair_grid_points = 7;
  /// Horizons of the search: fractions of each run's samples (a horizon h keeps the first
  /// ceil(h n) samples of a run of n), ascending in (0, 1], the last 1. Every coarse grid point
  /// is scored at every horizon from the same prediction; the best point of each horizon is a
  /// start of the bracketing. Short horizons find the narrow basins of switching systems, whose
  /// residuals are discontinuous in a threshold: {1} (the default) searches the full runs only.
  std::vector<double> horizons = {1.0};
  /// Further starts of the bracketing: the best other local minima of the full-horizon loss on
  /// the coarse grid.
  int extra_starts = 0;
  /// The most predictions (Predict calls, one run each) the search may make: once exceeded, no
  /// further candidate is searched (a note says which were not).
  long max_predictions = 200000;
  /// The outlier rule (SpikeMask): a residual more than this many noise standard deviations
  /// from the median of its 5-sample window is a spike, left out of the test for systematic
  /// residuals, of explained_fraction and of `where`; EstimateChannelNoise applies the same rule.
  double spike_sigmas = kDefaultSpikeSigmas;
  /// When the best extension still leaves a systematic residual but explains at least this
  /// fraction of the baseline's excess (ModelDiagnosis::explained_fraction), its causes are
  /// named all the same, with the remainder located; below it the verdict is "unexplained".
  double main_fraction = 0.9;
  /// Refine the selected parameters with Ceres (robust loss, from the cross-validated values).
  bool refine = true;
  /// Worker threads (>= 1): the candidates are fitted side by side, and a joint fit or a
  /// refinement simulates its runs in parallel.
  int threads = 2;
  /// If set, called before each candidate is fitted: the stage ("single causes", "pairs"), the
  /// candidates started before it and their number (for a progress report). Candidates are
  /// fitted side by side on the worker threads: it is called from them, one call at a time.
  std::function<void(const std::string& stage, int done, int total)> progress;
};

/// One candidate extension as judged by cross-validation.
struct ParameterFit {
  /// Indices into DiagnosisModel::Parameters(): the first cause then the candidate (pairs), or
  /// the candidate alone.
  std::vector<int> parameters;
  /// Fitted on all runs.
  std::vector<double> values;
  /// Held-out (leave-one-run-out) mean squared error per channel.
  std::vector<double> heldout_mse;
  /// Held-out robust loss (chi-square units) and its gain over the reference (the baseline for
  /// single causes, the first cause alone for pairs).
  double heldout_loss = 0.0;
  double gain = 0.0;
  /// Bayesian information criterion of the all-data fit: loss + k ln(N).
  double bic = 0.0;
  bool significant = false;
};

/// Baseline residuals of one channel in one mode and direction of travel.
struct ChannelResiduals {
  int channel = 0;
  std::string mode;  ///< ModeName, or "?" where the model's mode is unknown
  int direction = 1;
  int samples = 0;
  double mean = 0.0;   ///< bias
  double slope = 0.0;  ///< trend per unit of input
  double rms = 0.0;
  /// mean square / noise variance - 1 (0 for pure noise).
  double excess = 0.0;
  double input_min = 0.0, input_max = 0.0;
};

/// A jump of the mean residual where the baseline switches mode.
struct ResidualJump {
  std::string run;
  int sample = 0;
  double input = 0.0;
  std::string from_mode, to_mode;
  int channel = 0;
  double jump = 0.0;  ///< mean residual over the next 10 samples minus the previous 10
};

/// Where a systematic residual is, when no candidate explains it.
struct SystematicResidual {
  int channel = 0;
  std::string mode;
  int direction = 1;
  double input_min = 0.0, input_max = 0.0;
  double mean_residual = 0.0;
  double excess = 0.0;
};

/// What DiagnoseModel found.
struct ModelDiagnosis {
  /// Cause names (CandidateParameter::cause, each once), or {"none"}, or {"unexplained"}.
  std::vector<std::string> cause;
  /// The named causes' parameters (indices and all-data values, refined).
  ParameterValues parameters;
  /// Held-out mean squared error per channel of the baseline model and of the extended one
  /// (the baseline's when no cause is named).
  std::vector<double> baseline_mse, extended_mse;
  std::vector<ChannelResiduals> residuals;
  /// The 50 largest, largest first.
  std::vector<ResidualJump> change_points;
  /// Mean baseline residual with the input rising minus falling, per channel.
  std::vector<double> direction_difference;
  /// Where the residual no candidate explains is ("unexplained" only): located on the best
  /// extension's predictions (the baseline's when no candidate is significant).
  std::optional<SystematicResidual> where;
  /// The fraction of the baseline's excess over the noise that the named causes explain:
  /// (E_base - E_ext) / E_base, clamped to [0, 1], E = sum over channels of
  /// n_c (ms_c / sigma_c^2 - 1) of the held-out residuals that are not spikes (n_c of them, mean
  /// square ms_c); 0 when E_base <= 0 or no candidate is significant. Also set for
  /// "unexplained" when a candidate was significant (the best extension's fraction).
  double explained_fraction = 0.0;
  /// When causes are named but the extension still leaves a systematic residual (it explains
  /// at least DiagnosisOptions::main_fraction): where that remainder is, on the extension's
  /// predictions.
  std::optional<SystematicResidual> remainder;
  /// What the search could not do, in words: a candidate that could not be simulated
  /// ("<cause> (<parameter name>): could not be simulated: <message>", at every value: left out
  /// of the selection and of `candidates`; or at some values: "... could not be simulated at K
  /// of N run predictions (loss +inf there): <message>"), the prediction budget spent.
  std::vector<std::string> notes;
  /// Every single candidate, then the pairs with the first cause (if one was significant and
  /// left a systematic residual): the best three of them (by held-out loss with the first fixed)
  /// fitted jointly, the others with the first fixed at its single-cause value.
  std::vector<ParameterFit> candidates;
  /// The baseline's and the extended model's predictions of every run.
  std::vector<RunPrediction> baseline, extended;
};

/// Diagnoses measured `runs` against `model`, whose noise floor per channel is `noise`:
/// 1. scores the baseline (no parameter set) with the robust loss sum rho(r / sigma), rho the
///    Huber function with threshold DiagnosisOptions::huber, and groups its residuals per
///    channel, mode and direction of travel (bias, trend, excess over the noise; change points
///    where the mode switches; the difference between directions);
/// 2. searches every candidate parameter (SearchProfile, solvers/diagnosis/profile_search.h):
///    a coarse grid scored at every horizon, then from the best grid point of each horizon (and
///    `extra_starts` further local minima) a bracketing between the start's grid neighbours,
///    golden-section steps with parabolic ones where they help, on the full-horizon loss of all
///    runs; every value tried is recorded. Each run's fold (the candidate fitted without it) is
///    the recorded value of least training loss, refined by a parabola when its neighbours are
///    close; the held-out run is predicted there. The candidate of least held-out loss is named
///    when its gain over the baseline is significant (DiagnosisOptions::significance; BIC breaks
///    ties). When it leaves a systematic residual, each other candidate is searched with it
///    fixed, the best three of those are fitted jointly with it (coordinate search: the first
///    given the second, then the second given the first, around the best point so far; every
///    point recorded) and cross-validated (each fold at the recorded point of least training
///    loss), and a second cause is named when the pair's held-out gain over the first alone is
///    significant. A prediction that throws (std::exception) scores +inf at that value (notes);
///    a candidate with no finite value is left out; the search stops at max_predictions;
/// 3. refines the named parameters on all runs with Ceres (Huber loss per sample, bounds = the
///    search ranges), kept only when the all-data loss drops;
/// 4. the verdict: "none" when nothing is significant and the baseline's residual is not
///    systematic; "unexplained" (with `where` on the best extension's predictions, no
///    parameters adopted) when the best extension (or the baseline) leaves a systematic residual
///    and explains less than main_fraction of the baseline's excess (explained_fraction); else
///    the causes, with `remainder` when a systematic residual is left. Systematic: on some
///    channel the mean square of the held-out residuals that are not spikes (SpikeMask,
///    spike_sigmas) exceeds the noise floor by more than systematic_sigmas standard errors plus
///    systematic_margin.
/// Throws std::invalid_argument when `runs` is empty, when `noise` or a run does not have one
/// entry per channel, when the horizons or main_fraction are out of range, or when the model
/// cannot predict a run of the baseline; std::logic_error when a prediction does not have its
/// run's shape.
ModelDiagnosis DiagnoseModel(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
                             const ChannelNoise& noise, const DiagnosisOptions& options = {});

}  // namespace hybrid
