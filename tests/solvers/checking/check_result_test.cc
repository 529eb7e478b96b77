// Tests of the verdict names (include/hybrid/checking/check_result.h): every verdict has its own
// documented name, and a default CheckResult is an undecided `always` property; ConfirmTrace lets a
// `violated` or `reachable` verdict through only with a trace that replays.

#include "hybrid/checking/check_result.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <string_view>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "tests/test_utilities/properties.h"

namespace hybrid {
namespace {

TEST(VerdictName, NamesEveryVerdict) {
  EXPECT_EQ(VerdictName(Verdict::kProved), "proved");
  EXPECT_EQ(VerdictName(Verdict::kViolated), "violated");
  EXPECT_EQ(VerdictName(Verdict::kReachable), "reachable");
  EXPECT_EQ(VerdictName(Verdict::kUnreachable), "unreachable");
  EXPECT_EQ(VerdictName(Verdict::kUnknown), "unknown");
}

TEST(VerdictName, NamesAreDistinct) {
  std::set<std::string> names;
  for (Verdict v : {Verdict::kProved, Verdict::kViolated, Verdict::kReachable,
                    Verdict::kUnreachable, Verdict::kUnknown}) {
    names.insert(std::string(VerdictName(v)));
  }
  EXPECT_EQ(names.size(), 5u);
}

TEST(CheckResult, DefaultIsUndecidedWithoutTrace) {
  const CheckResult r;
  EXPECT_EQ(r.verdict, Verdict::kUnknown);
  EXPECT_EQ(r.kind, Property::Kind::kAlways);
  EXPECT_FALSE(r.trace.has_value());
  EXPECT_EQ(r.seconds, 0.0);
}

// x' = u, u in [0, 1], from x = 0: x <= t.
constexpr std::string_view kRampModel = R"(
automaton ramp {
  var x;
  input u in [0, 1];
  mode run { x' = u; }
  init run { x = 0; }
  property below_2: always x <= 2;
  property gets_to_3: reach x >= 3;
}
)";

// A trace holding u at `u` for `until` seconds.
Trace Ramp(const System& system, double u, double until) {
  Trace t;
  InputSignal s;
  s.slot = system.symbols().Find("u").value();
  s.shape = InputSignal::Shape::kStep;
  s.points = {{0.0, u}};
  t.inputs.inputs = {s};
  t.inputs.until = until;
  return t;
}

CheckResult Claim(const std::string& property, Verdict verdict, std::optional<Trace> trace) {
  CheckResult r;
  r.property = property;
  r.verdict = verdict;
  r.reason = "claimed";
  r.trace = std::move(trace);
  return r;
}

TEST(ConfirmTrace, TraceThatReplaysIsKeptWithItsFreshReplay) {
  const System system = ParseModel(kRampModel, "ramp.ha");
  // By hand: at u = 1, x = 2.5 > 2 at t = 2.5 and x = 3 at t = 3.
  CheckResult violated = Claim("below_2", Verdict::kViolated, Ramp(system, 1.0, 2.5));
  ConfirmTrace(system, testing::Named(system, "below_2"), violated);
  EXPECT_EQ(violated.verdict, Verdict::kViolated) << violated.reason;
  EXPECT_EQ(violated.reason, "claimed");
  ASSERT_TRUE(violated.trace.has_value());
  ASSERT_GE(violated.trace->state_index, 0);
  EXPECT_GT(violated.trace->run.samples.at(violated.trace->state_index).x[0], 2.0);

  CheckResult reachable = Claim("gets_to_3", Verdict::kReachable, Ramp(system, 1.0, 3.0));
  ConfirmTrace(system, testing::Named(system, "gets_to_3"), reachable);
  EXPECT_EQ(reachable.verdict, Verdict::kReachable) << reachable.reason;
  ASSERT_TRUE(reachable.trace.has_value());
  EXPECT_GE(reachable.trace->run.samples.at(reachable.trace->state_index).x[0], 3.0 - 1e-6);
}

TEST(ConfirmTrace, TraceThatDoesNotReplayMakesTheVerdictUnknown) {
  const System system = ParseModel(kRampModel, "ramp.ha");
  // At u = 0.5 for 3 s, x ends at 1.5: neither above 2 nor at 3.
  CheckResult violated = Claim("below_2", Verdict::kViolated, Ramp(system, 0.5, 3.0));
  ConfirmTrace(system, testing::Named(system, "below_2"), violated);
  EXPECT_EQ(violated.verdict, Verdict::kUnknown);
  EXPECT_FALSE(violated.trace.has_value());
  EXPECT_NE(violated.reason.find("does not replay"), std::string::npos) << violated.reason;
  EXPECT_NE(violated.reason.find("claimed"), std::string::npos) << violated.reason;

  CheckResult reachable = Claim("gets_to_3", Verdict::kReachable, Ramp(system, 0.5, 3.0));
  ConfirmTrace(system, testing::Named(system, "gets_to_3"), reachable);
  EXPECT_EQ(reachable.verdict, Verdict::kUnknown);
  EXPECT_FALSE(reachable.trace.has_value());

  // No trace at all; a trace the simulator rejects (input out of its bounds).
  CheckResult bare = Claim("below_2", Verdict::kViolated, std::nullopt);
  ConfirmTrace(system, testing::Named(system, "below_2"), bare);
  EXPECT_EQ(bare.verdict, Verdict::kUnknown);
  EXPECT_NE(bare.reason.find("no trace"), std::string::npos) << bare.reason;
  CheckResult rejected = Claim("below_2", Verdict::kViolated, Ramp(system, 7.0, 3.0));
  ConfirmTrace(system, testing::Named(system, "below_2"), rejected);
  EXPECT_EQ(rejected.verdict, Verdict::kUnknown);
  EXPECT_FALSE(rejected.trace.has_value());
}

TEST(ConfirmTrace, OtherVerdictsAreLeftAlone) {
  const System system = ParseModel(kRampModel, "ramp.ha");
  for (Verdict v : {Verdict::kProved, Verdict::kUnreachable, Verdict::kUnknown}) {
    CheckResult r = Claim("below_2", v, std::nullopt);
    ConfirmTrace(system, testing::Named(system, "below_2"), r);
    EXPECT_EQ(r.verdict, v);
    EXPECT_EQ(r.reason, "claimed");
  }
}

}  // namespace
}  // namespace hybrid
