// Expression evaluation: the compiled IR (CompiledExpression) against the same expression written
// in C++, both reading their operands from the same environment array. Run
// `tools/bench_expression.py` to get the ratios printed from one run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "hybrid/automaton/compiled_expression.h"
#include "hybrid/automaton/parser.h"

namespace {

// Slots: theta3_min, theta3_max, g, u, x, y, m1.
constexpr int kTheta3Min = 0, kTheta3Max = 1, kG = 2, kU = 3, kX = 4, kY = 5, kM1 = 6;

hybrid::Expression Parse(const std::string& rhs) {
  const std::string text =
      "automaton b {\n"
      "  param theta3_min = -55; param theta3_max = 43;\n"
      "  var g; input u in [-1, 1]; var x; var y; param m1 = 0.5;\n"
      "  mode m { x' = " +
      rhs +
      "; }\n"
      "  init m { g = 0; x = 0; y = 0; }\n"
      "}\n";
  return *hybrid::ParseAutomaton(text, "benchmark.ha").modes()[0].FlowOf(kX);
}

std::vector<double> Environment() { return {-55.0, 43.0, 100.0, 1.0, 0.3, 0.7, 0.5}; }

struct Case {
  const char* name;
  const char* rhs;
  double (*native)(const double*);
};

const Case kCases[] = {
    {"finger_m3_flow", "(theta3_min + (theta3_max - theta3_min) / (255 - g)) * u",
     [](const double* e) {
       return (e[kTheta3Min] + (e[kTheta3Max] - e[kTheta3Min]) / (255 - e[kG])) * e[kU];
     }},
    {"linear_flow", "m1 * u", [](const double* e) { return e[kM1] * e[kU]; }},
    {"polynomial", "3 * x^2 - 2 * x * y + y^3 - 4 * x + 1",
     [](const double* e) {
       return 3 * std::pow(e[kX], 2) - 2 * e[kX] * e[kY] + std::pow(e[kY], 3) - 4 * e[kX] + 1;
     }},
    {"trigonometric", "sin(x) * cos(y) + atan2(y, x) - sqrt(x * x + y * y)",
     [](const double* e) {
       return std::sin(e[kX]) * std::cos(e[kY]) + std::atan2(e[kY], e[kX]) -
              std::sqrt(e[kX] * e[kX] + e[kY] * e[kY]);
     }},
};

// Each iteration changes one operand so that nothing can be hoisted out of the loop.
void BM_Compiled(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const hybrid::CompiledExpression compiled(Parse(c.rhs));
  std::vector<double> env = Environment();
  double sum = 0.0;
  for (auto _ : state) {
    env[kX] += 1e-9;
    env[kG] = 100.0 + env[kX];
    sum += compiled.Evaluate(env.data());
    benchmark::DoNotOptimize(sum);
  }
  state.SetLabel(c.name);
}

void BM_Native(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  std::vector<double> env = Environment();
  auto* native = c.native;
  benchmark::DoNotOptimize(native);  // call through a pointer, as the compiled form must
  double sum = 0.0;
  for (auto _ : state) {
    env[kX] += 1e-9;
    env[kG] = 100.0 + env[kX];
    sum += native(env.data());
    benchmark::DoNotOptimize(sum);
  }
  state.SetLabel(c.name);
}

void BM_TreeWalk(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const hybrid::Expression e = Parse(c.rhs);
  std::vector<double> env = Environment();
  double sum = 0.0;
  for (auto _ : state) {
    env[kX] += 1e-9;
    env[kG] = 100.0 + env[kX];
    sum += e.Evaluate(env);
    benchmark::DoNotOptimize(sum);
  }
  state.SetLabel(c.name);
}

BENCHMARK(BM_Compiled)->DenseRange(0, 3);
BENCHMARK(BM_Native)->DenseRange(0, 3);
BENCHMARK(BM_TreeWalk)->DenseRange(0, 3);

}  // namespace

BENCHMARK_MAIN();
