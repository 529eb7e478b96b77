// `hybrid diagnose` on 10 runs of 512 samples (target: under 2 s). The data are synthesized once
// (the demo's design: 4 free runs, 3 runs against link 1, 3 against link 2) and read back from
// CSV text; each iteration diagnoses them from scratch with a fresh predictor (no cached
// simulators), as the command line does. Cases: clean data (`none`), one cause (backlash 6),
// two causes (backlash 6 and a 2.5 deg theta3 bias: the demo, pairs searched), with one worker
// thread and with two.

#include <benchmark/benchmark.h>

#include <sstream>
#include <string>

#include "benchmarks/bundled_model.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_diagnosis.h"
#include "hybrid/gripper/synthetic_data.h"

namespace {

using namespace hybrid;

Automaton Finger() {
  return ParseModelFile(hybrid::benchmarks::BundledModel("finger.ha")).components()[0].automaton;
}

MeasuredData Data(const HiddenEffects& hidden) {
  const FingerPredictor predictor(Finger());
  SyntheticDesign design;
  design.seed = 7;
  std::ostringstream csv;
  WriteMeasuredData(csv, Synthesize(predictor, hidden, design), {"benchmark"});
  std::istringstream in(csv.str());
  return ReadMeasuredData(in, "benchmark.csv");
}

void Run(benchmark::State& state, const HiddenEffects& hidden) {
  const MeasuredData data = Data(hidden);
  const Automaton finger = Finger();
  FingerDiagnosisOptions options;
  options.threads = static_cast<int>(state.range(0));
  std::string cause;
  for (auto _ : state) {
    const FingerPredictor predictor(finger, FingerPredictor::FastOptions());
    const Diagnosis d = Diagnose(predictor, data, options);
    cause.clear();
    for (const std::string& c : d.cause) cause += c + " ";
    benchmark::DoNotOptimize(d);
  }
  state.SetLabel(cause);
  state.counters["runs"] = static_cast<double>(data.runs.size());
  state.counters["samples"] = static_cast<double>(data.samples());
}

void BM_DiagnoseClean(benchmark::State& state) { Run(state, {}); }

void BM_DiagnoseBacklash(benchmark::State& state) {
  HiddenEffects h;
  h.finger.backlash = 6;
  Run(state, h);
}

void BM_DiagnoseDemo(benchmark::State& state) {
  HiddenEffects h;
  h.finger.backlash = 6;
  h.finger.sensor_bias[2] = 2.5;
  Run(state, h);
}

BENCHMARK(BM_DiagnoseClean)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK(BM_DiagnoseBacklash)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK(BM_DiagnoseDemo)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
