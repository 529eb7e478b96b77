// Tests of the checks before a run (solvers/simulation/option_validation.h and
// ValidateSimulationOptions): the horizon, every setting's range, the sample budget and the listed
// sample times, with messages in the words of the API (never a command-line flag).

#include "solvers/simulation/option_validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The message `f` throws as std::invalid_argument, or "" if it does not throw.
std::string Message(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// The message of ValidateSimulationOptions for `options` with one setting changed by `change`.
std::string Refusal(const std::function<void(SimulationOptions&)>& change, double until = 10.0) {
  SimulationOptions options;
  change(options);
  return Message([&] { ValidateSimulationOptions(options, until); });
}

TEST(OptionValidationTest, TheHorizonComesFromTheOptionsOrTheScenario) {
  const System with = ParseModel(
      "automaton a { var x; mode m { x' = 1; } init m { x = 0; } scenario { until 7; } }", "a.ha");
  const System without =
      ParseModel("automaton a { var x; mode m { x' = 1; } init m { x = 0; } }", "a.ha");
  SimulationOptions options;
  EXPECT_EQ(Horizon(with, options), 7.0);
  options.until = 3.0;
  EXPECT_EQ(Horizon(with, options), 3.0);
  EXPECT_EQ(Horizon(without, options), 3.0);
  EXPECT_EQ(Message([&] { Horizon(without, SimulationOptions{}); }),
            "no horizon: set the horizon `until` or declare a scenario in the model");
}

TEST(OptionValidationTest, MessagesNameTheFieldsNotFlags) {
  EXPECT_EQ(Refusal([](SimulationOptions&) {}, -1.0),
            "the horizon `until` must be positive and finite, got -1");
  EXPECT_EQ(Refusal([](SimulationOptions&) {}, kInf).find("the horizon `until`"), 0u);
  EXPECT_EQ(Refusal([](SimulationOptions& o) { o.sample_step = -0.5; }),
            "the sample step `sample_step` must be finite and >= 0, got -0.5");
  SimulationOptions dense;
  dense.sample_step = 1e-9;
  EXPECT_EQ(Message([&] { ValidateSimulationOptions(dense, 120.0); }),
            "recording the state every sample step `sample_step` = 1e-09 up to the horizon "
            "`until` = 120 would record 1.2e+11 samples, more than the limit of 1000000: give a "
            "larger sample step or a shorter horizon");
}

TEST(OptionValidationTest, EverySettingOutOfItsRangeIsRefused) {
  const double nan = std::nan("");
  const std::vector<std::pair<std::function<void(SimulationOptions&)>, std::string>> cases = {
      {[](SimulationOptions& o) { o.relative_tolerance = 0; }, "the relative tolerance must be"},
      {[](SimulationOptions& o) { o.absolute_tolerance = -1; }, "the absolute tolerance must be"},
      {[&](SimulationOptions& o) { o.event_tolerance = nan; }, "the event tolerance must be"},
      {[](SimulationOptions& o) { o.resolution_tolerance = -1; }, "the resolution tolerance"},
      {[](SimulationOptions& o) { o.max_step = kInf; }, "the largest step must be"},
      {[](SimulationOptions& o) { o.zeno_window = -1; }, "the Zeno window must be"},
      {[](SimulationOptions& o) { o.zeno_horizon = -1; }, "the Zeno horizon must be"},
      {[](SimulationOptions& o) { o.dense_checks = 1001; }, "dense checks must lie in [0, 1000]"},
      {[](SimulationOptions& o) { o.dense_checks = -1; }, "dense checks must lie in [0, 1000]"},
      {[](SimulationOptions& o) { o.max_event_iterations = 0; }, "the event iteration bound"},
      {[](SimulationOptions& o) { o.zeno_events = -1; }, "the Zeno event count must be >= 0"},
      {[](SimulationOptions& o) { o.max_events = -1; }, "the event limit must be >= 0"},
      {[](SimulationOptions& o) { o.max_samples = -1; }, "the sample limit must be >= 0"},
      {[](SimulationOptions& o) { o.max_steps = 0; }, "the step limit must be at least 1"},
      {[](SimulationOptions& o) {
         o.lazy_schedule = {{5.0, "", {}}, {4.0, "", {}}};
       },
       "scheduled jump 2 at t = 4: jump times must be non-decreasing and within [0, 10]"},
      {[](SimulationOptions& o) {
         o.lazy_schedule = {{11.0, "", {}}};
       },
       "scheduled jump 1"},
      {[](SimulationOptions& o) {
         o.sample_times = {1.0, 2.0};
         o.max_samples = 1;
       },
       "recording the state at 2 listed times would record 2 samples, more than the limit of 1"},
  };
  for (const auto& [change, expected] : cases) {
    const std::string message = Refusal(change);
    EXPECT_EQ(message.find(expected), 0u) << message;
    EXPECT_EQ(message.find("--"), std::string::npos) << message;
  }
  EXPECT_EQ(Refusal([](SimulationOptions&) {}), "");
  // The limit itself is allowed.
  EXPECT_EQ(Refusal([](SimulationOptions& o) { o.sample_step = 1e-5; }), "");
}

TEST(OptionValidationTest, ListedSampleTimesAreOrderedAndWithinTheHorizon) {
  SimulationOptions options;
  options.sample_times = {0.0, 1.0, 1.0, 10.0};
  EXPECT_NO_THROW(ValidateSampleTimes(options, 10.0));
  options.sample_times = {0.0, 10.5};
  EXPECT_EQ(Message([&] { ValidateSampleTimes(options, 10.0); }),
            "sample time 10.5 lies outside [0, 10]");
  options.sample_times = {-1.0};
  EXPECT_EQ(Message([&] { ValidateSampleTimes(options, 10.0); }),
            "sample time -1 lies outside [0, 10]");
  options.sample_times = {2.0, 1.0};
  EXPECT_EQ(Message([&] { ValidateSampleTimes(options, 10.0); }), "sample times must not decrease");
}

}  // namespace
}  // namespace hybrid
