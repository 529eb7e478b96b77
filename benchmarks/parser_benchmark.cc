// Parsing models with many unnamed transitions (automaton/parser.cc): the time should grow
// linearly with the number of transitions. Two shapes: every transition between the same two
// modes (default names m_to_n, m_to_n_2, ..., m_to_n_N), and every transition between its own
// pair of modes (default names without numbers). Wall time: the parser runs on a thread of its
// own (stack_thread.h), which the CPU time of the benchmark's thread would not count.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "hybrid/automaton/parser.h"

namespace {

// `count` unnamed transitions `m -> n`.
std::string SamePairModel(int count) {
  std::string text = "automaton many {\n  mode m { }\n  mode n { }\n";
  text.reserve(text.size() + 24 * static_cast<std::size_t>(count) + 32);
  for (int i = 0; i < count; ++i) text += "  transition m -> n { }\n";
  return text + "  init m { }\n}\n";
}

// `count` unnamed transitions, each between its own ordered pair of modes q0, q1, ...
std::string DistinctPairsModel(int count) {
  const int modes = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  std::string text = "automaton many {\n";
  for (int i = 0; i < modes; ++i) text += "  mode q" + std::to_string(i) + " { }\n";
  for (int i = 0; i < count; ++i) {
    text += "  transition q" + std::to_string(i / modes) + " -> q" + std::to_string(i % modes) +
            " { }\n";
  }
  return text + "  init q0 { }\n}\n";
}

void Parse(benchmark::State& state, const std::string& text) {
  for (auto _ : state) {
    hybrid::Automaton a = hybrid::ParseAutomaton(text, "benchmark.ha");
    benchmark::DoNotOptimize(a);
  }
  state.SetComplexityN(state.range(0));
  state.counters["bytes"] = static_cast<double>(text.size());
}

void BM_ParseUnnamedTransitions_SamePair(benchmark::State& state) {
  Parse(state, SamePairModel(static_cast<int>(state.range(0))));
}

void BM_ParseUnnamedTransitions_DistinctPairs(benchmark::State& state) {
  Parse(state, DistinctPairsModel(static_cast<int>(state.range(0))));
}

BENCHMARK(BM_ParseUnnamedTransitions_SamePair)
    ->RangeMultiplier(10)
    ->Range(1000, 100000)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);
BENCHMARK(BM_ParseUnnamedTransitions_DistinctPairs)
    ->RangeMultiplier(10)
    ->Range(1000, 100000)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

}  // namespace

BENCHMARK_MAIN();
