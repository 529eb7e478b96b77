// Simulation speed: one close-then-open cycle of the finger (spec/finger.ha, its default scenario)
// and 1000 bounces of the bouncing ball (spec/bouncing_ball.ha with e = 0.999, v_rest = 0). The
// Simulator is built once; each iteration is one Simulator::Run with default SimulationOptions.
// `tools/compare_scipy.py` compares the finger cycle with scipy's solve_ivp; see
// docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "benchmarks/bundled_model.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"

namespace {

std::string ReadSpec(const std::string& name) {
  const std::string path = hybrid::benchmarks::BundledModel(name);
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Replaces the one occurrence of `from` in `text`.
std::string ReplaceOnce(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
    throw std::runtime_error("bouncing_ball.ha: expected exactly one '" + from + "'");
  }
  return text.replace(at, from.size(), to);
}

// The finger's default scenario: close at u = 1 until t = 255 (phase changes at 110, 140, 240),
// hold, open at u = -1 from t = 265 (at 265, 365, 395), stop at 505, horizon 530.
void FingerCycle(benchmark::State& state, const hybrid::SimulationOptions& options) {
  const hybrid::System system = hybrid::ParseModel(ReadSpec("finger.ha"), "finger.ha");
  const hybrid::Simulator simulator(system);
  const hybrid::SimulationResult check = simulator.Run(options);
  if (check.status != hybrid::SimulationStatus::kCompleted || check.events.size() != 6) {
    state.SkipWithError("the finger's default scenario did not complete with 6 events");
    return;
  }
  constexpr double kEventTimes[] = {110, 140, 240, 265, 365, 395};  // analytic
  double max_error = 0.0;
  for (size_t i = 0; i < check.events.size(); ++i) {
    max_error = std::max(max_error, std::abs(check.events[i].time - kEventTimes[i]));
  }
  for (auto _ : state) {
    hybrid::SimulationResult result = simulator.Run(options);
    benchmark::DoNotOptimize(result);
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["events"] = static_cast<double>(check.events.size());
  state.counters["steps"] = static_cast<double>(check.steps);
  state.counters["max_event_error"] = max_error;
  state.counters["time_per_event"] =
      benchmark::Counter(iterations * static_cast<double>(check.events.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Default options (the horizon from the scenario): the figure docs/benchmarks.md reports.
void BM_FingerCycle(benchmark::State& state) { FingerCycle(state, {}); }
BENCHMARK(BM_FingerCycle)->Unit(benchmark::kMicrosecond);

// Without the interior-point checks for double crossings: only to show their share of the cost
// (the finger's guards are linear in time, so the events are the same).
void BM_FingerCycle_NoDenseChecks(benchmark::State& state) {
  hybrid::SimulationOptions options;
  options.dense_checks = 0;
  FingerCycle(state, options);
}
BENCHMARK(BM_FingerCycle_NoDenseChecks)->Unit(benchmark::kMicrosecond);

// The bouncing ball from h0 = 10 with e = 0.999 and v_rest = 0: bounce k (k >= 1) is at
// t_k = t1 + 2 t1 e (1 - e^(k-1)) / (1 - e), t1 = sqrt(2 h0 / g). The horizon lies halfway between
// bounces 1000 and 1001, so every run has exactly 1000 events and ends `completed` (the intervals
// shrink geometrically, but the predicted accumulation point stays ~1000 s ahead, far beyond
// zeno_horizon, so Zeno detection does not stop the run).
void BM_BouncingBall1000(benchmark::State& state) {
  constexpr int kBounces = 1000;
  constexpr double kE = 0.999, kH0 = 10.0, kG = 9.81;
  std::string text = ReadSpec("bouncing_ball.ha");
  text = ReplaceOnce(text, "param e = 0.8;", "param e = 0.999;");
  text = ReplaceOnce(text, "param v_rest [m/s] = 0.01;", "param v_rest [m/s] = 0;");
  const hybrid::System system = hybrid::ParseModel(text, "bouncing_ball.ha");
  const hybrid::Simulator simulator(system);
  const double t1 = std::sqrt(2.0 * kH0 / kG);
  auto bounce_time = [&](int k) {
    return t1 + 2.0 * t1 * kE * (1.0 - std::pow(kE, k - 1)) / (1.0 - kE);
  };
  hybrid::SimulationOptions options;  // defaults but the horizon
  options.until = 0.5 * (bounce_time(kBounces) + bounce_time(kBounces + 1));
  const hybrid::SimulationResult check = simulator.Run(options);
  if (check.status != hybrid::SimulationStatus::kCompleted ||
      check.events.size() != static_cast<size_t>(kBounces)) {
    state.SkipWithError(("expected 1000 bounces and completed, got " +
                         std::to_string(check.events.size()) + " events, status " +
                         std::string(hybrid::StatusName(check.status)))
                            .c_str());
    return;
  }
  double max_error = 0.0;  // event times against the closed form
  for (int k = 1; k <= kBounces; ++k) {
    max_error = std::max(max_error, std::abs(check.events[k - 1].time - bounce_time(k)));
  }
  for (auto _ : state) {
    hybrid::SimulationResult result = simulator.Run(options);
    benchmark::DoNotOptimize(result);
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["events"] = kBounces;
  state.counters["steps"] = static_cast<double>(check.steps);
  state.counters["max_event_error"] = max_error;
  state.counters["time_per_event"] = benchmark::Counter(
      iterations * kBounces, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_BouncingBall1000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
