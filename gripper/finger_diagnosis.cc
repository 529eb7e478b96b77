#include "hybrid/gripper/finger_diagnosis.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <utility>

#include "hybrid/diagnosis/parallel_for.h"
#include "hybrid/gripper/finger_diagnosis_model.h"

namespace hybrid {
namespace {

// The model's prediction of every run without effects; throws when one does not complete.
std::vector<FingerPrediction> BaselinePredictions(const FingerPredictor& predictor,
                                                  const MeasuredData& data, int threads) {
  const int runs = static_cast<int>(data.runs.size());
  std::vector<FingerPrediction> base(runs);
  ParallelFor(runs, threads, [&](int r) {
    base[r] = predictor.Predict(data.runs[r], FingerEffects{});
    if (base[r].status != SimulationStatus::kCompleted) {
      throw std::invalid_argument("the model stopped on run '" + data.runs[r].label +
                                  "': " + base[r].message);
    }
  });
  return base;
}

// The report's outlier rule, applied to the residual against the baseline model: "a change in
// sensed angle of more than 5 degrees from one value of g to the next" cannot happen on the
// robot, except where the model itself moves that fast (the phase-3 law near g = 255 does), so
// the rule looks at changes beyond the model's. Cleans `data` in place; the report's entries are
// in measured angles.
OutlierReport CleanAgainstModel(MeasuredData& data, const std::vector<FingerPrediction>& base,
                                double threshold) {
  const int runs = static_cast<int>(data.runs.size());
  MeasuredData residual = data;
  for (int r = 0; r < runs; ++r) {
    for (int j = 0; j < 3; ++j) {
      for (size_t k = 0; k < data.runs[r].g.size(); ++k) {
        residual.runs[r].theta[j][k] -= base[r].theta[j][k];
      }
    }
  }
  OutlierReport report = CleanOutliers(residual, threshold);
  for (int r = 0; r < runs; ++r) {
    for (int j = 0; j < 3; ++j) {
      for (size_t k = 0; k < data.runs[r].g.size(); ++k) {
        data.runs[r].theta[j][k] = residual.runs[r].theta[j][k] + base[r].theta[j][k];
      }
    }
  }
  for (OutlierReport::Entry& e : report.entries) {
    for (int r = 0; r < runs; ++r) {
      const MeasuredRun& run = data.runs[r];
      if (run.label != e.run) continue;
      const auto it = std::find(run.lines.begin(), run.lines.end(), e.line);
      if (it == run.lines.end()) continue;
      const double model = base[r].theta[e.joint - 1][it - run.lines.begin()];
      e.measured += model;
      e.cleaned += model;
    }
  }
  return report;
}

std::array<double, 3> Joints(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

std::array<std::vector<double>, 3> Joints(const std::vector<std::vector<double>>& v) {
  return {v[0], v[1], v[2]};
}

CandidateFit AsCandidateFit(const ParameterFit& f, const FingerDiagnosisModel& model) {
  CandidateFit c;
  for (int p : f.parameters) c.parameters.push_back(model.effect(p));
  c.values = f.values;
  c.heldout_mse = Joints(f.heldout_mse);
  c.heldout_loss = f.heldout_loss;
  c.gain = f.gain;
  c.bic = f.bic;
  c.significant = f.significant;
  return c;
}

// The engine's findings in the finger's terms (joints, g, effect parameters, curves).
void Translate(const ModelDiagnosis& m, const FingerDiagnosisModel& model, const MeasuredData& data,
               Diagnosis& d) {
  d.cause = m.cause;
  for (const auto& [p, v] : m.parameters) d.parameters.emplace_back(model.effect(p), v);
  d.effects = model.Effects(m.parameters);
  d.baseline_mse = Joints(m.baseline_mse);
  d.extended_mse = Joints(m.extended_mse);
  d.residuals = m.residuals;
  d.change_points = m.change_points;
  d.direction_difference = Joints(m.direction_difference);
  d.where = m.where;
  d.explained_fraction = m.explained_fraction;
  d.remainder = m.remainder;
  d.notes = m.notes;
  for (const ParameterFit& f : m.candidates) d.candidates.push_back(AsCandidateFit(f, model));
  for (size_t r = 0; r < data.runs.size(); ++r) {
    d.curves.push_back(RunCurves{data.runs[r].label, data.runs[r].g, data.runs[r].theta,
                                 Joints(m.baseline[r].channels), Joints(m.extended[r].channels)});
  }
}

// The effects of the significant candidate of `m` with the largest gain, if any.
std::optional<FingerEffects> BestCandidate(const ModelDiagnosis& m,
                                           const FingerDiagnosisModel& model) {
  const ParameterFit* best = nullptr;
  for (const ParameterFit& f : m.candidates) {
    if (f.significant && (!best || f.gain > best->gain)) best = &f;
  }
  if (!best) return std::nullopt;
  ParameterValues values;
  for (size_t i = 0; i < best->parameters.size(); ++i) {
    values.emplace_back(best->parameters[i], best->values[i]);
  }
  return model.Effects(values);
}

bool SameSamples(const OutlierReport& a, const OutlierReport& b) {
  if (a.entries.size() != b.entries.size()) return false;
  for (size_t i = 0; i < a.entries.size(); ++i) {
    const OutlierReport::Entry &x = a.entries[i], &y = b.entries[i];
    if (x.run != y.run || x.line != y.line || x.joint != y.joint) return false;
  }
  return true;
}

// One diagnosis of `cleaned` data (`outliers`: what the cleaning changed), and in `best` the
// effects of its best significant candidate.
Diagnosis DiagnoseCleaned(const FingerPredictor& predictor, const MeasuredData& cleaned,
                          std::vector<FingerPrediction> base, OutlierReport outliers,
                          const FingerDiagnosisOptions& options,
                          std::optional<FingerEffects>* best) {
  Diagnosis d;
  d.outliers = std::move(outliers);
  d.noise = EstimateNoiseFloor(cleaned, options.spike_sigmas);  // the engine's outlier rule
  d.samples = cleaned.samples();
  const FingerDiagnosisModel model(predictor, cleaned, std::move(base));
  const ChannelNoise noise{{d.noise.variance.begin(), d.noise.variance.end()},
                           {d.noise.dof.begin(), d.noise.dof.end()}};
  const ModelDiagnosis m = DiagnoseModel(model, model.Runs(), noise, options);
  Translate(m, model, cleaned, d);
  *best = BestCandidate(m, model);
  return d;
}

}  // namespace

Diagnosis Diagnose(const FingerPredictor& predictor, MeasuredData data,
                   const FingerDiagnosisOptions& options) {
  if (data.runs.empty()) throw std::invalid_argument("the data have no runs");
  const std::vector<FingerPrediction> base = BaselinePredictions(predictor, data, options.threads);
  MeasuredData cleaned = data;
  OutlierReport outliers = CleanAgainstModel(cleaned, base, options.outlier_threshold);
  std::optional<FingerEffects> best;
  Diagnosis d = DiagnoseCleaned(predictor, cleaned, base, std::move(outliers), options, &best);
  // Second pass: the rule looks at changes beyond the model's, and where an effect is large the
  // baseline's residual itself changes fast (e.g. a play of 6 counts on reopening from the stop
  // in phase 3), genuine samples are clamped and the diagnosis says `unexplained` though a
  // candidate fits. Then clean the measured data again against the best candidate's prediction,
  // and diagnose again if that changes which samples are outliers.
  if (!best || d.outliers.entries.empty() || d.cause != std::vector<std::string>{"unexplained"}) {
    return d;
  }
  std::vector<FingerPrediction> fitted(data.runs.size());
  ParallelFor(static_cast<int>(data.runs.size()), options.threads,
              [&](int r) { fitted[r] = predictor.Predict(data.runs[r], *best); });
  for (const FingerPrediction& f : fitted) {
    if (f.status != SimulationStatus::kCompleted) return d;
  }
  OutlierReport second = CleanAgainstModel(data, fitted, options.outlier_threshold);
  if (SameSamples(second, d.outliers)) return d;
  return DiagnoseCleaned(predictor, data, base, std::move(second), options, &best);
}

}  // namespace hybrid
