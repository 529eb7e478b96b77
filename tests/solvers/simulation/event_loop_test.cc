// Tests of the event loop of one run (solvers/simulation/event_loop.h), driven directly as
// Simulator::Run drives it: the same results as the Simulator, exact segments without CVODE, the
// solver path, event iteration, invariant violations, limits, and the preconditions it asserts.
// The event semantics in full are tested through the Simulator (simulator_test.cc).

#include "solvers/simulation/event_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/parser.h"
#include "solvers/simulation/option_validation.h"
#include "solvers/simulation/run_inputs.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

using testing::kInvariantViolationModel;
using testing::kPingPongModel;
using testing::SpecText;

// A model and one run of it through an EventLoop set up as Simulator::Run sets it up.
struct Loop {
  explicit Loop(std::string_view text, SimulationOptions o = {})
      : options(std::move(o)), system(ParseModel(text, "test.ha")), model(system) {}

  SimulationResult Run() {
    const double until = Horizon(system, options);
    const std::vector<InputSignal> inputs = MergedInputs(system, {});
    RunState run(model, model.ParameterEnvironment(options.parameters), inputs, options);
    const int n = static_cast<int>(model.variable_slots().size());
    Eigen::VectorXd x = Eigen::VectorXd::Zero(std::max(n, 1));
    std::vector<int> modes;
    for (const CompiledComponent& cc : model.components()) {
      modes.push_back(cc.initial_mode);
      for (const auto& [index, value] : cc.initial_values) x[index] = value;
    }
    run.SetStepInputs(0.0);
    run.SetModes(modes);
    run.Load(0.0, x.data());
    EventLoop loop(model, run, options, until, Breakpoints(inputs, until, options.lazy_schedule),
                   x);
    return loop.Simulate();
  }

  SimulationOptions options;
  System system;
  CompiledModel model;
};

// Two results are the same run: statuses, messages, every state and event, exactly.
void ExpectSameRun(const SimulationResult& a, const SimulationResult& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.steps, b.steps);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i) {
    EXPECT_EQ(a.samples[i].time, b.samples[i].time) << i;
    EXPECT_EQ(a.samples[i].modes, b.samples[i].modes) << i;
    EXPECT_EQ(a.samples[i].x, b.samples[i].x) << i;
  }
  ASSERT_EQ(a.events.size(), b.events.size());
  for (size_t i = 0; i < a.events.size(); ++i) {
    EXPECT_EQ(a.events[i].time, b.events[i].time) << i;
    EXPECT_EQ(a.events[i].transitions, b.events[i].transitions) << i;
  }
}

TEST(EventLoopTest, TheSameRunAsTheSimulator) {
  for (const char* name : {"thermostat", "bouncing_ball"}) {
    SimulationOptions options;
    options.sample_step = 0.5;
    Loop loop(SpecText(name), options);
    const Simulator simulator(loop.system);
    ExpectSameRun(loop.Run(), simulator.Run(options));
  }
}

TEST(EventLoopTest, ExactSegmentsNeedNoSolverSteps) {
  Loop loop(R"(
automaton clock {
  var x;
  mode a { x' = 3; }
  mode b { x' = -1; }
  transition go: a -> b { guard x >= 1; }
  init a { x = 0; }
  scenario { until 2; }
})");
  const SimulationResult r = loop.Run();
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  EXPECT_EQ(r.steps, 0);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].time, 1.0 / 3.0);
  EXPECT_EQ(r.events[0].cause, EventRecord::Cause::kCrossing);
  EXPECT_EQ(r.samples.back().kind, StateSample::Kind::kEnd);
  EXPECT_EQ(r.samples.back().time, 2.0);
  EXPECT_NEAR(r.samples.back().x[0], 1.0 - (2.0 - 1.0 / 3.0), 1e-15);
}

TEST(EventLoopTest, TheSolverLocatesACrossing) {
  Loop loop(R"(
automaton decay {
  var x;
  mode a { x' = -x; }
  mode b { x' = 0; }
  transition half: a -> b { guard x <= 0.5; }
  init a { x = 1; }
  scenario { until 2; }
})");
  const SimulationResult r = loop.Run();
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  EXPECT_GT(r.steps, 0);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_NEAR(r.events[0].time, std::log(2.0), 1e-8);
  EXPECT_NEAR(r.events[0].before[0], 0.5, 1e-9);
}

TEST(EventLoopTest, EventIterationThatDoesNotSettleIsZeno) {
  SimulationOptions options;
  options.max_event_iterations = 5;
  Loop loop(kPingPongModel, options);
  const SimulationResult r = loop.Run();
  EXPECT_EQ(r.status, SimulationStatus::kZeno);
  EXPECT_EQ(r.message, "more than 5 jumps at t = 1 (event iteration does not settle)");
  ASSERT_TRUE(r.zeno);
  EXPECT_EQ(r.zeno->accumulation_time, 1.0);
  EXPECT_EQ(r.events.size(), 5u);
}

TEST(EventLoopTest, AnInvariantLeftWithNothingEnabled) {
  Loop loop(kInvariantViolationModel);
  const SimulationResult r = loop.Run();
  EXPECT_EQ(r.status, SimulationStatus::kInvariantViolated);
  EXPECT_EQ(r.message,
            "at t = 1 the state leaves the invariant 'x <= 1' of mode run and no transition is "
            "enabled");
  EXPECT_EQ(r.samples.back().time, 1.0);
}

TEST(EventLoopTest, TheStepAndEventLimits) {
  SimulationOptions steps;
  steps.max_steps = 3;
  Loop decay(R"(
automaton decay { var x; mode a { x' = -x; } init a { x = 1; } scenario { until 100; } })",
             steps);
  const SimulationResult r = decay.Run();
  EXPECT_EQ(r.status, SimulationStatus::kStepLimit);
  EXPECT_EQ(r.message.find("more than 3 integration steps"), 0u) << r.message;
  SimulationOptions events;
  events.max_events = 2;
  Loop ball(SpecText("bouncing_ball"), events);
  const SimulationResult b = ball.Run();
  EXPECT_EQ(b.status, SimulationStatus::kEventLimit);
  EXPECT_EQ(b.message, "more than 2 events");
  EXPECT_EQ(b.events.size(), 2u);
}

TEST(EventLoopTest, ItsPreconditionsAreAsserted) {
  Loop loop(SpecText("bouncing_ball"));
  RunState run(loop.model, loop.model.ParameterEnvironment({}), {}, loop.options);
  // The modes are not set.
  EXPECT_THROW(EventLoop(loop.model, run, loop.options, 1.0, {}, Eigen::VectorXd::Zero(2)),
               InternalError);
  run.SetModes({0});
  // The state has the wrong size.
  EXPECT_THROW(EventLoop(loop.model, run, loop.options, 1.0, {}, Eigen::VectorXd::Zero(3)),
               InternalError);
}

}  // namespace
}  // namespace hybrid
