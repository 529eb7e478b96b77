#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/diagnosis/diagnosis_engine.h"
#include "hybrid/gripper/finger_effects.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"

namespace hybrid {

/// Settings of Diagnose: the engine's (DiagnosisOptions) and the finger data's cleaning.
struct FingerDiagnosisOptions : DiagnosisOptions {
  /// The report's outlier rule (CleanOutliers): a jump of more than this many degrees.
  double outlier_threshold = 5.0;
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

/// Baseline residuals of one joint (channel 0..2 = theta1..3) in one mode and direction of
/// travel (+1 closing, -1 opening); input = g, deg.
using ResidualGroup = ChannelResiduals;

/// A jump of the mean residual where the baseline switches mode (input = g).
using ChangePoint = ResidualJump;

/// Where a systematic residual is, when no candidate explains it (input = g).
using ResidualLocation = SystematicResidual;

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
  /// The fraction of the baseline's held-out excess over the noise floor the named causes remove
  /// (ModelDiagnosis::explained_fraction), and where the systematic remainder they leave is.
  double explained_fraction = 0.0;
  std::optional<ResidualLocation> remainder;
  /// Candidates dropped or searched in part (ModelDiagnosis::notes).
  std::vector<std::string> notes;
  /// Every single candidate, then the pairs with the first cause (if one was significant).
  std::vector<CandidateFit> candidates;
  std::vector<RunCurves> curves;
  int samples = 0;
};

/// Diagnoses `data` against the finger model of `predictor` with the general engine
/// (DiagnoseModel; the candidates are AllEffectParameters, the channels theta1..3, the input g):
/// 1. cleans outliers (the report's rule, on the residual against the baseline model: a change
///    of more than `outlier_threshold` degrees from one sample to the next beyond the model's)
///    and estimates the noise floor (EstimateNoiseFloor);
/// 2. runs DiagnoseModel on the cleaned runs through FingerDiagnosisModel: residuals per joint,
///    mode and direction of travel, cross-validated selection of one or two causes, refinement,
///    verdict ("none", the causes, or "unexplained" with `where`);
/// 3. turns the named parameters into FingerEffects and records the curves for plots.
/// Throws std::invalid_argument ("the data have no runs", "the model stopped on run '...': ...")
/// when `data` has no runs or a prediction fails.
Diagnosis Diagnose(const FingerPredictor& predictor, MeasuredData data,
                   const FingerDiagnosisOptions& options = {});

}  // namespace hybrid
