// Gripper speed: the closed-form query (target: under 20 ns), finding contacts by geometry, the
// quasistatic closing of the whole hand against an object with geometric contact, and the same
// closing simulated as composed automata with distance guards. See docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "benchmarks/bundled_model.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/gripper/geometric_finger.h"
#include "hybrid/gripper/hand.h"
#include "hybrid/simulation/simulator.h"

namespace {

using namespace hybrid::gripper;

// Motor positions to query: 4096 uniform draws in [0, 255], so the branch predictor cannot learn
// the piece of a fixed g.
std::vector<double> QueryPoints() {
  std::mt19937 random(20261121);
  std::uniform_real_distribution<double> g(0.0, 255.0);
  std::vector<double> out(4096);
  for (double& v : out) v = g(random);
  return out;
}

void ClosedFormQuery(benchmark::State& state, const FingerContacts& contacts) {
  const FingerClosedForm f(contacts);
  const std::vector<double> points = QueryPoints();
  size_t i = 0;
  for (auto _ : state) {
    FingerConfiguration q = f.At(points[i++ & 4095]);
    benchmark::DoNotOptimize(q);
  }
  state.counters["pieces"] = static_cast<double>(f.pieces().size());
}

// Free space (5 pieces) and a link-1 then link-2 contact (6 pieces, phase 3 with the rational
// theta3 law).
void BM_ClosedFormQuery_FreeSpace(benchmark::State& state) { ClosedFormQuery(state, {}); }
BENCHMARK(BM_ClosedFormQuery_FreeSpace);
void BM_ClosedFormQuery_Link1And2(benchmark::State& state) {
  FingerContacts c;
  c.gob = {60.0, 120.0, FingerContacts::kNone};
  ClosedFormQuery(state, c);
}
BENCHMARK(BM_ClosedFormQuery_Link1And2);

// The batch kernel behind the Python module's finger_angles: Arg(0) positions per call (the
// output preallocated), reported per position.
void BM_ClosedFormBatch(benchmark::State& state, const FingerContacts& contacts) {
  const FingerClosedForm f(contacts);
  const std::vector<double> pool = QueryPoints();
  std::vector<double> g(static_cast<size_t>(state.range(0)));
  for (size_t i = 0; i < g.size(); ++i) g[i] = pool[i & 4095] * (1.0 - 1e-9 * (i >> 12));
  std::vector<double> theta(3 * g.size());
  for (auto _ : state) {
    f.AnglesAt(g, theta);
    benchmark::DoNotOptimize(theta.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
void BM_ClosedFormBatch_FreeSpace(benchmark::State& state) { BM_ClosedFormBatch(state, {}); }
BENCHMARK(BM_ClosedFormBatch_FreeSpace)->Arg(4096)->Arg(1 << 20);
void BM_ClosedFormBatch_Link1And2(benchmark::State& state) {
  FingerContacts c;
  c.gob = {60.0, 120.0, FingerContacts::kNone};
  BM_ClosedFormBatch(state, c);
}
BENCHMARK(BM_ClosedFormBatch_Link1And2)->Arg(4096)->Arg(1 << 20);

// Building the closed form itself (once per object).
void BM_ClosedFormBuild(benchmark::State& state) {
  FingerContacts c;
  c.gob = {60.0, 120.0, FingerContacts::kNone};
  for (auto _ : state) {
    FingerClosedForm f(c);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_ClosedFormBuild);

// Contacts of one finger with a circle found by geometry (sampling every 0.05 counts + bisection).
void BM_GeometricFinger(benchmark::State& state) {
  for (auto _ : state) {
    GeometricFinger f({Obstacle::Circle({0.06, 0.08}, 0.01)});
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_GeometricFinger)->Unit(benchmark::kMillisecond);

// The whole hand closing on a cylinder (basic mode, one command 255): three geometric fingers plus
// the finger-finger sweep.
void BM_HandClosing(benchmark::State& state) {
  for (auto _ : state) {
    Hand hand({Obstacle::Circle({0.0, 0.06}, 0.02)}, Hand::SpreadPosition(SpreadMode::kBasic),
              {255, 255, 255});
    benchmark::DoNotOptimize(hand);
  }
}
BENCHMARK(BM_HandClosing)->Unit(benchmark::kMillisecond);

// The same closing simulated: three finger automata with distance guards (objects, palm and,
// for link pairs that come within 2 mm, the other fingers) composed with the spread automaton of
// spec/hand.ha, one shared command u = 1 until 255. The Simulator is built once; each iteration
// is one run. Basic mode (no finger touches) and pinch mode (fingers touch each other).
void HandClosingSimulated(benchmark::State& state, double spread) {
  const Hand hand({Obstacle::Circle({0.0, 0.06}, 0.02)}, spread, {255, 255, 255});
  const hybrid::System system = hand.ComposedAutomata(
      hybrid::ParseModelFile(hybrid::benchmarks::BundledModel("hand.ha")), true);
  const hybrid::Simulator simulator(system);
  hybrid::SimulationOptions options;
  options.until = 256.0;
  const hybrid::InputSignal u{
      *system.symbols().Find("u"), hybrid::InputSignal::Shape::kStep, {{0.0, 1.0}, {255.0, 0.0}}};
  const hybrid::SimulationResult check = simulator.Run(options, {&u, 1});
  if (check.status != hybrid::SimulationStatus::kCompleted) {
    state.SkipWithError("the hand closing did not complete");
    return;
  }
  for (auto _ : state) {
    hybrid::SimulationResult r = simulator.Run(options, {&u, 1});
    benchmark::DoNotOptimize(r);
  }
  state.counters["events"] = static_cast<double>(check.events.size());
  state.counters["steps"] = static_cast<double>(check.steps);
  state.counters["touches"] = static_cast<double>(hand.touches().size());
}
void BM_HandClosingSimulated(benchmark::State& state) {
  HandClosingSimulated(state, Hand::SpreadPosition(SpreadMode::kBasic));
}
BENCHMARK(BM_HandClosingSimulated)->Unit(benchmark::kMillisecond);
void BM_HandClosingSimulated_Pinch(benchmark::State& state) {
  HandClosingSimulated(state, Hand::SpreadPosition(SpreadMode::kPinch));
}
BENCHMARK(BM_HandClosingSimulated_Pinch)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
