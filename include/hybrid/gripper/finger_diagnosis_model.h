#pragma once

#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hybrid/diagnosis/diagnosis_model.h"
#include "hybrid/gripper/finger_effects.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"

namespace hybrid {

/// The finger as the diagnosis engine sees it (DiagnosisModel): one candidate parameter per
/// EffectParameter of AllEffectParameters (in that order; causes named by CauseName, ranges the
/// documented search ranges of docs/diagnosis.md, sensor biases cheap on a 121-point grid), the
/// channels theta1..3 (deg), and predictions by FingerPredictor.
///
/// A prediction whose effects leave the drive and the dynamics neutral (no backlash, offset,
/// joint range, compliance or theta3 law; only sensor biases) is the baseline shifted by the
/// biases; other predictions are memoised per run with the same motor path and object (runs
/// that repeat one another share them) and per dynamic effects. Safe to call from several
/// threads.
class FingerDiagnosisModel : public DiagnosisModel {
 public:
  /// `data` (cleaned) must outlive the model; `baseline` holds the model's prediction of every
  /// run of `data` without effects, each completed.
  FingerDiagnosisModel(const FingerPredictor& predictor, const MeasuredData& data,
                       std::vector<FingerPrediction> baseline);

  const std::vector<CandidateParameter>& Parameters() const override { return candidates_; }
  /// The prediction under Effects(values). Throws std::invalid_argument ("the model stopped on
  /// run '...': ...") when the simulation does not complete.
  RunPrediction Predict(int run, const ParameterValues& values) const override;
  /// Backlash only matters in runs where g reverses; link compliance only where the baseline
  /// visits a mode with that link blocked (c<i> = 1); the theta3 law only where it visits c2 = 1
  /// or l2 = 1.
  bool Affects(int parameter, int run, const RunPrediction& reference) const override;
  std::string ModeName(int mode) const override { return predictor_.ModeName(mode); }

  /// The effect parameter of candidate `parameter`.
  const EffectParameter& effect(int parameter) const { return effects_[parameter]; }
  /// The FingerEffects of a setting (SetEffect in order).
  FingerEffects Effects(const ParameterValues& values) const;
  /// The runs as the engine reads them: input g, channels theta1..3.
  std::vector<DiagnosisRun> Runs() const;

 private:
  FingerPrediction Checked(int run, const FingerEffects& effects) const;
  // The prediction of `run` under `dynamic` (no sensor biases): from the memo, or simulated
  // (Checked) for its representative and kept there.
  RunPrediction Memoised(int run, const FingerEffects& dynamic) const;

  const FingerPredictor& predictor_;
  const MeasuredData& data_;
  std::vector<RunPrediction> baseline_;
  std::vector<EffectParameter> effects_;
  std::vector<CandidateParameter> candidates_;
  std::vector<int> representative_;  // the first run with the same motor path and object
  mutable std::mutex memo_mutex_;
  // Each key's prediction, or the error simulating it gave (rethrown to every caller).
  mutable std::map<std::string, std::shared_future<std::shared_ptr<const RunPrediction>>> memo_;
};

}  // namespace hybrid
