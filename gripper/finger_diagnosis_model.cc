#include "hybrid/gripper/finger_diagnosis_model.h"

#include <cstdio>
#include <functional>
#include <future>
#include <limits>
#include <stdexcept>
#include <utility>

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The range searched for each parameter (docs/diagnosis.md).
std::pair<double, double> SearchRange(const EffectParameter& p) {
  switch (p.cause) {
    case Cause::kBacklash:
      return {0.0, 30.0};
    case Cause::kMotorOffset:
      return {-30.0, 30.0};
    case Cause::kJointRange:
      return p.index == 0   ? std::pair{45.0, 95.0}
             : p.index == 1 ? std::pair{60.0, 120.0}
                            : std::pair{20.0, 66.0};
    case Cause::kSensorBias:
      return {-15.0, 15.0};
    case Cause::kCompliance:
      return {0.0, 0.3};
    case Cause::kTheta3Law:
      return {0.2, 0.85};
  }
  return {0.0, 1.0};
}

bool HasReversal(const MeasuredRun& run) {
  int direction = 0;
  double last = 0.0;
  for (double g : run.g) {
    const int d = g > last ? 1 : g < last ? -1 : 0;
    if (d != 0 && direction != 0 && d != direction) return true;
    if (d != 0) direction = d;
    last = g;
  }
  return false;
}

FingerEffects WithoutBias(FingerEffects e) {
  e.sensor_bias = {0.0, 0.0, 0.0};
  return e;
}

bool NeutralDrive(const FingerEffects& e) {
  return e.backlash == 0.0 && e.motor_offset == 0.0 && e.SameDynamics(FingerEffects{});
}

// The memo key of dynamic effects for representative run `run`.
std::string MemoKey(int run, const FingerEffects& dynamic) {
  std::string key = std::to_string(run) + ":";
  char buffer[40];
  auto add = [&](double v) {
    std::snprintf(buffer, sizeof buffer, "%.17g;", v);
    key += buffer;
  };
  add(dynamic.backlash);
  add(dynamic.motor_offset);
  for (const auto& m : dynamic.joint_max) add(m ? *m : kNaN);
  for (double k : dynamic.compliance) add(k);
  add(dynamic.theta3_fraction ? *dynamic.theta3_fraction : kNaN);
  return key;
}

RunPrediction AsRunPrediction(FingerPrediction p) {
  RunPrediction out;
  for (std::vector<double>& theta : p.theta) out.channels.push_back(std::move(theta));
  out.mode = std::move(p.mode);
  out.direction = std::move(p.direction);
  return out;
}

}  // namespace

FingerDiagnosisModel::FingerDiagnosisModel(const FingerPredictor& predictor,
                                           const MeasuredData& data,
                                           std::vector<FingerPrediction> baseline)
    : predictor_(predictor),
      data_(data),
      baseline_([&] {
        std::vector<RunPrediction> out;
        for (FingerPrediction& p : baseline) out.push_back(AsRunPrediction(std::move(p)));
        return out;
      }()),
      effects_(AllEffectParameters()) {
  for (const EffectParameter& p : effects_) {
    const auto [lo, hi] = SearchRange(p);
    const bool cheap = p.cause == Cause::kSensorBias;
    candidates_.push_back(CandidateParameter{std::string(CauseName(p.cause)), ParameterName(p), lo,
                                             hi, cheap ? 121 : 0, cheap});
  }
  const int runs = static_cast<int>(data.runs.size());
  representative_.resize(runs);
  for (int r = 0; r < runs; ++r) {
    representative_[r] = r;
    for (int s = 0; s < r; ++s) {
      const MeasuredRun &a = data.runs[r], &b = data.runs[s];
      if (a.g == b.g && a.gob == b.gob && a.contact_link == b.contact_link) {
        representative_[r] = s;
        break;
      }
    }
  }
}

FingerEffects FingerDiagnosisModel::Effects(const ParameterValues& values) const {
  FingerEffects e;
  for (const auto& [p, v] : values) SetEffect(e, effects_[p], v);
  return e;
}

std::vector<DiagnosisRun> FingerDiagnosisModel::Runs() const {
  std::vector<DiagnosisRun> runs;
  for (const MeasuredRun& run : data_.runs) {
    runs.push_back(DiagnosisRun{run.label, run.g, {run.theta[0], run.theta[1], run.theta[2]}});
  }
  return runs;
}

FingerPrediction FingerDiagnosisModel::Checked(int r, const FingerEffects& e) const {
  FingerPrediction p = predictor_.Predict(data_.runs[r], e);
  if (p.status != SimulationStatus::kCompleted) {
    throw std::invalid_argument("the model stopped on run '" + data_.runs[r].label +
                                "': " + p.message);
  }
  return p;
}

RunPrediction FingerDiagnosisModel::Memoised(int r, const FingerEffects& dynamic) const {
  const std::string key = MemoKey(representative_[r], dynamic);
  std::promise<std::shared_ptr<const RunPrediction>> promise;
  std::shared_future<std::shared_ptr<const RunPrediction>> entry;
  bool mine = false;
  {
    std::lock_guard<std::mutex> lock(memo_mutex_);
    auto [it, inserted] = memo_.try_emplace(key);
    if (inserted) it->second = promise.get_future().share();
    entry = it->second;
    mine = inserted;
  }
  // The first caller of a key simulates it; callers on other threads meanwhile wait for its
  // result (or its error) instead of simulating it again.
  if (mine) {
    try {
      promise.set_value(std::make_shared<const RunPrediction>(
          AsRunPrediction(Checked(representative_[r], dynamic))));
    } catch (...) {
      promise.set_exception(std::current_exception());
    }
  }
  return *entry.get();
}

RunPrediction FingerDiagnosisModel::Predict(int r, const ParameterValues& values) const {
  if (values.empty()) return baseline_[r];
  const FingerEffects e = Effects(values);
  const FingerEffects dynamic = WithoutBias(e);
  RunPrediction p = NeutralDrive(dynamic) ? baseline_[r] : Memoised(r, dynamic);
  for (int j = 0; j < 3; ++j) {
    for (double& v : p.channels[j]) v += e.sensor_bias[j];
  }
  return p;
}

bool FingerDiagnosisModel::Affects(int parameter, int r, const RunPrediction& reference) const {
  const EffectParameter& p = effects_[parameter];
  const Automaton& a = predictor_.finger();
  auto visits = [&](const std::function<bool(const Mode&)>& f) {
    for (int m : reference.mode) {
      if (m >= 0 && f(a.modes()[m])) return true;
    }
    return false;
  };
  auto value = [&](const Mode& m, const char* name) {
    return m.DiscreteValueOf(*a.symbols().Find(name)).value_or(0);
  };
  switch (p.cause) {
    case Cause::kBacklash:
      return HasReversal(data_.runs[r]);
    case Cause::kCompliance:
      return visits([&](const Mode& m) { return value(m, p.index == 0 ? "c1" : "c2") == 1; });
    case Cause::kTheta3Law:
      return visits([&](const Mode& m) { return value(m, "c2") == 1 || value(m, "l2") == 1; });
    default:
      return true;
  }
}

}  // namespace hybrid
