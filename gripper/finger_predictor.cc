#include "hybrid/gripper/finger_predictor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// gob beyond the motor range: no object (spec/finger.ha's parameter range is [0, 256]).
constexpr double kNoObject = 256.0;
constexpr double kMotorMax = 255.0;

// Step-signal points with strictly increasing times: of several points at one time the last
// holds (pieces shorter than the time's rounding vanish), and repeated values are merged.
void Normalize(std::vector<std::pair<double, double>>& points) {
  std::vector<std::pair<double, double>> out;
  for (const auto& pt : points) {
    if (!out.empty() && out.back().first >= pt.first) out.pop_back();
    if (!out.empty() && out.back().second == pt.second) continue;
    out.push_back(pt);
  }
  points = std::move(out);
}

// The timeline of a drive path: time is the path length of the drive, the input u the drive's
// direction on each piece (step points, returned); sets options.sample_times (one per sample)
// and options.until (a second past the last sample, the motor stopped).
std::vector<std::pair<double, double>> DriveTimeline(const std::vector<double>& drive,
                                                     SimulationOptions& options) {
  const size_t n = drive.size();
  options.sample_times.resize(n);
  std::vector<std::pair<double, double>> points;
  // The timeline keeps the drive a hair (1e-9 counts) inside the motor range: the finger's g is
  // integrated along it, and a rounding-level mismatch between the two must not reach g = 0 or
  // 255 moving out before the input stops or reverses there.
  constexpr double kMargin = 1e-9;
  double t = 0.0, q = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double step = std::clamp(drive[k], kMargin, kMotorMax - kMargin) - q;
    if (step != 0.0) {
      const double sign = step > 0 ? 1.0 : -1.0;
      if (points.empty() || points.back().second != sign) points.emplace_back(t, sign);
      t += std::abs(step);
      q += step;
    }
    options.sample_times[k] = t;
  }
  // The motor stops after the last sample (a run that ends at g = 0 or 255, moving out, must not
  // end on the motor range's boundary: an input breakpoint there is decided by the next piece).
  if (points.empty()) points.emplace_back(0.0, 0.0);
  points.front().first = 0.0;
  if (t > 0.0) points.emplace_back(t, 0.0);
  options.until = t + 1.0;
  Normalize(points);
  return points;
}

// Runs `sim` with u following `points`. Where the finger stopped the motor (phase 4) but the
// data's g went on, the finger's g lags the drive and may reach the end of the motor range (0 or
// 255) before the drive turns: the finger then stays there (the extended automaton's
// transmission goes slack) until the drive reverses. Each pass that ends on the range's boundary,
// moving out, stops the input there to the end of that piece (at most 9 passes).
SimulationResult RunToTheRangeEnds(const Simulator& sim, const SimulationOptions& options,
                                   int g_index, std::vector<std::pair<double, double>> points) {
  const int u_slot = *sim.system().symbols().Find("u");
  SimulationResult r;
  for (int pass = 0;; ++pass) {
    const std::vector<InputSignal> signals = {
        InputSignal{u_slot, InputSignal::Shape::kStep, points}};
    r = sim.Run(options, signals);
    if (r.status != SimulationStatus::kInvariantViolated || pass >= 8) break;
    const StateSample& last = r.samples.back();
    const double g_end = last.x[g_index];
    if (!(std::abs(g_end) < 1e-6 || std::abs(g_end - kMotorMax) < 1e-6)) break;
    // Stop the piece that moved out (a hair before the violation: it may be reported at the
    // next breakpoint, within rounding) and keep the pieces after it.
    const double stop = std::max(0.0, last.time - 1e-7);
    const double outward = std::abs(g_end) < 1e-6 ? -1.0 : 1.0;
    size_t i = 0;
    while (i + 1 < points.size() && points[i + 1].first <= stop) ++i;
    if (points[i].second != outward) break;
    if (points[i].first == stop) {
      points[i].second = 0.0;
    } else {
      points.insert(points.begin() + static_cast<long>(i) + 1, {stop, 0.0});
    }
    Normalize(points);
  }
  return r;
}

// Whether the finger's g lags the drive position: it has stalled.
bool IsStall(double drive, double g) {
  // Where the finger's g lags the drive by more than this (counts), it has stalled.
  constexpr double kStallGap = 1e-3;
  return drive - g > kStallGap;
}

// The first sample from `from` on where the finger has stalled, or the sample count when there
// is none (samples the run did not reach are NaN: never a stall).
size_t FirstStall(const FingerPrediction& p, size_t from) {
  size_t k = from;
  while (k < p.drive.size() && !IsStall(p.drive[k], p.model_g[k])) ++k;
  return k;
}

}  // namespace

FingerPredictor::FingerPredictor(Automaton finger) : FingerPredictor(std::move(finger), {}) {}

FingerPredictor::FingerPredictor(Automaton finger, Options options)
    : finger_(std::move(finger)), options_(options) {
  for (const char* name : {"g", "u", "gob1", "gob2", "c1", "c2", "theta3_fraction"}) {
    if (!finger_.symbols().Find(name)) {
      throw std::invalid_argument(std::string("the model has no '") + name +
                                  "' (expected spec/finger.ha's finger)");
    }
  }
  for (const char* name : {"theta1", "theta2", "theta3"}) {
    if (!finger_.symbols().Find(name)) {
      throw std::invalid_argument(std::string("the model has no '") + name + "'");
    }
  }
  if (finger_.initial_states().empty()) {
    throw std::invalid_argument("the model has no initial state");
  }
}

FingerPredictor::~FingerPredictor() = default;

const std::string& FingerPredictor::ModeName(int mode) const { return finger_.modes()[mode].name; }

std::shared_ptr<const FingerPredictor::Entry> FingerPredictor::SimulatorFor(
    const FingerEffects& e) const {
  // One simulator per structure (which links yield: compliance adds flows); the parameter values
  // are set per run (RunParameters).
  const std::string key =
      std::string(e.compliance[0] != 0.0 ? "1" : "0") + (e.compliance[1] != 0.0 ? "1" : "0");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
  }
  FingerEffects structure;
  structure.compliance = e.compliance;
  auto sim = std::make_shared<const Entry>(System::Of(ApplyDynamicEffects(finger_, structure)));
  std::lock_guard<std::mutex> lock(mutex_);
  return cache_.emplace(key, std::move(sim)).first->second;
}

std::vector<std::pair<std::string, double>> FingerPredictor::RunParameters(const MeasuredRun& run,
                                                                           const FingerEffects& e) {
  CheckDynamicEffects(e);
  std::vector<std::pair<std::string, double>> values;
  static constexpr std::array<const char*, 3> kMax = {"theta1_max", "theta2_max", "theta3_max"};
  for (int j = 0; j < 3; ++j) {
    if (e.joint_max[j]) values.emplace_back(kMax[j], *e.joint_max[j]);
  }
  if (e.theta3_fraction) values.emplace_back("theta3_fraction", *e.theta3_fraction);
  for (int i = 0; i < 2; ++i) {
    if (e.compliance[i] != 0.0) {
      values.emplace_back("compliance_link" + std::to_string(i + 1), e.compliance[i]);
    }
  }
  if (run.gob && run.contact_link) {
    values.emplace_back("gob" + std::to_string(*run.contact_link),
                        std::clamp(*run.gob - e.motor_offset, 0.0, kNoObject));
  }
  return values;
}

std::vector<double> MotorPositions(std::span<const double> requests,
                                   std::span<const ControllerStop> stops) {
  std::vector<double> motor(requests.size());
  bool holding = false;  // the motor held at `held` (a bool beside it: any value may be a stop)
  double held = 0.0;
  size_t next = 0;
  for (size_t k = 0; k < requests.size(); ++k) {
    while (next < stops.size() && stops[next].index <= k) {
      if (stops[next].index == k) holding = true, held = stops[next].motor;
      ++next;
    }
    if (holding && requests[k] < held) holding = false;  // a more open request: follow it
    motor[k] = holding ? held : requests[k];
  }
  return motor;
}

FingerPrediction FingerPredictor::Predict(const MeasuredRun& run, const FingerEffects& e) const {
  constexpr int kMaxPasses = 16;
  std::vector<ControllerStop> stops;
  FingerPrediction p;
  for (int pass = 0;; ++pass) {
    const size_t from = stops.empty() ? 0 : stops.back().index + 1;
    // Each pass but the last ends at its first stall (nothing after it is used).
    const std::optional<size_t> stall_from =
        pass + 1 < kMaxPasses ? std::optional<size_t>(from) : std::nullopt;
    p = PredictAlong(run, e, MotorPositions(run.g, stops), stall_from);
    if (p.status != SimulationStatus::kStopped) break;
    // The motor stopped where the engaged transmission (q = p - offset) put the finger's g.
    const size_t k = FirstStall(p, from);
    stops.push_back({k, std::clamp(p.model_g[k] + e.motor_offset, 0.0, kMotorMax)});
  }
  return p;
}

FingerPrediction FingerPredictor::PredictAlong(const MeasuredRun& run, const FingerEffects& e,
                                               std::vector<double> motor,
                                               std::optional<size_t> stall_from) const {
  const size_t n = run.g.size();
  FingerPrediction p;
  p.drive = DrivePositions(motor, e.backlash, e.motor_offset);
  p.motor = std::move(motor);
  for (auto& v : p.theta) v.assign(n, kNaN);
  p.mode.assign(n, -1);
  p.direction.assign(n, 1);
  for (size_t k = 0; k < n; ++k) {
    const double before = k == 0 ? 0.0 : p.motor[k - 1];
    const double step = p.motor[k] - before;
    p.direction[k] = step > 0 ? 1 : step < 0 ? -1 : (k == 0 ? 1 : p.direction[k - 1]);
  }
  SimulationOptions options;
  options.relative_tolerance = options_.relative_tolerance;
  options.absolute_tolerance = options_.absolute_tolerance;
  options.dense_checks = options_.dense_checks;
  options.interpolate_samples = options_.interpolate_samples;
  options.fixed_point_iteration = options_.fixed_point_iteration;
  options.parameters = RunParameters(run, e);
  std::vector<std::pair<double, double>> points = DriveTimeline(p.drive, options);
  const std::shared_ptr<const Entry> entry = SimulatorFor(e);
  const Simulator* sim = &entry->simulator;
  const int g_index =
      static_cast<int>(std::find(sim->variable_names().begin(), sim->variable_names().end(), "g") -
                       sim->variable_names().begin());
  if (stall_from) {
    options.monitor = [&p, g_index, from = *stall_from](size_t k, const StateSample& s) {
      return !(k >= from && k < p.drive.size() && IsStall(p.drive[k], s.x[g_index]));
    };
  }
  const SimulationResult r = RunToTheRangeEnds(*sim, options, g_index, std::move(points));
  p.status = r.status;
  p.message = r.message;
  p.model_g.assign(n, kNaN);
  std::array<int, 3> index{};
  const std::vector<std::string>& names = sim->variable_names();
  for (int j = 0; j < 3; ++j) {
    index[j] = static_cast<int>(
        std::find(names.begin(), names.end(), "theta" + std::to_string(j + 1)) - names.begin());
  }
  size_t k = 0;
  for (const StateSample& s : r.samples) {
    if (s.kind != StateSample::Kind::kSample || k >= n) continue;
    for (int j = 0; j < 3; ++j) p.theta[j][k] = s.x[index[j]] + e.sensor_bias[j];
    p.mode[k] = s.modes[0];
    p.model_g[k] = s.x[g_index];
    ++k;
  }
  if (p.status == SimulationStatus::kCompleted && k < n) {
    p.status = SimulationStatus::kSolverFailure;
    p.message = "the simulation recorded fewer samples than the run has";
  }
  return p;
}

std::optional<FingerInitialState> FingerPredictor::StartState(const FingerEffects& e) const {
  MeasuredRun start;
  start.g = {0.0};
  start.theta = {{{kNaN}, {kNaN}, {kNaN}}};
  const double q0 = DrivePositions(start.g, e.backlash, e.motor_offset)[0];
  if (q0 == 0.0) return std::nullopt;
  const std::shared_ptr<const Entry> entry = SimulatorFor(e);
  const Simulator* sim = &entry->simulator;
  SimulationOptions options;
  options.relative_tolerance = options_.relative_tolerance;
  options.absolute_tolerance = options_.absolute_tolerance;
  options.until = q0;
  options.parameters = RunParameters(start, e);
  const int u_slot = *sim->system().symbols().Find("u");
  const std::vector<InputSignal> signals = {
      InputSignal{u_slot, InputSignal::Shape::kStep, {{0.0, 1.0}}}};
  const SimulationResult r = sim->Run(options, signals);
  if (r.status != SimulationStatus::kCompleted) {
    throw std::runtime_error("the finger's start state: " + r.message);
  }
  const StateSample& end = r.samples.back();
  FingerInitialState state;
  state.mode = finger_.modes()[end.modes[0]].name;
  for (size_t i = 0; i < sim->variable_names().size(); ++i) {
    state.values.emplace_back(sim->variable_names()[i], end.x[static_cast<int>(i)]);
  }
  return state;
}

}  // namespace hybrid
