// Tests of the sampling checker (include/hybrid/verification/property_sampler.h): counterexamples
// and witnesses found on small models, shrunk to minimal input schedules, parameter values and
// initial values; true invariants stay unknown; results are repeatable for a seed; misuse throws;
// and a broken copy of the finger model (spec/finger.ha) is caught.

#include "hybrid/verification/property_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/properties.h"
#include "tests/test_utilities/trace_states.h"

namespace hybrid {
namespace {

using testing::ReplaceOnce;
using testing::SpecText;

// x' = u with u in [-1, 1] from x = 0: |x(t)| <= t.
constexpr std::string_view kRampModel = R"(
automaton ramp {
  var x;
  input u in [-1, 1];
  mode run { x' = u; }
  init run { x = 0; }
  scenario { until 10; }
  property below_5: always x <= 5;
  property bounded: always x >= -10.5 and x <= 10.5;
  property gets_to_4: reach x >= 4;
  property quick_to_1_5: reach x >= 1.5 within 2;
  property quick_to_2_5: reach x >= 2.5 within 2;
}
)";

// `armed` is entered at x = 3; coming back to x <= 1 there needs u > 0 and then u < 0.
constexpr std::string_view kReversalModel = R"(
automaton reversal {
  var x;
  input u in [-1, 1];
  mode up { x' = u; }
  mode armed { x' = u; }
  transition arm: up -> armed { guard x >= 3; }
  init up { x = 0; }
  scenario { until 10; }
  property no_return: never in armed and x <= 1;
}
)";

// An uncertain bound: the nominal c = 5 is already exceeded at full speed.
constexpr std::string_view kParameterModel = R"(
automaton uncertain_bound {
  param c = 5 in [0, 10];
  var x;
  input u in [-1, 1];
  mode run { x' = u; }
  init run { x = 0; }
  scenario { until 10; }
  property below_c: always x <= c;
}
)";

// x >= 10.5 within 10 s needs u = 1 throughout and x(0) > 0.5.
constexpr std::string_view kIntervalInitModel = R"(
automaton drift {
  var x;
  input u in [-1, 1];
  mode run { x' = u; }
  init run { x in [-1, 1]; }
  scenario { until 10; }
  property below: never x >= 10.5;
}
)";

// No input, no uncertain parameter, a point initial state: one run decides.
constexpr std::string_view kClockModel = R"(
automaton clock {
  var x;
  mode run { x' = 1; }
  init run { x = 0; }
  scenario { until 3; }
  property small: always x <= 2;
  property far: reach x >= 5;
}
)";

// The invariant x >= 0 rejects initial values below 0: those draws are skipped.
constexpr std::string_view kPartlyRejectedModel = R"(
automaton half_box {
  var x;
  mode run { x' = 0; inv x >= 0; }
  init run { x in [-1, 1]; }
  scenario { until 1; }
  property small: always x <= 0.9;
}
)";

// Every initial value violates the invariant: no run is possible.
constexpr std::string_view kAllRejectedModel = R"(
automaton outside {
  var x;
  mode run { x' = 0; inv x >= 0; }
  init run { x in [-2, -1]; }
  scenario { until 1; }
  property small: always x <= 0.9;
}
)";

System Parse(std::string_view text) { return ParseModel(text, "test.ha"); }

using testing::Named;

// The value of variable `name` at the trace's target state.
double AtTarget(const System& system, const Trace& trace, const std::string& name) {
  const Simulator sim(system);
  const auto& names = sim.variable_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument("no variable " + name);
  return trace.run.samples.at(trace.state_index).x[static_cast<int>(it - names.begin())];
}

// The step values of the (only) input of a trace.
std::vector<double> InputValues(const Trace& trace) {
  EXPECT_EQ(trace.inputs.inputs.size(), 1u);
  std::vector<double> values;
  for (const auto& [t, v] : trace.inputs.inputs.at(0).points) values.push_back(v);
  return values;
}

// Replays a copy of the result's trace: it must hit again, at the same state.
void ExpectReplays(const System& system, const Property& property, const CheckResult& result) {
  ASSERT_TRUE(result.trace.has_value());
  Trace copy = *result.trace;
  copy.run = {};
  copy.state_index = -1;
  EXPECT_TRUE(ReplayTrace(system, property, copy));
  EXPECT_EQ(copy.state_index, result.trace->state_index);
  ASSERT_GE(copy.state_index, 0);
  EXPECT_LT(copy.state_index, static_cast<int>(copy.run.samples.size()));
}

TEST(PropertySamplerTest, FullSpeedViolationShrinksToOnePiece) {
  const System system = Parse(kRampModel);
  const Property& property = Named(system, "below_5");
  const CheckResult result = PropertySampler().Check(system, property);
  EXPECT_EQ(result.verdict, Verdict::kViolated);
  EXPECT_EQ(result.method, "sample");
  EXPECT_EQ(result.property, "below_5");
  EXPECT_EQ(result.kind, Property::Kind::kAlways);
  EXPECT_GE(result.seconds, 0.0);
  EXPECT_NE(result.reason.find("counterexample in run "), std::string::npos) << result.reason;
  ASSERT_TRUE(result.trace.has_value());
  EXPECT_DOUBLE_EQ(result.trace->inputs.until, 10.0);               // the scenario's horizon
  EXPECT_EQ(InputValues(*result.trace), std::vector<double>{1.0});  // full speed, one piece
  EXPECT_GT(AtTarget(system, *result.trace, "x"), 5.0);
  ExpectReplays(system, property, result);
}

TEST(PropertySamplerTest, ReversalNeedsExactlyTwoPieces) {
  const System system = Parse(kReversalModel);
  const Property& property = Named(system, "no_return");
  const CheckResult result = PropertySampler().Check(system, property);
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  const std::vector<double> values = InputValues(*result.trace);
  ASSERT_EQ(values.size(), 2u) << result.reason;
  EXPECT_GT(values[0], 0.0);
  EXPECT_LT(values[1], 0.0);
  // Shrinking pushes the values to the ends of the bounds (a reversal at full speed).
  EXPECT_EQ(values, (std::vector<double>{1.0, -1.0}));
  // ... and the durations to equal pieces: up for 5, down for 5.
  EXPECT_DOUBLE_EQ(result.trace->inputs.inputs[0].points[1].first, 5.0);
  EXPECT_LE(AtTarget(system, *result.trace, "x"), 1.0);
  ExpectReplays(system, property, result);
}

TEST(PropertySamplerTest, ReachIsFoundAsReachableWithinItsHorizon) {
  const System system = Parse(kRampModel);
  const PropertySampler sampler;
  const CheckResult far = sampler.Check(system, Named(system, "gets_to_4"));
  EXPECT_EQ(far.verdict, Verdict::kReachable) << far.reason;
  EXPECT_NE(far.reason.find("witness in run "), std::string::npos) << far.reason;
  EXPECT_GE(AtTarget(system, *far.trace, "x"), 4.0);
  ExpectReplays(system, Named(system, "gets_to_4"), far);

  // `within 2` is the default horizon: x = 1.5 is reachable by then, x = 2.5 is not.
  const CheckResult quick = sampler.Check(system, Named(system, "quick_to_1_5"));
  EXPECT_EQ(quick.verdict, Verdict::kReachable) << quick.reason;
  EXPECT_DOUBLE_EQ(quick.trace->inputs.until, 2.0);
  const CheckResult too_far = sampler.Check(system, Named(system, "quick_to_2_5"));
  EXPECT_EQ(too_far.verdict, Verdict::kUnknown);
  EXPECT_FALSE(too_far.trace.has_value());
  EXPECT_EQ(too_far.reason, "no witness in 200 sampled runs (sampling never proves)");
}

TEST(PropertySamplerTest, TrueInvariantIsUnknownNeverProved) {
  const System system = Parse(kRampModel);
  PropertySampler::Options options;
  options.runs = 100;
  const CheckResult result = PropertySampler(options).Check(system, Named(system, "bounded"));
  EXPECT_EQ(result.verdict, Verdict::kUnknown);
  EXPECT_EQ(result.method, "sample");
  EXPECT_FALSE(result.trace.has_value());
  EXPECT_EQ(result.reason, "no counterexample in 100 sampled runs (sampling never proves)");
}

TEST(PropertySamplerTest, UncertainParameterIsReportedAndShrunkToItsNominalValue) {
  const System system = Parse(kParameterModel);
  const Property& property = Named(system, "below_c");
  const CheckResult result = PropertySampler().Check(system, property);
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  ASSERT_EQ(result.trace->parameters.size(), 1u);
  EXPECT_EQ(result.trace->parameters[0].first, "c");
  // Full speed exceeds the nominal bound, so the counterexample keeps c at 5.
  EXPECT_DOUBLE_EQ(result.trace->parameters[0].second, 5.0);
  EXPECT_GT(AtTarget(system, *result.trace, "x"), 5.0);
  EXPECT_EQ(InputValues(*result.trace), std::vector<double>{1.0});
  ExpectReplays(system, property, result);
}

TEST(PropertySamplerTest, EveryInitDeclarationIsSampledAndNamed) {
  // Only a start from the second declaration, high in its box, reaches x > 9.6.
  const System system = Parse(R"(
automaton two_starts {
  var x;
  mode up { x' = 0; }
  mode down { x' = -1; }
  init up { x = 0; }
  init down { x in [9, 10]; }
  scenario { until 1; }
  property low: always x <= 9.6;
})");
  const Property& property = Named(system, "low");
  const CheckResult result = PropertySampler().Check(system, property);
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  EXPECT_EQ(result.trace->initial_states, (std::vector<std::pair<int, int>>{{0, 1}}));
  ASSERT_EQ(result.trace->initial_values.size(), 1u);
  EXPECT_DOUBLE_EQ(result.trace->initial_values[0].second, 10.0);  // shrunk to the end
  ExpectReplays(system, property, result);
}

TEST(PropertySamplerTest, IntervalInitialValueIsSampledAndShrunkToTheEndThatMatters) {
  const System system = Parse(kIntervalInitModel);
  const Property& property = Named(system, "below");
  const CheckResult result = PropertySampler().Check(system, property);
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  ASSERT_EQ(result.trace->initial_values.size(), 1u);
  EXPECT_EQ(result.trace->initial_values[0].first, "x");
  // The midpoint 0 cannot reach 10.5 in 10 s; the upper end can.
  EXPECT_DOUBLE_EQ(result.trace->initial_values[0].second, 1.0);
  EXPECT_EQ(InputValues(*result.trace), std::vector<double>{1.0});
  ExpectReplays(system, property, result);
}

TEST(PropertySamplerTest, SameSeedSameResult) {
  const System system = Parse(kReversalModel);
  const Property& property = Named(system, "no_return");
  PropertySampler::Options options;
  options.seed = 7;
  const CheckResult a = PropertySampler(options).Check(system, property);
  const CheckResult b = PropertySampler(options).Check(system, property);
  ASSERT_EQ(a.verdict, Verdict::kViolated);
  EXPECT_EQ(a.verdict, b.verdict);
  EXPECT_EQ(a.reason, b.reason);
  ASSERT_TRUE(b.trace.has_value());
  EXPECT_EQ(a.trace->inputs, b.trace->inputs);
  EXPECT_EQ(a.trace->parameters, b.trace->parameters);
  EXPECT_EQ(a.trace->initial_values, b.trace->initial_values);
  EXPECT_EQ(a.trace->state_index, b.trace->state_index);

  // Another seed finds a counterexample too, and shrinks it to the same minimal form.
  options.seed = 8;
  const CheckResult c = PropertySampler(options).Check(system, property);
  ASSERT_EQ(c.verdict, Verdict::kViolated);
  EXPECT_EQ(InputValues(*c.trace).size(), 2u);
}

TEST(PropertySamplerTest, NothingRandomMeansOneRun) {
  const System system = Parse(kClockModel);
  const PropertySampler sampler;
  const CheckResult small = sampler.Check(system, Named(system, "small"));
  EXPECT_EQ(small.verdict, Verdict::kViolated);
  EXPECT_EQ(small.reason, "counterexample in run 1 of 1");
  ASSERT_TRUE(small.trace.has_value());
  EXPECT_TRUE(small.trace->inputs.inputs.empty());
  EXPECT_GT(AtTarget(system, *small.trace, "x"), 2.0);
  ExpectReplays(system, Named(system, "small"), small);

  const CheckResult far = sampler.Check(system, Named(system, "far"));
  EXPECT_EQ(far.verdict, Verdict::kUnknown);
  EXPECT_EQ(far.reason, "no witness in 1 sampled run (sampling never proves)");
}

TEST(PropertySamplerTest, DrawsTheModelRejectsAreSkipped) {
  const System system = Parse(kPartlyRejectedModel);
  const CheckResult result = PropertySampler().Check(system, Named(system, "small"));
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  ASSERT_EQ(result.trace->initial_values.size(), 1u);
  EXPECT_DOUBLE_EQ(result.trace->initial_values[0].second, 1.0);

  const System rejecting = Parse(kAllRejectedModel);
  EXPECT_THROW(PropertySampler().Check(rejecting, Named(rejecting, "small")),
               std::invalid_argument);
}

TEST(PropertySamplerTest, MisuseThrows) {
  PropertySampler::Options options;
  options.runs = 0;
  EXPECT_THROW(PropertySampler{options}, std::invalid_argument);
  options = {};
  options.max_segments = 0;
  EXPECT_THROW(PropertySampler{options}, std::invalid_argument);
  options = {};
  options.horizon = -1.0;
  EXPECT_THROW(PropertySampler{options}, std::invalid_argument);
  options = {};
  options.max_shrink_steps = -1;
  EXPECT_THROW(PropertySampler{options}, std::invalid_argument);
}

// The tank of issue 12 (h from 5 at 0.5 + d per second, d in [-0.2, 0], h <= 8): by hand, h > 6
// after at most 1 / 0.3 s and h = 7 after at most 2 / 0.3 s, whatever the input. The violation
// and the witness come with traces that replay on a fresh simulator.
constexpr std::string_view kTankModel = R"(
automaton tank {
  var h in [0, 10];
  input d in [-0.2, 0];
  mode fill { h' = 0.5 + d; inv h <= 8; }
  init fill { h = 5; }
  scenario { until 10; }
  property stays_below_6: always h <= 6;
  property reaches_7: reach h >= 7;
}
)";

TEST(PropertySamplerTest, TankViolationAndWitnessReplay) {
  const System system = Parse(kTankModel);
  for (const char* name : {"stays_below_6", "reaches_7"}) {
    const Property& property = Named(system, name);
    const CheckResult r = PropertySampler().Check(system, property);
    ASSERT_EQ(r.verdict,
              property.kind == Property::Kind::kReach ? Verdict::kReachable : Verdict::kViolated)
        << name << ": " << r.reason;
    ExpectReplays(system, property, r);
    // Independently: simulate the trace's inputs and find the state by hand.
    bool hit = false;
    testing::ForEachTraceState(system, *r.trace, 1000, [&](const Simulator&, const StateSample& s) {
      hit = hit || (property.kind == Property::Kind::kReach ? s.x[0] >= 7.0 - 1e-6 : s.x[0] > 6.0);
    });
    EXPECT_TRUE(hit) << name;
  }
}

// Misuse messages speak of sampling and the option, not of C++ names.
TEST(PropertySamplerTest, MisuseMessagesHaveNoCppNames) {
  PropertySampler::Options options;
  options.runs = 0;
  try {
    PropertySampler{options};
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("runs must be at least 1"), std::string::npos) << what;
    EXPECT_EQ(what.find("::"), std::string::npos) << what;
    EXPECT_EQ(what.find("PropertySampler"), std::string::npos) << what;
  }
}

TEST(PropertySamplerTest, HorizonOptionOverridesTheScenario) {
  const System system = Parse(kRampModel);
  PropertySampler::Options options;
  options.horizon = 4.0;  // x <= 4 < 5: nothing to find
  options.runs = 50;
  const CheckResult result = PropertySampler(options).Check(system, Named(system, "below_5"));
  EXPECT_EQ(result.verdict, Verdict::kUnknown);
  EXPECT_EQ(result.reason, "no counterexample in 50 sampled runs (sampling never proves)");
}

// The block of `text` that starts with `head` and ends with the first line "  }" after it.
std::pair<std::size_t, std::size_t> Block(const std::string& text, const std::string& head) {
  const std::size_t begin = text.find(head);
  if (begin == std::string::npos || text.find(head, begin + 1) != std::string::npos) {
    throw std::invalid_argument("no single block '" + head + "'");
  }
  const std::size_t end = text.find("\n  }\n", begin);
  if (end == std::string::npos) throw std::invalid_argument("unterminated block '" + head + "'");
  return {begin, end + 5};
}

// spec/finger.ha with theta1's upper limit removed in phase 1' (link 3 at its lower limit): the
// limit transition t3_c000_l00n_to_c000_l10n is dropped (and, should the mode's invariant bound
// theta1 by theta1_max, that bound is widened by 10 degrees), so closing carries theta1 past
// theta1_max. The text is read at test time: the file is generated (tools/generate_finger.py).
std::string FingerWithoutPhase1PrimeTheta1Limit() {
  std::string text = SpecText("finger");
  const auto [t_begin, t_end] = Block(text, "  transition t3_c000_l00n_to_c000_l10n:");
  text.erase(t_begin, t_end - t_begin);
  const auto [m_begin, m_end] = Block(text, "  mode c000_l00n (");
  const std::string mode = text.substr(m_begin, m_end - m_begin);
  if (mode.find("theta1 <= theta1_max") != std::string::npos) {
    text.replace(m_begin, m_end - m_begin,
                 ReplaceOnce(mode, "theta1 <= theta1_max", "theta1 <= theta1_max + 10"));
  }
  return text;
}

TEST(PropertySamplerTest, FingerWithoutTheta1LimitViolatesTheta1Range) {
  const System system = ParseModel(FingerWithoutPhase1PrimeTheta1Limit(), "finger_mutant.ha");
  const Property& property = Named(system, "theta1_range");
  const CheckResult result = PropertySampler().Check(system, property);
  ASSERT_EQ(result.verdict, Verdict::kViolated) << result.reason;
  EXPECT_GT(AtTarget(system, *result.trace, "theta1"), 70.0);
  // Closing at full speed is the minimal counterexample.
  EXPECT_EQ(InputValues(*result.trace), std::vector<double>{1.0}) << result.reason;
  // Uncertain parameters (the contact positions gob1..3, if declared with ranges) do not matter:
  // shrinking leaves them at their nominal values (no contact).
  const std::vector<UncertainParameter> uncertain = UncertainParameters(system);
  ASSERT_EQ(result.trace->parameters.size(), uncertain.size());
  for (std::size_t i = 0; i < uncertain.size(); ++i) {
    EXPECT_EQ(result.trace->parameters[i].first, uncertain[i].name);
    EXPECT_EQ(result.trace->parameters[i].second, uncertain[i].nominal) << uncertain[i].name;
  }
  ExpectReplays(system, property, result);

  // The unmodified model is not caught by this property (its limits hold).
  PropertySampler::Options options;
  options.runs = 20;
  const System original = ParseModel(SpecText("finger"), "finger.ha");
  EXPECT_EQ(PropertySampler(options).Check(original, Named(original, "theta1_range")).verdict,
            Verdict::kUnknown);
}

}  // namespace
}  // namespace hybrid
