// Tests of the state of one run (solvers/simulation/run_state.h): the root functions of the current
// modes and their directions, exact segments, guards in their closure, invariants, the resolution
// tolerance, recorded states outside their invariants, and the OdeSystem callbacks.

#include "solvers/simulation/run_state.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr const char* kModel = R"(
automaton a {
  discrete level;
  var x;
  var y;
  input u in [-10, 10];
  mode low (level = 1) {
    x' = u;
    y' = 2;
    inv x <= 5 and level == 1;
  }
  mode high (level = 2) {
    x' = -y;
    inv x >= 0;
  }
  transition up: low -> high { guard x > 3 and y >= 1; }
  transition stay: low -> low { guard x == 1; }
  transition down: high -> low { guard x <= 1; }
  init low { x = 0; y = 0; }
})";

// A parsed model, its compiled form and a run state with `signals`.
struct Fixture {
  explicit Fixture(const std::string& text = kModel, std::vector<InputSignal> signals = {})
      : system(ParseModel(text, "test.ha")),
        model(system),
        run(model, model.ParameterEnvironment({}), std::move(signals), options) {}
  int Slot(const std::string& name) const { return *system.symbols().Find(name); }
  // Loads (x, y) at t = 0 after setting the step inputs there.
  void At(double x, double y) {
    const double state[] = {x, y};
    run.SetStepInputs(0.0);
    run.Load(0.0, state);
  }

  SimulationOptions options;
  System system;
  CompiledModel model;
  RunState run;
};

TEST(RunStateTest, RootFunctionsOfTheCurrentModes) {
  Fixture f;
  f.run.SetModes({0});
  // Guards of `up` (x > 3: rising, y >= 1: rising), of `stay` (x == 1: both), then the invariant
  // x <= 5 (leaving it: rising); the equality level == 1 is no root function.
  ASSERT_EQ(f.run.roots().size(), 4u);
  EXPECT_EQ(f.run.directions(), (std::vector<int>{1, 1, 0, 1}));
  EXPECT_FALSE(f.run.roots()[0].invariant);
  EXPECT_EQ(f.run.roots()[1].index, 0);
  EXPECT_EQ(f.run.roots()[1].comparison, 1);
  EXPECT_EQ(f.run.roots()[2].index, 1);
  EXPECT_TRUE(f.run.roots()[3].invariant);
  EXPECT_EQ(f.run.ComparisonOf(f.run.roots()[3]).text, "x <= 5");
  EXPECT_EQ(f.run.env()[f.Slot("level")], 1.0);
  f.run.SetModes({1});
  EXPECT_EQ(f.run.directions(), (std::vector<int>{-1, -1}));  // x <= 1; leaving x >= 0
  EXPECT_EQ(f.run.env()[f.Slot("level")], 2.0);
  EXPECT_EQ(f.run.modes(), (std::vector<int>{1}));
}

TEST(RunStateTest, ModesOutOfRangeAreABug) {
  Fixture f;
  EXPECT_THROW(f.run.SetModes({2}), InternalError);
  EXPECT_THROW(f.run.SetModes({0, 0}), InternalError);
}

TEST(RunStateTest, ExactSegmentsNeedConstantRatesAndSteadyInputs) {
  Fixture f;
  f.run.SetModes({0});
  EXPECT_TRUE(f.run.exact());  // x' = u (a step input), y' = 2, affine root functions
  Eigen::VectorXd rate(2);
  rate << 3.0, 2.0;
  EXPECT_EQ(f.run.Slope(0, rate), 3.0);  // x > 3
  EXPECT_EQ(f.run.Slope(1, rate), 2.0);  // y >= 1
  f.run.SetModes({1});
  EXPECT_FALSE(f.run.exact());  // x' = -y
  Fixture linear(kModel, {InputSignal{*f.system.symbols().Find("u"),
                                      InputSignal::Shape::kLinear,
                                      {{0.0, 0.0}, {1.0, 1.0}}}});
  linear.run.SetModes({0});
  EXPECT_FALSE(linear.run.exact());  // x' = u varies within a segment
}

TEST(RunStateTest, DerivativesAndRootsLoadTheState) {
  const int u = *ParseModel(kModel, "t.ha").symbols().Find("u");
  Fixture f(kModel, {InputSignal{u, InputSignal::Shape::kLinear, {{0.0, 0.0}, {2.0, 4.0}}}});
  f.run.SetModes({0});
  const double x[] = {1.0, 7.0};
  double dxdt[2];
  f.run.Derivatives(1.0, x, dxdt);
  EXPECT_EQ(dxdt[0], 2.0);  // u(1) = 2
  EXPECT_EQ(dxdt[1], 2.0);
  double g[4];
  f.run.Roots(1.0, x, g);
  EXPECT_EQ(g[0], -2.0);  // x - 3
  EXPECT_EQ(g[1], 6.0);   // y - 1
  EXPECT_EQ(g[2], 0.0);   // x - 1
  EXPECT_EQ(g[3], -4.0);  // x - 5
}

TEST(RunStateTest, StepInputsKeepTheirSegmentValue) {
  const int u = *ParseModel(kModel, "t.ha").symbols().Find("u");
  Fixture f(kModel, {InputSignal{u, InputSignal::Shape::kStep, {{0.0, 1.0}, {1.0, 3.0}}}});
  f.run.SetModes({0});
  f.run.SetStepInputs(0.0);
  const double x[] = {0.0, 0.0};
  double dxdt[2];
  f.run.Derivatives(1.0, x, dxdt);  // the step at 1 does not leak into [0, 1]
  EXPECT_EQ(dxdt[0], 1.0);
  f.run.SetStepInputs(1.0);
  f.run.Derivatives(1.0, x, dxdt);
  EXPECT_EQ(dxdt[0], 3.0);
}

TEST(RunStateTest, AModelWithoutVariablesHasOneDummyDerivative) {
  Fixture f(R"(automaton a { mode m { } init m { } })");
  f.run.SetModes({0});
  EXPECT_EQ(f.run.x_size(), 0u);
  const double x[] = {5.0};
  double dxdt[] = {7.0};
  f.run.Derivatives(0.0, x, dxdt);
  EXPECT_EQ(dxdt[0], 0.0);
}

TEST(RunStateTest, GuardsInTheirClosureAndInvariants) {
  Fixture f;
  f.run.SetModes({0});
  f.At(3.0, 1.0);  // x > 3 on its boundary
  EXPECT_FALSE(f.run.GuardHolds(0, 0, false));
  EXPECT_TRUE(f.run.GuardHolds(0, 0, true));
  f.At(3.0 - 1e-10, 1.0);  // within event_tolerance
  EXPECT_TRUE(f.run.GuardHolds(0, 0, true));
  f.At(3.0 - 1e-6, 1.0);
  EXPECT_FALSE(f.run.GuardHolds(0, 0, true));
  EXPECT_FALSE(f.run.ViolatedInvariant());
  f.At(5.0 + 1e-10, 0.0);  // within event_tolerance of x <= 5
  EXPECT_FALSE(f.run.ViolatedInvariant());
  f.At(5.1, 0.0);
  EXPECT_EQ(f.run.ViolatedInvariant(), "x <= 5");
  EXPECT_EQ(f.run.ViolatedInvariantOf(0), "x <= 5");
}

TEST(RunStateTest, ResolutionToleranceScalesWithTheSides) {
  Fixture f;
  f.run.SetModes({0});
  f.At(4.0, 0.0);
  const CompiledComparison& bound = f.run.ComparisonOf(f.run.roots()[3]);  // x <= 5
  EXPECT_DOUBLE_EQ(f.run.ResolutionTolerance(bound), 1e-9 + 1e-6 * (4.0 + 5.0));
  f.At(3.0 + 1e-7, 0.0);
  EXPECT_FALSE(f.run.OffBoundary(0));  // x > 3 within 1e-9 + 1e-6 * 6
  f.At(3.1, 0.0);
  ASSERT_TRUE(f.run.OffBoundary(0));
  EXPECT_NEAR(f.run.OffBoundary(0)->first, 0.1, 1e-12);
}

TEST(RunStateTest, RecordedStatesOutsideTheirInvariants) {
  Fixture f;
  f.run.SetModes({0});
  StateSample s;
  s.modes = {1};  // high: x >= 0
  s.x = Eigen::Vector2d(-1.0, 0.0);
  const auto outside = f.run.OutsideInvariant(s, 0.0);
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->first, "x >= 0");
  EXPECT_EQ(outside->second, -1.0);
  EXPECT_EQ(f.run.modes(), (std::vector<int>{0}));  // the current modes are kept
  s.x = Eigen::Vector2d(-1e-10, 0.0);               // within 1e-9 + 1e-6 * (|x| + 0)
  EXPECT_FALSE(f.run.OutsideInvariant(s, 0.0));
  s.modes = {0, 0};
  EXPECT_THROW(f.run.OutsideInvariant(s, 0.0), InternalError);
}

}  // namespace
}  // namespace hybrid
