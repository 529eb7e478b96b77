#include "hybrid/model_diagnosis/automaton_diagnosis.h"

#include <algorithm>
#include <stdexcept>

#include "hybrid/model_diagnosis/automaton_diagnosis_model.h"

namespace hybrid {
namespace {

// The edits with every dynamic one at its neutral value (the instrumented model's).
std::vector<std::pair<ModelEdit, double>> Neutral(const std::vector<ModelEdit>& edits) {
  std::vector<std::pair<ModelEdit, double>> neutral;
  for (const ModelEdit& e : edits) {
    if (!e.cheap && e.kind != EditKind::kParameter) neutral.emplace_back(e, e.neutral);
  }
  return neutral;
}

// The edits the simulator can set per run: a model parameter that an initial value reads, or
// that scales a variable in a guard or invariant, is a constant of the compiled model.
std::vector<ModelEdit> Settable(const System& instrumented, std::vector<ModelEdit> edits,
                                std::vector<std::string>& notes) {
  const Simulator simulator(instrumented);
  std::vector<ModelEdit> kept;
  for (ModelEdit& e : edits) {
    if (e.kind == EditKind::kParameter) {
      try {
        const std::pair<std::string, double> p{e.identifier, e.neutral};
        simulator.ParameterEnvironment({&p, 1});
      } catch (const std::invalid_argument& error) {
        notes.push_back("parameter '" + e.name + "' is not a candidate: " + error.what());
        continue;
      }
    }
    kept.push_back(std::move(e));
  }
  return kept;
}

// The noise floor: estimated (repeats, else second differences), then the given values.
void NoiseFloor(const AutomatonDiagnosisModel& model, const AutomatonDiagnosisOptions& options,
                AutomatonDiagnosis& d) {
  d.noise = EstimateChannelNoise(d.runs, model.RepeatOf(), options.engine.spike_sigmas);
  bool repeats = false;
  for (size_t r = 0; r < model.RepeatOf().size(); ++r) {
    repeats = repeats || model.RepeatOf()[r] != static_cast<int>(r);
  }
  for (size_t c = 0; c < d.channels.size(); ++c) {
    d.noise_method.push_back(repeats ? "repeated runs" : "second differences");
    const auto it = options.noise.find(d.channels[c]);
    if (it == options.noise.end()) continue;
    d.noise.variance[c] = it->second * it->second;
    d.noise.dof[c] = 1000000;
    d.noise_method[c] = "given";
  }
  for (const auto& [name, sd] : options.noise) {
    if (std::find(d.channels.begin(), d.channels.end(), name) == d.channels.end()) {
      throw std::invalid_argument("noise given for '" + name + "', which the data do not observe");
    }
    if (!(sd > 0)) throw std::invalid_argument("the noise of '" + name + "' must be positive");
  }
}

}  // namespace

DiagnosisOptions AnyModelDiagnosisOptions() {
  DiagnosisOptions o;
  o.horizons = {0.25, 0.5, 1.0};
  o.extra_starts = 2;
  return o;
}

AutomatonDiagnosis DiagnoseAutomaton(const System& model, const TraceData& data,
                                     const AutomatonDiagnosisOptions& options) {
  if (model.components().size() != 1) {
    throw std::invalid_argument("the model has " + std::to_string(model.components().size()) +
                                " components; diagnosis takes a model of one automaton");
  }
  const Automaton& automaton = model.components()[0].automaton;
  AutomatonDiagnosis d;
  CandidateSet candidates = CandidateEdits(automaton, data);
  d.notes = candidates.notes;
  const System instrumented = System::Of(ApplyEdits(automaton, Neutral(candidates.edits)));
  d.edits = Settable(instrumented, std::move(candidates.edits), d.notes);
  const AutomatonDiagnosisModel diagnosis_model(instrumented, data, d.edits);
  d.channels = data.observed_names;
  d.runs = diagnosis_model.Runs();
  NoiseFloor(diagnosis_model, options, d);
  d.result = DiagnoseModel(diagnosis_model, d.runs, d.noise, options.engine);
  for (std::string note : d.result.notes) {
    // The engine names a candidate as "cause (parameter)"; here both are the edit's name.
    for (const ModelEdit& e : d.edits) {
      const std::string twice = e.name + " (" + e.name + ")";
      if (note.starts_with(twice)) note = e.name + note.substr(twice.size());
    }
    d.notes.push_back(std::move(note));
  }
  std::vector<std::pair<ModelEdit, double>> named;
  for (const auto& [index, value] : d.result.parameters) {
    named.emplace_back(d.edits[index], value);
    d.named.emplace_back(d.edits[index].name, value);
  }
  d.extended = System::Of(ApplyEdits(automaton, named));
  return d;
}

}  // namespace hybrid
