#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/diagnosis/diagnosis_model.h"

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
  /// Grid points of the first, coarse pass over a parameter's range (a second, fine pass adds
  /// points around the best one).
  int grid_points = 9;
  /// The same for the second parameter of a pair (the first one fixed).
  int pair_grid_points = 7;
  /// Refine the selected parameters with Ceres (robust loss, from the cross-validated values).
  bool refine = true;
  /// Worker threads for the simulations (>= 1).
  int threads = 2;
  /// If set, called on the calling thread before each candidate is fitted: the stage ("single
  /// causes", "pairs"), the candidates done and their number (for a progress report).
  std::function<void(const std::string& stage, int done, int total)> progress;
};

/// The noise floor of each channel: variance (unit^2) and the degrees of freedom it was
/// estimated from (its standard error enters the test for systematic residuals).
struct ChannelNoise {
  std::vector<double> variance;
  std::vector<int> dof;
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
  std::optional<SystematicResidual> where;
  /// Every single candidate, then the pairs with the first cause (if one was significant and
  /// left a systematic residual).
  std::vector<ParameterFit> candidates;
  /// The baseline's and the extended model's predictions of every run.
  std::vector<RunPrediction> baseline, extended;
};

/// Diagnoses measured `runs` against `model`, whose noise floor per channel is `noise`:
/// 1. scores the baseline (no parameter set) with the robust loss sum rho(r / sigma), rho the
///    Huber function with threshold DiagnosisOptions::huber, and groups its residuals per
///    channel, mode and direction of travel (bias, trend, excess over the noise; change points
///    where the mode switches; the difference between directions);
/// 2. fits every candidate parameter on its grid (a coarse pass, then a fine one around the
///    best point, each refined by the parabola through the best point and its neighbours),
///    cross-validates it leaving one run out, and names the best one when its held-out gain is
///    significant (DiagnosisOptions::significance; BIC breaks ties); when that one leaves a
///    systematic residual, tries each other candidate with it and names a second cause when it
///    adds a significant held-out gain;
/// 3. refines the named parameters on all runs with Ceres (Huber loss per sample, bounds = the
///    search ranges);
/// 4. calls the result "unexplained" (with `where`) when the extended model's held-out residual
///    is still systematic against the noise floor, and "none" when the baseline's is not.
/// Throws std::invalid_argument when `runs` is empty, when `noise` or a run does not have one
/// entry per channel, or when the model cannot predict a run.
ModelDiagnosis DiagnoseModel(const DiagnosisModel& model, const std::vector<DiagnosisRun>& runs,
                             const ChannelNoise& noise, const DiagnosisOptions& options = {});

}  // namespace hybrid
