#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/diagnosis/diagnosis_engine.h"
#include "hybrid/diagnosis/noise_floor.h"
#include "hybrid/model_diagnosis/model_edit.h"
#include "hybrid/model_diagnosis/trace_data.h"

namespace hybrid {

/// The engine's settings for a model of any kind: the search for switching systems on (the
/// horizons 1/4, 1/2 and the whole run, two extra starts; docs/diagnosis.md, "Any model").
DiagnosisOptions AnyModelDiagnosisOptions();

/// Settings of DiagnoseAutomaton.
struct AutomatonDiagnosisOptions {
  DiagnosisOptions engine = AnyModelDiagnosisOptions();
  /// The noise standard deviation of observed variables (by name), in place of the estimate.
  std::map<std::string, double> noise;
};

/// What DiagnoseAutomaton found, in the model's words.
struct AutomatonDiagnosis {
  /// The engine's result; its parameter indices are into `edits`.
  ModelDiagnosis result;
  /// The candidate causes tried, in the engine's order (after those that cannot be set per run
  /// were dropped).
  std::vector<ModelEdit> edits;
  /// Why candidates were left out or dropped (CandidateEdits' notes, parameters the simulator
  /// cannot set per run, the engine's notes).
  std::vector<std::string> notes;
  /// The observed variables (the engine's channels) and the runs as the engine read them.
  std::vector<std::string> channels;
  std::vector<DiagnosisRun> runs;
  /// The noise floor used and how it was found ("repeated runs", "second differences", "given"
  /// or a mix, per channel).
  ChannelNoise noise;
  std::vector<std::string> noise_method;
  /// The named causes' parameters: (ModelEdit::name, fitted value).
  std::vector<std::pair<std::string, double>> named;
  /// The model with the named edits at their fitted values (the model itself for `none` and
  /// `unexplained`).
  System extended{"model"};
};

/// Diagnoses `model` (a System of one component) against its measured trace `data`
/// (ReadTraceData): generates the candidate edits (CandidateEdits), compiles the model with all of
/// them at their neutral values once, estimates the noise floor (EstimateChannelNoise; repeats
/// are runs with the same times and inputs) unless given, and runs DiagnoseModel. Throws
/// std::invalid_argument for a system of several components or when the model cannot predict a
/// run as it is (its simulation does not complete).
AutomatonDiagnosis DiagnoseAutomaton(const System& model, const TraceData& data,
                                     const AutomatonDiagnosisOptions& options = {});

}  // namespace hybrid
