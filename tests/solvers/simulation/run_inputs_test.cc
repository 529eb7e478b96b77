// Tests of a run's input signals (solvers/simulation/run_inputs.h): the scenario's merged with the
// caller's, their checks against the model, and the breakpoints at which integration restarts.

#include "solvers/simulation/run_inputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr const char* kModel = R"(
automaton a {
  var x;
  input u in [-1, 1];
  input w in [-1, 1];
  input v in [1, 2];
  mode m { x' = u + v + w; }
  init m { x = 0; }
  scenario { until 10; u = step(0: 0, 2: 1); v = step(0: 1); }
})";

// The message ValidateInputs throws for `inputs`, or "".
std::string Refusal(const System& system, const std::vector<InputSignal>& inputs) {
  try {
    ValidateInputs(system, inputs);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(RunInputsTest, TheCallersSignalsOverrideTheScenarios) {
  const System system = ParseModel(kModel, "a.ha");
  const int u = *system.symbols().Find("u");
  const int v = *system.symbols().Find("v");
  const int x = *system.symbols().Find("x");
  EXPECT_EQ(MergedInputs(system, {}), system.scenario()->inputs);
  const InputSignal mine{u, InputSignal::Shape::kLinear, {{0.0, -1.0}, {1.0, 1.0}}};
  const std::vector<InputSignal> merged = MergedInputs(system, std::vector<InputSignal>{mine});
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_EQ(merged[0].slot, v);
  EXPECT_EQ(merged[1], mine);
  for (int slot : {x, -1, 1000}) {
    const std::vector<InputSignal> bad = {{slot, InputSignal::Shape::kStep, {{0.0, 0.0}}}};
    EXPECT_THROW(MergedInputs(system, bad), std::invalid_argument) << slot;
  }
}

TEST(RunInputsTest, SignalsAreCheckedAgainstTheModel) {
  const System system = ParseModel(kModel, "a.ha");
  const int u = *system.symbols().Find("u");
  const int v = *system.symbols().Find("v");
  const InputSignal v1{v, InputSignal::Shape::kStep, {{0.0, 1.5}}};
  EXPECT_EQ(Refusal(system, {v1}), "");
  EXPECT_EQ(Refusal(system, {}), "input 'v' has no signal and 0 lies outside its bounds");
  EXPECT_EQ(Refusal(system, {v1, {u, InputSignal::Shape::kStep, {}}}),
            "signal for 'u' has no points");
  EXPECT_EQ(Refusal(system, {v1, {u, InputSignal::Shape::kStep, {{0.0, std::nan("")}}}}),
            "signal for 'u' has a non-finite point");
  EXPECT_EQ(Refusal(system, {v1, {u, InputSignal::Shape::kStep, {{1.0, 0.0}, {1.0, 0.0}}}}),
            "signal for 'u': times must increase strictly");
  EXPECT_EQ(Refusal(system, {v1, {u, InputSignal::Shape::kStep, {{0.0, 0.0}, {3.0, 2.0}}}}),
            "input 'u' = 2 at t = 3 lies outside its bounds [-1, 1]");
}

TEST(RunInputsTest, BreakpointsAreSortedDistinctAndInsideTheHorizon) {
  const std::vector<InputSignal> inputs = {
      {0, InputSignal::Shape::kStep, {{0.0, 0.0}, {3.0, 1.0}, {12.0, 0.0}}},
      {1, InputSignal::Shape::kLinear, {{1.0, 0.0}, {3.0, 1.0}, {10.0, 1.0}}}};
  const std::vector<ScheduledJump> schedule = {{0.0, "", {}}, {2.5, "", {}}, {10.0, "", {}}};
  EXPECT_EQ(Breakpoints(inputs, 10.0, schedule), (std::vector<double>{1.0, 2.5, 3.0}));
  EXPECT_TRUE(Breakpoints({}, 10.0, {}).empty());
}

}  // namespace
}  // namespace hybrid
