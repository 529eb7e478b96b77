#include "hybrid/model_diagnosis/automaton_diagnosis_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace hybrid {
namespace {

// Memoised simulations kept at most (a bound on memory: each holds one run's samples).
constexpr size_t kMaxMemo = 4096;

bool SameSamples(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (!(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k])))) return false;
  }
  return true;
}

bool SameRunSetup(const TraceRun& a, const TraceRun& b) {
  if (a.time != b.time) return false;
  for (size_t i = 0; i < a.inputs.size(); ++i) {
    if (!SameSamples(a.inputs[i], b.inputs[i])) return false;
  }
  return true;
}

// `points` without the interior points that lie on the line through their neighbours (exactly,
// in floating point): the same piecewise-linear signal with fewer breakpoints, each of which
// stops the integration.
std::vector<std::pair<double, double>> WithoutCollinear(
    const std::vector<std::pair<double, double>>& points) {
  std::vector<std::pair<double, double>> kept;
  for (size_t k = 0; k < points.size(); ++k) {
    if (kept.empty() || k + 1 == points.size()) {
      kept.push_back(points[k]);
      continue;
    }
    const auto [t0, u0] = kept.back();
    const auto [t1, u1] = points[k];
    const auto [t2, u2] = points[k + 1];
    const bool collinear = (u0 == u1 && u1 == u2) || (u1 - u0) * (t2 - t1) == (u2 - u1) * (t1 - t0);
    if (!collinear) kept.push_back(points[k]);
  }
  return kept;
}

// The input signals of one run: piecewise linear through its non-missing samples.
std::vector<InputSignal> Signals(const TraceData& data, const TraceRun& run, const System& s) {
  std::vector<InputSignal> signals;
  for (size_t i = 0; i < data.input_names.size(); ++i) {
    InputSignal signal;
    signal.slot = *s.symbols().Find(data.input_names[i]);
    signal.shape = InputSignal::Shape::kLinear;
    for (size_t k = 0; k < run.time.size(); ++k) {
      if (!std::isnan(run.inputs[i][k])) signal.points.emplace_back(run.time[k], run.inputs[i][k]);
    }
    signal.points = WithoutCollinear(signal.points);
    signals.push_back(std::move(signal));
  }
  return signals;
}

std::string MemoKey(int run, const std::vector<std::pair<std::string, double>>& p) {
  std::string key = std::to_string(run);
  char buffer[40];
  for (const auto& [name, v] : p) {
    std::snprintf(buffer, sizeof buffer, "=%.17g;", v);
    key += ":" + name + buffer;
  }
  return key;
}

}  // namespace

AutomatonDiagnosisModel::AutomatonDiagnosisModel(const System& instrumented, const TraceData& data,
                                                 std::vector<ModelEdit> edits)
    : system_(instrumented), simulator_(instrumented), data_(data), edits_(std::move(edits)) {
  for (const ModelEdit& e : edits_) {
    delays_ = delays_ || e.kind == EditKind::kDelay;
    candidates_.push_back(
        CandidateParameter{e.name, e.name, e.lo, e.hi, e.cheap ? 121 : 33, e.cheap});
  }
  const std::vector<std::string>& names = simulator_.variable_names();
  for (const std::string& x : data.observed_names) {
    const auto it = std::find(names.begin(), names.end(), x);
    if (it == names.end()) throw std::invalid_argument("the model has no variable '" + x + "'");
    channel_index_.push_back(static_cast<int>(it - names.begin()));
  }
  for (size_t r = 0; r < data.runs.size(); ++r) {
    signals_.push_back(Signals(data, data.runs[r], instrumented));
    representative_.push_back(static_cast<int>(r));
    for (size_t s = 0; s < r; ++s) {
      if (SameRunSetup(data.runs[r], data.runs[s])) {
        representative_.back() = static_cast<int>(s);
        break;
      }
    }
  }
}

std::vector<DiagnosisRun> AutomatonDiagnosisModel::Runs() const {
  std::vector<DiagnosisRun> runs;
  for (const TraceRun& run : data_.runs)
    runs.push_back(DiagnosisRun{run.label, run.time, run.observed});
  return runs;
}

RunPrediction AutomatonDiagnosisModel::Simulated(
    int run, const std::vector<std::pair<std::string, double>>& parameters) const {
  const TraceRun& trace = data_.runs[run];
  SimulationOptions options;
  options.until = trace.time.back() > 0 ? trace.time.back() : 1.0;
  options.sample_times = trace.time;
  options.parameters = parameters;
  // Looser than the simulator's defaults (1e-10, 1e-12) yet far below any measurement noise:
  // the diagnosis simulates each run some hundreds of times.
  options.relative_tolerance = 1e-8;
  options.absolute_tolerance = 1e-10;
  if (delays_) {
    // Every jump of a delayed transition is two (into its pending mode and out): the same runs
    // of the model as given need twice the events at one instant and in the Zeno window.
    options.zeno_events *= 2;
    options.max_event_iterations *= 2;
  }
  const SimulationResult result = simulator_.Run(options, signals_[run]);
  if (result.status != SimulationStatus::kCompleted) {
    throw std::invalid_argument("the model stopped on run '" + trace.label +
                                "': " + result.message);
  }
  RunPrediction p;
  p.channels.assign(channel_index_.size(), {});
  for (const StateSample& s : result.samples) {
    if (!s.modes.empty()) p.visited.push_back(s.modes[0]);
    if (s.kind != StateSample::Kind::kSample) continue;
    for (size_t c = 0; c < channel_index_.size(); ++c)
      p.channels[c].push_back(s.x[channel_index_[c]]);
    p.mode.push_back(s.modes.empty() ? -1 : s.modes[0]);
  }
  if (p.mode.size() != trace.time.size()) {
    throw std::logic_error("the simulation of run '" + trace.label +
                           "' did not record one state per sample");
  }
  p.direction.assign(trace.time.size(), 1);
  std::sort(p.visited.begin(), p.visited.end());
  p.visited.erase(std::unique(p.visited.begin(), p.visited.end()), p.visited.end());
  return p;
}

RunPrediction AutomatonDiagnosisModel::Predict(int run, const ParameterValues& values) const {
  std::vector<std::pair<std::string, double>> dynamic;
  std::vector<double> bias(channel_index_.size(), 0.0), gain(channel_index_.size(), 1.0);
  for (const auto& [index, v] : values) {
    const ModelEdit& e = edits_.at(index);
    if (e.cheap) {
      const auto it =
          std::find(data_.observed_names.begin(), data_.observed_names.end(), e.variable);
      const size_t c = it - data_.observed_names.begin();
      if (c < bias.size()) (e.kind == EditKind::kSensorBias ? bias : gain)[c] = v;
      continue;
    }
    std::erase_if(dynamic, [&](const auto& p) { return p.first == e.identifier; });
    dynamic.emplace_back(e.identifier, v);
  }
  std::sort(dynamic.begin(), dynamic.end());
  const int rep = representative_[run];
  const std::string key = MemoKey(rep, dynamic);
  std::shared_ptr<const RunPrediction> simulated;
  {
    std::lock_guard<std::mutex> lock(memo_mutex_);
    const auto it = memo_.find(key);
    if (it != memo_.end()) simulated = it->second;
  }
  if (!simulated) {
    simulated = std::make_shared<const RunPrediction>(Simulated(rep, dynamic));
    std::lock_guard<std::mutex> lock(memo_mutex_);
    if (memo_.size() >= kMaxMemo) memo_.clear();
    memo_.emplace(key, simulated);
  }
  RunPrediction p = *simulated;
  for (size_t c = 0; c < p.channels.size(); ++c) {
    for (double& y : p.channels[c]) y = gain[c] * y + bias[c];
  }
  return p;
}

bool AutomatonDiagnosisModel::Affects(int parameter, int run,
                                      const RunPrediction& reference) const {
  (void)run;
  const ModelEdit& e = edits_.at(parameter);
  std::string mode = e.owner;
  if (e.kind == EditKind::kGuardThreshold || e.kind == EditKind::kDelay) {
    const Automaton& a = system_.components()[0].automaton;
    for (const Transition& t : a.transitions()) {
      if (t.name == e.owner) mode = a.mode(t.source).name;
    }
  } else if (e.kind != EditKind::kFlowGain && e.kind != EditKind::kInvariantThreshold) {
    return true;
  }
  // Every mode the reference visits, also at the instant of a jump (a mode left at the instant
  // it is entered has no sample).
  for (int m : reference.visited.empty() ? reference.mode : reference.visited) {
    if (m >= 0 && ModeName(m) == mode) return true;
  }
  return false;
}

std::string AutomatonDiagnosisModel::ModeName(int mode) const {
  return system_.components()[0].automaton.mode(ModeId(mode)).name;
}

}  // namespace hybrid
