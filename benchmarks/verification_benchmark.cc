// Proof time of every declared invariant (`always`, `never`) of the finger and of the hand, as
// `hybrid check MODEL` proves them (reach queries, whose witnesses are searched by bounded model
// checking, are left out). Each iteration proves everything from scratch; the benchmark fails if
// a property is not proved.

#include <benchmark/benchmark.h>

#include <string>

#include "benchmarks/bundled_model.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/verification/property_prover.h"

namespace {

using hybrid::Property;

void ProveAll(benchmark::State& state, const std::string& model) {
  const hybrid::System system = hybrid::ParseModelFile(hybrid::benchmarks::BundledModel(model));
  std::vector<Property> invariants;
  for (const Property& p : hybrid::DeclaredProperties(system)) {
    if (p.kind != Property::Kind::kReach) invariants.push_back(p);
  }
  for (auto _ : state) {
    const auto results = hybrid::PropertyProver().Check(system, invariants);
    for (const auto& r : results) {
      if (r.verdict != hybrid::Verdict::kProved) {
        state.SkipWithError(("not proved: " + r.property).c_str());
        return;
      }
    }
    benchmark::DoNotOptimize(results);
  }
  state.counters["properties"] = static_cast<double>(invariants.size());
}

void BM_ProveFinger(benchmark::State& state) { ProveAll(state, "finger.ha"); }
void BM_ProveHand(benchmark::State& state) { ProveAll(state, "hand.ha"); }

BENCHMARK(BM_ProveFinger)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_ProveHand)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
