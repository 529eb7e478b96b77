#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/diagnosis/diagnosis_model.h"
#include "hybrid/model_diagnosis/model_edit.h"
#include "hybrid/model_diagnosis/trace_data.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// A model of one automaton as the diagnosis engine sees it (DiagnosisModel): the candidate
/// parameters are ModelEdits, a prediction is a simulation of the instrumented model (every
/// dynamic edit declared at its neutral value, compiled once) with the edits' values set per run
/// (SimulationOptions::parameters), sampled at the run's times, driven by the run's inputs
/// (piecewise linear; inputs the trace lacks follow the model's scenario, else 0), the sensor
/// edits applied to the sampled variables (gain, then bias); with delay edits, twice the
/// simulator's Zeno and event-iteration bounds (each jump of a delayed transition is two). Every
/// sample's direction is +1 (the
/// engine's input is time). Simulations of runs that repeat an earlier one (the same times and
/// inputs) and of repeated settings are shared; thread-safe.
class AutomatonDiagnosisModel : public DiagnosisModel {
 public:
  /// `instrumented` (one component, ApplyEdits of the dynamic edits at their neutral values),
  /// `data` and `edits` must outlive the model. Throws std::invalid_argument when a column of
  /// `data` is not a variable or input of `instrumented`.
  AutomatonDiagnosisModel(const System& instrumented, const TraceData& data,
                          std::vector<ModelEdit> edits);

  const std::vector<CandidateParameter>& Parameters() const override { return candidates_; }
  /// Throws std::invalid_argument ("the model stopped on run 'L': ...") when the simulation does
  /// not complete.
  RunPrediction Predict(int run, const ParameterValues& values) const override;
  /// False for a flow gain or invariant threshold of a mode, or a guard threshold of a
  /// transition out of a mode, that `reference` never visits (RunPrediction::visited: also a
  /// mode left at the instant it is entered).
  bool Affects(int parameter, int run, const RunPrediction& reference) const override;
  std::string ModeName(int mode) const override;

  /// The runs as the engine reads them: input = time, one channel per observed variable.
  std::vector<DiagnosisRun> Runs() const;
  /// repeat_of[r]: the first run with run r's times and inputs (r itself if none).
  const std::vector<int>& RepeatOf() const { return representative_; }

 private:
  RunPrediction Simulated(int run, const std::vector<std::pair<std::string, double>>& p) const;

  const System& system_;
  Simulator simulator_;
  const TraceData& data_;
  std::vector<ModelEdit> edits_;
  std::vector<CandidateParameter> candidates_;
  std::vector<int> channel_index_;                 // observed c -> simulator variable
  std::vector<std::vector<InputSignal>> signals_;  // per run
  std::vector<int> representative_;
  bool delays_ = false;  // some edit is a delay (its pending modes double the jumps)
  mutable std::mutex memo_mutex_;
  mutable std::map<std::string, std::shared_ptr<const RunPrediction>> memo_;
};

}  // namespace hybrid
