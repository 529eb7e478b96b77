#pragma once

#include <string>
#include <utility>
#include <vector>

namespace hybrid {

/// One measured run as the diagnosis engine sees it: an input signal (e.g. a motor position) and
/// the measured output channels at the same samples.
struct DiagnosisRun {
  std::string label;
  /// The input at each sample (used to locate residuals: slopes, ranges, change points).
  std::vector<double> input;
  /// channels[c][k]: channel c measured at sample k; NaN where the sample is missing. Every
  /// channel has input.size() samples.
  std::vector<std::vector<double>> channels;
};

/// What a model predicts for one run: the channels at the run's samples, with the discrete state
/// and direction of travel of each sample (residuals are grouped by them).
struct RunPrediction {
  /// channels[c][k], the same shape as the run's.
  std::vector<std::vector<double>> channels;
  /// The model's mode at each sample (an index the model names with ModeName; -1 unknown).
  std::vector<int> mode;
  /// Direction of travel of the input at each sample: +1 or -1.
  std::vector<int> direction;
  /// Every mode the prediction visits, also between samples and at the instant of a jump
  /// (sorted, each once); empty when the model records only `mode`. For Affects.
  std::vector<int> visited;
};

/// One number a candidate extension of the model fits.
struct CandidateParameter {
  /// The cause it stands for (several parameters may share one, e.g. one per joint).
  std::string cause;
  /// Its name in reports, e.g. "theta2_max".
  std::string name;
  /// The range searched: a grid over [lo, hi], then a finer pass around the best point.
  double lo = 0.0;
  double hi = 1.0;
  /// Points of the coarse grid; 0 takes DiagnosisOptions::grid_points (pair_grid_points when it
  /// is fitted on top of another cause). Cheap parameters (e.g. an output offset, which needs no
  /// simulation) use a dense grid and no worker threads.
  int grid_points = 0;
  bool cheap = false;
};

/// A parameter setting: (index into DiagnosisModel::Parameters(), value), applied in order (a
/// later entry for the same parameter replaces an earlier one). Parameters not named keep the
/// model's own (neutral) values.
using ParameterValues = std::vector<std::pair<int, double>>;

/// The model under diagnosis, as the engine (DiagnoseModel) uses it: its candidate parameters
/// and its predictions of the measured runs under any setting of them.
///
/// Implementations must be safe to call from several threads at once (the engine simulates
/// runs in parallel) and deterministic (the same run and values give the same prediction).
class DiagnosisModel {
 public:
  virtual ~DiagnosisModel() = default;

  /// Every candidate parameter, in the order candidates are tried and reported.
  virtual const std::vector<CandidateParameter>& Parameters() const = 0;

  /// The prediction of run `run` (an index into the runs given to DiagnoseModel) under
  /// `values`. Throws std::invalid_argument (with a message for the user) when the model cannot
  /// predict the run (e.g. its simulation stops early).
  virtual RunPrediction Predict(int run, const ParameterValues& values) const = 0;

  /// Whether changing parameter `parameter` can change run `run`'s prediction, given the
  /// prediction `reference` of the setting it is changed from. False lets the engine reuse the
  /// reference's score. The default is true (always simulate).
  virtual bool Affects(int parameter, int run, const RunPrediction& reference) const {
    (void)parameter, (void)run, (void)reference;
    return true;
  }

  /// The name of mode index `mode` of RunPrediction::mode (mode >= 0).
  virtual std::string ModeName(int mode) const = 0;
};

}  // namespace hybrid
