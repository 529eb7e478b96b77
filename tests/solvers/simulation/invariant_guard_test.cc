// Tests of the general guard of every run (solvers/simulation/invariant_guard.h): the first
// recorded state outside its invariant, the states a jump leaves at their own instant, and the
// truncation of a result at an unresolved state.

#include "solvers/simulation/invariant_guard.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr const char* kModel = R"(
automaton a {
  var x;
  input u in [0, 10];
  mode low { x' = 1; inv x <= u; }
  mode high { x' = 0; }
  transition up: low -> high { guard x >= 1; }
  init low { x = 0; }
})";

// A run state of kModel with `u` driven by `points` (a step signal).
struct Fixture {
  explicit Fixture(std::vector<std::pair<double, double>> points = {{0.0, 5.0}})
      : system(ParseModel(kModel, "a.ha")),
        model(system),
        run(model, model.ParameterEnvironment({}),
            {InputSignal{*system.symbols().Find("u"), InputSignal::Shape::kStep, points}},
            options) {
    run.SetModes({0});
  }
  SimulationOptions options;
  System system;
  CompiledModel model;
  RunState run;
};

StateSample Sample(double t, StateSample::Kind kind, int mode, double x) {
  StateSample s;
  s.time = t;
  s.kind = kind;
  s.modes = {mode};
  s.x = Eigen::VectorXd::Constant(1, x);
  return s;
}

using Kind = StateSample::Kind;

TEST(InvariantGuardTest, TheFirstStateOutsideItsInvariant) {
  Fixture f;
  const std::vector<StateSample> samples = {
      Sample(0, Kind::kStart, 0, 0.0), Sample(1, Kind::kSample, 0, 4.0),
      Sample(2, Kind::kSample, 0, 6.0), Sample(3, Kind::kEnd, 0, 7.0)};
  const auto outside = StateOutsideInvariant(f.run, samples, f.model);
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->first, 2u);
  EXPECT_EQ(outside->second,
            "the state recorded at t = 2 lies outside the invariant 'x <= u' of mode low (residual "
            "1): the run is not resolved there");
  // From the final instant of a violation on, states are exempt.
  EXPECT_EQ(StateOutsideInvariant(f.run, samples, f.model, 3.0)->first, 2u);
  EXPECT_FALSE(StateOutsideInvariant(f.run, samples, f.model, 2.0));
  // Within the resolution tolerance (1e-9 + 1e-6 * (|x| + |u|)).
  EXPECT_FALSE(StateOutsideInvariant(f.run, {Sample(1, Kind::kSample, 0, 5.0 + 1e-6)}, f.model));
}

TEST(InvariantGuardTest, AStateEnteredAndLeftAtOneInstantIsExempt) {
  Fixture f;
  // Entered outside at t = 2 by a jump and left at once by another.
  const std::vector<StateSample> entered = {
      Sample(0, Kind::kStart, 1, 6.0), Sample(2, Kind::kBeforeEvent, 1, 6.0),
      Sample(2, Kind::kAfterEvent, 0, 6.0), Sample(2, Kind::kBeforeEvent, 0, 6.0),
      Sample(2, Kind::kAfterEvent, 1, 6.0)};
  EXPECT_FALSE(StateOutsideInvariant(f.run, entered, f.model));
  // Reached outside by the flow and left: not exempt.
  const std::vector<StateSample> flowed = {Sample(0, Kind::kStart, 0, 0.0),
                                           Sample(6, Kind::kBeforeEvent, 0, 6.0),
                                           Sample(6, Kind::kAfterEvent, 1, 6.0)};
  EXPECT_EQ(StateOutsideInvariant(f.run, flowed, f.model)->first, 1u);
}

TEST(InvariantGuardTest, AStatePutOutsideByAnInputJumpAndLeftIsExempt) {
  Fixture f({{0.0, 5.0}, {4.0, 3.0}});  // u drops from 5 to 3 at t = 4
  const std::vector<StateSample> samples = {Sample(0, Kind::kStart, 0, 0.0),
                                            Sample(4, Kind::kBeforeEvent, 0, 4.0),
                                            Sample(4, Kind::kAfterEvent, 1, 4.0)};
  EXPECT_FALSE(StateOutsideInvariant(f.run, samples, f.model));
  // Not left at that instant: outside.
  EXPECT_EQ(StateOutsideInvariant(f.run, {Sample(4, Kind::kSample, 0, 4.0)}, f.model)->first, 0u);
}

TEST(InvariantGuardTest, TruncateUnresolvedKeepsWhatCameBefore) {
  SimulationResult result;
  result.status = SimulationStatus::kZeno;
  result.zeno = ZenoReport{};
  result.samples = {Sample(0, Kind::kStart, 0, 0.0), Sample(1, Kind::kBeforeEvent, 0, 1.0),
                    Sample(1, Kind::kAfterEvent, 1, 1.0), Sample(2, Kind::kSample, 1, 1.0),
                    Sample(3, Kind::kEnd, 1, 1.0)};
  result.events.resize(2);
  result.events[0].time = 1.0;
  result.events[1].time = 2.0;
  TruncateUnresolved(result, 3, "why");
  EXPECT_EQ(result.status, SimulationStatus::kUnresolved);
  EXPECT_EQ(result.message, "why");
  EXPECT_FALSE(result.zeno);
  ASSERT_EQ(result.events.size(), 1u);
  ASSERT_EQ(result.samples.size(), 4u);
  EXPECT_EQ(result.samples[2].kind, Kind::kAfterEvent);
  EXPECT_EQ(result.samples[3].kind, Kind::kEnd);
  EXPECT_EQ(result.samples[3].time, 1.0);
  EXPECT_EQ(result.samples[3].modes, std::vector<int>{1});
}

TEST(InvariantGuardTest, TruncateUnresolvedKeepsTheStart) {
  SimulationResult result;
  result.samples = {Sample(0, Kind::kStart, 0, 9.0), Sample(0, Kind::kBeforeEvent, 0, 9.0),
                    Sample(0, Kind::kAfterEvent, 1, 9.0)};
  TruncateUnresolved(result, 0, "bad start");
  ASSERT_EQ(result.samples.size(), 2u);
  EXPECT_EQ(result.samples[0].kind, Kind::kStart);
  EXPECT_EQ(result.samples[1].kind, Kind::kEnd);
  EXPECT_THROW(TruncateUnresolved(result, 5, "no such state"), InternalError);
}

}  // namespace
}  // namespace hybrid
