// `hybrid check` on the finger (spec/finger.ha): every declared invariant is proved for all
// inputs and object positions, and deliberately broken copies of the model (mutants) come back
// violated with a trace that the simulator replays and that breaks the property there.

#include <gtest/gtest.h>

#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/properties.h"
#include "tests/test_utilities/trace_states.h"

namespace hybrid {
namespace {

using testing::ReplaceOnce;
using testing::SpecText;

// The text of transition `name` (from `  transition NAME:` to its closing brace).
std::string Block(const std::string& text, const std::string& name) {
  const auto at = text.find("  transition " + name + ":");
  if (at == std::string::npos) throw std::invalid_argument("no transition " + name);
  const auto end = text.find("  }\n", at);
  return text.substr(at, end + 4 - at);
}

using testing::Named;

TEST(FingerVerificationTest, EveryDeclaredInvariantIsProved) {
  const System finger = ParseModel(SpecText("finger"), "finger.ha");
  std::vector<Property> invariants;
  for (const Property& p : finger.properties()) {
    if (p.kind != Property::Kind::kReach) invariants.push_back(p);
  }
  ASSERT_EQ(invariants.size(), 12u);
  const auto results = PropertyProver().Check(finger, invariants);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kProved) << r.property << ": " << r.reason;
    EXPECT_FALSE(r.trace.has_value());
  }
}

TEST(FingerVerificationTest, ClosingFullyIsReachableWithAReplayedWitness) {
  const System finger = ParseModel(SpecText("finger"), "finger.ha");
  const Property& reach = Named(finger, "can_close_fully");
  const auto results = PropertyProver().Check(finger, {&reach, 1});
  ASSERT_EQ(results[0].verdict, Verdict::kReachable) << results[0].reason;
  ASSERT_TRUE(results[0].trace.has_value());
  Trace t = *results[0].trace;
  ASSERT_TRUE(ReplayTrace(finger, reach, t));
  const StateSample& s = t.run.samples[t.state_index];
  EXPECT_NEAR(s.x[0], 70.0, 1e-6);  // theta1 at its limit
  EXPECT_NEAR(s.x[1], 90.0, 1e-6);  // theta2 at its limit
}

struct Mutant {
  const char* name;
  const char* property;  // the property it must violate
  std::string (*mutate)(const std::string&);
};

// Each mutation breaks the model in one of the ways the issue lists.
const Mutant kMutants[] = {
    // A guard with the wrong sign: theta1's limit in phase 1' fires below the limit, so theta1
    // jumps to 70 while the motor is at 110 (the transmission no longer adds up).
    {"wrong_sign_guard", "transmission",
     [](const std::string& text) {
       const std::string b = Block(text, "t3_c000_l00n_to_c000_l10n");
       return ReplaceOnce(text, b, ReplaceOnce(b, "theta1 >= theta1_max", "theta1 <= theta1_max"));
     }},
    // A missing reset: reaching theta2's limit (blocking link 2, against the palm) no longer
    // records where phase 3 starts, so the transmission no longer adds up to g_s.
    {"missing_reset", "transmission",
     [](const std::string& text) {
       const std::string b = Block(text, "t3_c000_l10n_to_c000_l11n");
       return ReplaceOnce(text, b, ReplaceOnce(b, ", theta3_s := theta3, g_s := g", ""));
     }},
    // A dropped transition: nothing stops theta1 at its limit in phase 1'.
    {"dropped_transition", "theta1_range",
     [](const std::string& text) {
       return ReplaceOnce(text, Block(text, "t3_c000_l00n_to_c000_l10n"), "");
     }},
    // A wrong joint limit: link 2 stops at 95 degrees instead of theta2_max = 90.
    {"wrong_joint_limit", "theta2_range",
     [](const std::string& text) {
       const std::string b = Block(text, "t3_c000_l10n_to_c000_l11n");
       return ReplaceOnce(text, b, ReplaceOnce(b, "theta2 >= theta2_max", "theta2 >= 95"));
     }},
};

class FingerMutantTest : public ::testing::TestWithParam<Mutant> {};

TEST_P(FingerMutantTest, ComesBackViolatedWithATraceTheSimulatorReplays) {
  const Mutant& m = GetParam();
  const std::string original = SpecText("finger");
  const std::string text = m.mutate(original);
  ASSERT_NE(text, original);
  const System mutant = ParseModel(text, std::string(m.name) + ".ha");
  const Property& property = Named(mutant, m.property);
  PropertyProver::Options options;
  // Bounded by depth, not by time: every mutant breaks its property within 6 steps.
  options.max_depth = 6;
  options.search_seconds = 600;
  const auto results = PropertyProver(options).Check(mutant, {&property, 1});
  ASSERT_EQ(results[0].verdict, Verdict::kViolated) << results[0].reason;
  ASSERT_TRUE(results[0].trace.has_value());

  // Replay independently: the trace's parameters and inputs on a fresh simulator, and the
  // property evaluated at every recorded state.
  bool violated = false;
  testing::ForEachTraceState(mutant, *results[0].trace, 1000,
                             [&](const Simulator& simulator, const StateSample& s) {
                               violated = violated || IsTarget(simulator, property, s, 1e-6);
                             });
  EXPECT_TRUE(violated) << m.name << ": the trace does not violate " << m.property;
}

INSTANTIATE_TEST_SUITE_P(Mutants, FingerMutantTest, ::testing::ValuesIn(kMutants),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace hybrid
