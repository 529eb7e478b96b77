// Tests of traces (include/hybrid/checking/trace.h): the uncertain parameters of automata and
// systems; replaying a trace finds the first recorded state that violates (`always`, `never`) or
// satisfies
// (`reach`) a property, within a `within T` horizon, with the documented tolerance; the trace's
// parameter and initial values are applied; misuse throws.

#include "hybrid/checking/trace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/properties.h"

namespace hybrid {
namespace {

// x' = u from x = 0, with properties at the bound 2 of every kind.
constexpr std::string_view kRampModel = R"(
automaton ramp {
  var x;
  input u in [-1, 1];
  mode run { x' = u; }
  init run { x = 0; }
  scenario { until 5; }
  property small: always x <= 2;
  property small_strict: always x < 2;
  property never_3: never x >= 3;
  property gets_to_3: reach x >= 3;
  property small_early: always x <= 2 within 1.5;
  property small_by_4: always x <= 2 within 4;
  property quick_3: reach x >= 3 within 2;
  property small_to_2_002: always x <= 2 within 2.002;
  property small_to_2_006: always x <= 2 within 2.006;
}
)";

// A parameter with a range, one without, and a box of initial values.
constexpr std::string_view kUncertainModel = R"(
automaton tank {
  param k = 2;
  param c = 5 in [0, 10];
  param h = 2 * c in [0, 30];
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  init run { x in [-1, 1]; }
  scenario { until 5; }
  property below_c: always x <= c;
}
)";

constexpr std::string_view kComposedModel = R"(
automaton tank {
  param k = 2;
  param c = 5 in [0, 10];
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  init run { x = 0; }
}
system pair {
  share k;
  instance A = tank;
  instance B = tank;
  property a_below_c: always A.x <= A.c;
  scenario { until 5; }
}
)";

System Parse(std::string_view text) { return ParseModel(text, "test.ha"); }

using testing::Named;

// A trace that holds input `input` at `value` for `until` time units.
Trace ConstantInput(const System& system, const std::string& input, double value, double until) {
  Trace t;
  t.inputs.until = until;
  InputSignal s;
  s.slot = system.symbols().Find(input).value();
  s.shape = InputSignal::Shape::kStep;
  s.points = {{0.0, value}};
  t.inputs.inputs.push_back(s);
  return t;
}

// Value of variable `name` in recorded state `i` of the trace's run.
double ValueAt(const System& system, const Trace& trace, const std::string& name, int i) {
  const Simulator sim(system);
  const auto& names = sim.variable_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument("no variable " + name);
  return trace.run.samples.at(i).x[static_cast<int>(it - names.begin())];
}

TEST(UncertainParameters, ListsRangedParametersWithNominalAndBounds) {
  const System system = Parse(kUncertainModel);
  const std::vector<UncertainParameter> params = UncertainParameters(system);
  ASSERT_EQ(params.size(), 2u);  // k has no range
  EXPECT_EQ(params[0].name, "c");
  EXPECT_EQ(params[0].nominal, 5.0);
  EXPECT_EQ(params[0].lo, 0.0);
  EXPECT_EQ(params[0].hi, 10.0);
  EXPECT_EQ(params[1].name, "h");
  EXPECT_EQ(params[1].nominal, 10.0);
  EXPECT_EQ(params[1].lo, 0.0);
  EXPECT_EQ(params[1].hi, 30.0);
}

TEST(UncertainParameters, NoneWithoutRanges) {
  EXPECT_TRUE(UncertainParameters(Parse(kRampModel)).empty());
}

TEST(UncertainParameters, QualifiedPerInstanceInASystem) {
  const System system = Parse(kComposedModel);
  const std::vector<UncertainParameter> params = UncertainParameters(system);
  ASSERT_EQ(params.size(), 2u);
  EXPECT_EQ(params[0].name, "A.c");
  EXPECT_EQ(params[1].name, "B.c");
  for (const UncertainParameter& p : params) {
    EXPECT_EQ(p.nominal, 5.0);
    EXPECT_EQ(p.lo, 0.0);
    EXPECT_EQ(p.hi, 10.0);
  }
}

TEST(ReplayTrace, FindsTheFirstViolatingState) {
  const System system = Parse(kRampModel);
  Trace trace = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "small"), trace));
  EXPECT_EQ(trace.run.status, SimulationStatus::kCompleted);
  ASSERT_GE(trace.state_index, 0);
  ASSERT_LT(trace.state_index, static_cast<int>(trace.run.samples.size()));
  EXPECT_GT(ValueAt(system, trace, "x", trace.state_index), 2.0 - 1e-6);
  // Clear of the tolerance: the violation is by more than 1e-6.
  EXPECT_GT(ValueAt(system, trace, "x", trace.state_index), 2.0 + 1e-6);
  // Sampled every 5 ms (1e-3 of the horizon): the violation is found within one sample of t = 2.
  EXPECT_NEAR(trace.run.samples[trace.state_index].time, 2.0, 0.006);
  for (int i = 0; i < trace.state_index; ++i) {
    EXPECT_LE(ValueAt(system, trace, "x", i), 2.0 + 1e-6) << "sample " << i;
  }
}

TEST(ReplayTrace, NoViolationForATraceThatStaysBelow) {
  const System system = Parse(kRampModel);
  Trace trace = ConstantInput(system, "u", 0.3, 5.0);  // x(5) = 1.5
  EXPECT_FALSE(ReplayTrace(system, Named(system, "small"), trace));
  EXPECT_EQ(trace.state_index, -1);
  ASSERT_FALSE(trace.run.samples.empty());  // the run is still recorded
  EXPECT_NEAR(ValueAt(system, trace, "x", static_cast<int>(trace.run.samples.size()) - 1), 1.5,
              1e-9);
}

TEST(ReplayTrace, ResetsAPreviousStateIndex) {
  const System system = Parse(kRampModel);
  Trace trace = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "small"), trace));
  trace.inputs.inputs[0].points = {{0.0, 0.1}};
  EXPECT_FALSE(ReplayTrace(system, Named(system, "small"), trace));
  EXPECT_EQ(trace.state_index, -1);
}

TEST(ReplayTrace, NeverTargetsAStateWhereThePredicateHolds) {
  const System system = Parse(kRampModel);
  Trace trace = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "never_3"), trace));
  const int i = trace.state_index;
  EXPECT_GE(ValueAt(system, trace, "x", i), 3.0 + 1e-6);
  for (int j = 0; j < i; ++j) EXPECT_LT(ValueAt(system, trace, "x", j), 3.0 + 1e-6);

  Trace below = ConstantInput(system, "u", 0.5, 5.0);  // x(5) = 2.5
  EXPECT_FALSE(ReplayTrace(system, Named(system, "never_3"), below));
}

TEST(ReplayTrace, ReachTargetsTheFirstWitness) {
  const System system = Parse(kRampModel);
  Trace trace = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "gets_to_3"), trace));
  const int i = trace.state_index;
  // A witness within the tolerance: x >= 3 - 1e-6, found at t = 3 (a sample time).
  EXPECT_GE(ValueAt(system, trace, "x", i), 3.0 - 1e-6);
  EXPECT_NEAR(trace.run.samples[i].time, 3.0, 1e-6);
  for (int j = 0; j < i; ++j) EXPECT_LT(ValueAt(system, trace, "x", j), 3.0 - 1e-6);

  Trace slow = ConstantInput(system, "u", 0.5, 5.0);
  EXPECT_FALSE(ReplayTrace(system, Named(system, "gets_to_3"), slow));
  Trace backwards = ConstantInput(system, "u", -1.0, 5.0);
  EXPECT_FALSE(ReplayTrace(system, Named(system, "gets_to_3"), backwards));
}

TEST(ReplayTrace, WithinHorizonCapsTheStatesConsidered) {
  const System system = Parse(kRampModel);
  // x passes 2 at t = 2: after 1.5, before 4.
  Trace early = ConstantInput(system, "u", 1.0, 5.0);
  EXPECT_FALSE(ReplayTrace(system, Named(system, "small_early"), early));
  EXPECT_EQ(early.state_index, -1);
  Trace late = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "small_by_4"), late));
  EXPECT_LE(late.run.samples[late.state_index].time, 4.0);
  // x reaches 3 at t = 3, after the horizon 2 of quick_3.
  Trace quick = ConstantInput(system, "u", 1.0, 5.0);
  EXPECT_FALSE(ReplayTrace(system, Named(system, "quick_3"), quick));
  // Samples every 5 ms: x = 2 at t = 2 holds, the first violating sample is at t = 2.005,
  // which a horizon of 2.002 excludes and one of 2.006 includes.
  Trace cut = ConstantInput(system, "u", 1.0, 5.0);
  EXPECT_FALSE(ReplayTrace(system, Named(system, "small_to_2_002"), cut));
  Trace kept = ConstantInput(system, "u", 1.0, 5.0);
  ASSERT_TRUE(ReplayTrace(system, Named(system, "small_to_2_006"), kept));
  EXPECT_NEAR(kept.run.samples[kept.state_index].time, 2.005, 1e-9);
}

TEST(ReplayTrace, AppliesParameterAndInitialValues) {
  const System system = Parse(kUncertainModel);
  const Property& below_c = Named(system, "below_c");
  // Nominal c = 5, x from the midpoint 0 at rate 1: stays below c for 5 s.
  Trace nominal = ConstantInput(system, "u", 1.0, 4.9);
  EXPECT_FALSE(ReplayTrace(system, below_c, nominal));
  // c = 2: violated once x > 2.
  Trace low_c = ConstantInput(system, "u", 1.0, 4.9);
  low_c.parameters = {{"c", 2.0}};
  ASSERT_TRUE(ReplayTrace(system, below_c, low_c));
  EXPECT_GT(ValueAt(system, low_c, "x", low_c.state_index), 2.0);
  EXPECT_NEAR(low_c.run.samples[low_c.state_index].time, 2.0, 0.01);
  // x(0) = 1 from the box [-1, 1]: violated at t = 1 instead.
  Trace high_start = low_c;
  high_start.initial_values = {{"x", 1.0}};
  ASSERT_TRUE(ReplayTrace(system, below_c, high_start));
  EXPECT_DOUBLE_EQ(ValueAt(system, high_start, "x", 0), 1.0);
  EXPECT_NEAR(high_start.run.samples[high_start.state_index].time, 1.0, 0.01);
  // The system itself is unchanged.
  Trace again = ConstantInput(system, "u", 1.0, 4.9);
  EXPECT_FALSE(ReplayTrace(system, below_c, again));
}

// Two initial states in different modes with different boxes.
constexpr std::string_view kTwoInitModel = R"(
automaton two {
  var x;
  input u in [0, 1];
  mode a { x' = u; }
  mode b { x' = 2 * u; }
  init a { x in [0, 1]; }
  init b { x in [5, 6]; }
  property small: always x <= 5.5;
}
)";

TEST(ReplayTrace, StartsFromTheChosenInitialState) {
  const System system = Parse(kTwoInitModel);
  const Property& small = Named(system, "small");
  // From the first (mode a, x = 0.5 by default), x stays below 5.5 within 4 s.
  Trace first = ConstantInput(system, "u", 1.0, 4.0);
  EXPECT_FALSE(ReplayTrace(system, small, first));
  // From the second, in mode b, x = 5 + 2t passes 5.5 at t = 0.25.
  Trace second = ConstantInput(system, "u", 1.0, 4.0);
  second.initial_states = {{0, 1}};
  second.initial_values = {{"x", 5.0}};
  ASSERT_TRUE(ReplayTrace(system, small, second));
  EXPECT_NEAR(second.run.samples[second.state_index].time, 0.25, 0.01);
  EXPECT_DOUBLE_EQ(ValueAt(system, second, "x", 0), 5.0);
}

TEST(ReplayTrace, RejectsAStartNoInitialStateAdmits) {
  const System system = Parse(kTwoInitModel);
  const Property& small = Named(system, "small");
  // x = 5 lies in the second init's box, not in the first's, which the trace starts from.
  Trace mixed = ConstantInput(system, "u", 1.0, 4.0);
  mixed.initial_values = {{"x", 5.0}};
  EXPECT_THROW(ReplayTrace(system, small, mixed), std::invalid_argument);
  // A value off the box by rounding only is moved onto it.
  Trace rounded = ConstantInput(system, "u", 0.0, 1.0);
  rounded.initial_values = {{"x", 1.0 + 1e-12}};
  EXPECT_FALSE(ReplayTrace(system, small, rounded));
  EXPECT_DOUBLE_EQ(ValueAt(system, rounded, "x", 0), 1.0);
  // No such initial state or component.
  Trace third = ConstantInput(system, "u", 1.0, 4.0);
  third.initial_states = {{0, 2}};
  EXPECT_THROW(ReplayTrace(system, small, third), std::invalid_argument);
  third.initial_states = {{1, 0}};
  EXPECT_THROW(ReplayTrace(system, small, third), std::invalid_argument);
}

TEST(ReplayTrace, QualifiedNamesInASystem) {
  const System system = Parse(kComposedModel);
  Trace trace = ConstantInput(system, "A.u", 1.0, 5.0);
  trace.parameters = {{"A.c", 3.0}};
  ASSERT_TRUE(ReplayTrace(system, Named(system, "a_below_c"), trace));
  EXPECT_GT(ValueAt(system, trace, "A.x", trace.state_index), 3.0);
  // Driving B does not move A.
  Trace other = ConstantInput(system, "B.u", 1.0, 5.0);
  other.parameters = {{"A.c", 3.0}};
  EXPECT_FALSE(ReplayTrace(system, Named(system, "a_below_c"), other));
}

TEST(IsTarget, BoundaryIsNotACounterexample) {
  const System system = Parse(kRampModel);
  const Simulator sim(system);
  StateSample s;
  s.modes = {0};
  s.x = Eigen::VectorXd::Constant(1, 2.0);
  const Property& small = Named(system, "small");
  EXPECT_FALSE(IsTarget(sim, small, s, 1e-6));
  EXPECT_FALSE(IsTarget(sim, small, s, 0.0));  // x <= 2 holds on its boundary
  s.x[0] = 2.0 + 1e-3;
  EXPECT_TRUE(IsTarget(sim, small, s, 1e-6));
  // Within the tolerance of the boundary: not clear of rounding, not a counterexample.
  s.x[0] = 2.0 + 1e-7;
  EXPECT_FALSE(IsTarget(sim, small, s, 1e-6));
  EXPECT_TRUE(IsTarget(sim, small, s, 0.0));
  // A strict comparison gets the same margin: x = 2 does not clearly break x < 2.
  const Property& strict = Named(system, "small_strict");
  s.x[0] = 2.0;
  EXPECT_FALSE(IsTarget(sim, strict, s, 1e-6));
  EXPECT_TRUE(IsTarget(sim, strict, s, 0.0));
}

TEST(IsTarget, WitnessesAndNeverWithTolerance) {
  const System system = Parse(kRampModel);
  const Simulator sim(system);
  StateSample s;
  s.modes = {0};
  s.x = Eigen::VectorXd::Constant(1, 3.0 - 1e-7);
  // reach x >= 3: lenient, a state within the tolerance is a witness.
  EXPECT_TRUE(IsTarget(sim, Named(system, "gets_to_3"), s, 1e-6));
  EXPECT_FALSE(IsTarget(sim, Named(system, "gets_to_3"), s, 0.0));
  // never x >= 3: strict, the predicate must hold with margin.
  s.x[0] = 3.0;
  EXPECT_FALSE(IsTarget(sim, Named(system, "never_3"), s, 1e-6));
  EXPECT_TRUE(IsTarget(sim, Named(system, "never_3"), s, 0.0));
  s.x[0] = 3.0 + 1e-3;
  EXPECT_TRUE(IsTarget(sim, Named(system, "never_3"), s, 1e-6));
}

TEST(ReplayTrace, MisuseThrows) {
  const System system = Parse(kUncertainModel);
  const Property& below_c = Named(system, "below_c");
  Trace unknown_param = ConstantInput(system, "u", 1.0, 1.0);
  unknown_param.parameters = {{"nope", 1.0}};
  EXPECT_THROW(ReplayTrace(system, below_c, unknown_param), std::invalid_argument);
  Trace unknown_var = ConstantInput(system, "u", 1.0, 1.0);
  unknown_var.initial_values = {{"nope", 1.0}};
  EXPECT_THROW(ReplayTrace(system, below_c, unknown_var), std::invalid_argument);
  Trace out_of_range = ConstantInput(system, "u", 1.0, 1.0);
  out_of_range.parameters = {{"c", 11.0}};
  EXPECT_THROW(ReplayTrace(system, below_c, out_of_range), std::invalid_argument);
  Trace input_out_of_bounds = ConstantInput(system, "u", 2.0, 1.0);
  EXPECT_THROW(ReplayTrace(system, below_c, input_out_of_bounds), std::invalid_argument);
  Trace no_horizon = ConstantInput(system, "u", 1.0, 0.0);
  EXPECT_THROW(ReplayTrace(system, below_c, no_horizon), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
