#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "gripper/finger_effects.h"
#include "gripper/finger_predictor.h"
#include "gripper/measured_data.h"

namespace hybrid {

/// Settings of Diagnose. The defaults are the documented ones (docs/diagnosis.md).
struct DiagnosisOptions {
  /// The report's outlier rule (CleanOutliers): a jump of more than this many degrees.
  double outlier_threshold = 5.0;
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
  /// Grid points of the first, coarse pass over a parameter's range (a second, fine pass adds as
  /// many around the best one).
  int grid_points = 9;
  /// The same for the second parameter of a pair (the first one fixed).
  int pair_grid_points = 7;
  /// Refine the selected parameters with Ceres (robust loss, several starts).
  bool refine = true;
  /// Worker threads for the simulations (>= 1).
  int threads = 2;
};

/// One candidate extension as judged by cross-validation.
struct CandidateFit {
  std::vector<EffectParameter> parameters;
  /// Fitted on all runs.
  std::vector<double> values;
  /// Held-out (leave-one-run-out) mean squared error per joint, deg^2.
  std::array<double, 3> heldout_mse = {0, 0, 0};
  /// Held-out robust loss (chi-square units) and its gain over the reference (the baseline for
  /// single causes, the first cause alone for pairs).
  double heldout_loss = 0.0;
  double gain = 0.0;
  /// Bayesian information criterion of the all-data fit: loss + k ln(N).
  double bic = 0.0;
  bool significant = false;
};

/// Baseline residuals of one joint in one mode and direction of travel.
struct ResidualGroup {
  int joint = 0;  ///< 0..2
  std::string mode;
  int direction = 1;  ///< +1 closing, -1 opening
  int samples = 0;
  double mean = 0.0;   ///< bias, deg
  double slope = 0.0;  ///< trend, deg per count of g
  double rms = 0.0;
  /// mean square / noise variance - 1 (0 for pure noise).
  double excess = 0.0;
  double g_min = 0.0, g_max = 0.0;
};

/// A jump of the mean residual where the baseline switches mode.
struct ChangePoint {
  std::string run;
  int sample = 0;
  double g = 0.0;
  std::string from_mode, to_mode;
  int joint = 0;
  double jump = 0.0;  ///< mean residual over the next 10 samples minus the previous 10, deg
};

/// Where a systematic residual is, when no candidate explains it.
struct ResidualLocation {
  int joint = 0;
  std::string mode;
  int direction = 1;
  double g_min = 0.0, g_max = 0.0;
  double mean_residual = 0.0;
  double excess = 0.0;
};

/// Measured, baseline and extended angles of one run (for plots).
struct RunCurves {
  std::string label;
  std::vector<double> g;
  std::array<std::vector<double>, 3> measured, baseline, extended;
};

/// What Diagnose found.
struct Diagnosis {
  /// Cause names (CauseName), or {"none"}, or {"unexplained"}.
  std::vector<std::string> cause;
  /// The named causes' parameters (all-data fit) and the effects they make.
  std::vector<std::pair<EffectParameter, double>> parameters;
  FingerEffects effects;
  /// Held-out mean squared error per joint (deg^2) of the baseline model and of the extended
  /// one (the baseline's when no cause is named).
  std::array<double, 3> baseline_mse = {0, 0, 0};
  std::array<double, 3> extended_mse = {0, 0, 0};
  NoiseFloor noise;
  OutlierReport outliers;
  std::vector<ResidualGroup> residuals;
  std::vector<ChangePoint> change_points;
  /// Mean baseline residual closing minus opening, per joint (deg).
  std::array<double, 3> direction_difference = {0, 0, 0};
  std::optional<ResidualLocation> where;
  /// Every single candidate, then the pairs with the first cause (if one was significant).
  std::vector<CandidateFit> candidates;
  std::vector<RunCurves> curves;
  int samples = 0;
};

/// Diagnoses `data` against the finger model of `predictor`:
/// 1. cleans outliers (the report's rule) and estimates the noise floor (EstimateNoiseFloor);
/// 2. runs the model driven by each run's motor positions and analyses the residuals per joint,
///    mode and direction of travel;
/// 3. fits every candidate parameter (AllEffectParameters) on a grid of per-run robust losses,
///    cross-validates it leaving one run out, and names the best one when its held-out gain is
///    significant (DiagnosisOptions::significance; BIC breaks ties); then tries each other
///    candidate with it and names a second cause when that adds a significant held-out gain;
/// 4. refines the named parameters on all runs with Ceres (Huber loss; the grid's best points as
///    starts);
/// 5. calls the result "unexplained" (with `where`) when the extended model's held-out residual
///    is still systematic against the noise floor, and "none" when the baseline's is not.
/// Throws std::invalid_argument ("Diagnose: ...") when `data` has no runs or a prediction fails.
Diagnosis Diagnose(const FingerPredictor& predictor, MeasuredData data,
                   const DiagnosisOptions& options = {});

}  // namespace hybrid
