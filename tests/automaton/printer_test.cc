#include "hybrid/automaton/printer.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/system.h"
#include "tests/test_utilities/random_models.h"

namespace hybrid {
namespace {

using ::hybrid::testing::GenAutomaton;

Expression C(double v) { return Expression::Constant(v); }

/// A small automaton using every construct of the language once.
Automaton Tank() {
  Automaton a("tank");
  const int k = a.AddParameter("k", C(0.5), "1/s");
  const Expression K = Expression::Symbol("k", k);
  const int h = a.AddVariable("h", "m", Range{C(0.0), C(10.0)});
  const Expression H = Expression::Symbol("h", h);
  const int d = a.AddDiscreteVariable("d");
  const int u = a.AddInput("u", Range{-C(1.0), C(1.0)}, "m/s");
  const int v = a.AddInput("v", Range{C(0.0), K});
  const Expression U = Expression::Symbol("u", u);

  Mode fill;
  fill.name = "fill";
  fill.flows = {{h, U - K * H}};
  fill.invariant.comparisons = {{H, Relation::kLessEqual, C(10.0)}};
  fill.discrete_values = {{d, 1}};
  const ModeId fill_id = a.AddMode(fill);
  Mode drain;
  drain.name = "drain";
  drain.discrete_values = {{d, -2}};
  const ModeId drain_id = a.AddMode(drain);

  Transition t;
  t.name = "t";
  t.source = fill_id;
  t.target = drain_id;
  t.guard.comparisons = {{H, Relation::kGreaterEqual, C(9.0)},
                         {-U, Relation::kLess, Expression::Binary(Op::kPow, K, C(2.0))}};
  t.resets = {{h, H - C(1.0)}};
  t.label = "go";
  t.urgency = Urgency::kLazy;
  a.AddTransition(t);
  Transition back;
  back.name = "back";
  back.source = drain_id;
  back.target = fill_id;
  a.AddTransition(back);

  a.AddInitialState({fill_id, {{h, Range{C(0.0), C(0.0)}, true}}});
  a.AddInitialState({drain_id, {{h, Range{C(1.0), K * C(4.0)}, false}}});

  Scenario s;
  s.until = 10.0;
  s.inputs = {{u, InputSignal::Shape::kStep, {{0.0, 0.5}}},
              {v, InputSignal::Shape::kLinear, {{0.0, 0.0}, {2.5, 0.5}}}};
  a.SetScenario(s);

  a.AddProperty({"safe", Property::Kind::kAlways,
                 Predicate::And(Predicate::Compare({H, Relation::kLessEqual, C(10.0)}),
                                Predicate::Not(Predicate::InMode("drain"))),
                 5.0});
  a.AddProperty({"drains", Property::Kind::kReach,
                 Predicate::Not(Predicate::Or(Predicate::InMode("fill"), Predicate::False())),
                 std::nullopt});
  return a;
}

constexpr char kTankText[] = R"(automaton tank {
  param k [1/s] = 0.5;
  var h [m] in [0, 10];
  discrete d;
  input u [m/s] in [-1, 1];
  input v in [0, k];

  mode fill (d = 1) {
    h' = u - k * h;
    inv h <= 10;
  }

  mode drain (d = -2) {
  }

  transition t: fill -> drain {
    guard h >= 9 and -u < k^2;
    reset h := h - 1;
    label go;
    lazy;
  }

  transition back: drain -> fill {
  }

  init fill { h = 0; }

  init drain { h in [1, k * 4]; }

  scenario {
    until 10;
    u = 0.5;
    v = linear(0: 0, 2.5: 0.5);
  }

  property safe: always h <= 10 and not in drain within 5;
  property drains: reach not (in fill or false);
}
)";

TEST(PrinterTest, PrintsEveryConstruct) { EXPECT_EQ(PrintAutomaton(Tank()), kTankText); }

TEST(PrinterTest, ParsesBackToTheSameAutomaton) {
  const Automaton parsed = ParseAutomaton(kTankText, "tank.ha");
  EXPECT_TRUE(parsed == Tank());
  EXPECT_EQ(PrintAutomaton(parsed), kTankText);
}

TEST(PrinterTest, StepSignalsNotAtTimeZeroUseTheLongForm) {
  Automaton a("a");
  const int x = a.AddVariable("x");
  const int u = a.AddInput("u", Range{C(-1.0), C(1.0)});
  Mode m;
  m.name = "m";
  a.AddMode(m);
  a.AddInitialState({ModeId(0), {{x, Range{C(0.0), C(0.0)}, true}}});
  Scenario s;
  s.until = 0.5;
  s.inputs = {{u, InputSignal::Shape::kStep, {{1.0, -1.0}}}};
  a.SetScenario(s);
  const std::string text = PrintAutomaton(a);
  EXPECT_NE(text.find("u = step(1: -1);"), std::string::npos) << text;
  EXPECT_TRUE(ParseAutomaton(text, "a.ha") == a) << text;
  s.inputs = {{u, InputSignal::Shape::kStep, {{-0.5, 1.0}, {0.0, 0.25}}}};
  a.SetScenario(s);
  const std::string text2 = PrintAutomaton(a);
  EXPECT_NE(text2.find("u = step(-0.5: 1, 0: 0.25);"), std::string::npos) << text2;
  EXPECT_TRUE(ParseAutomaton(text2, "a.ha") == a) << text2;
}

TEST(PrinterTest, ParameterRangesFollowTheValue) {
  Automaton a("gripper");
  const int gmax = a.AddParameter("gmax", C(256), "count");
  a.AddParameter("gob1", C(256), "count", Range{C(0), Expression::Symbol("gmax", gmax)});
  a.AddParameter("k", -C(0.5), "", Range{-C(1), C(0)});
  a.AddParameter("m", C(1));
  const int x = a.AddVariable("x");
  Mode m;
  m.name = "m";
  a.AddMode(m);
  a.AddInitialState({ModeId(0), {{x, Range{C(0.0), C(0.0)}, true}}});
  const std::string text = PrintAutomaton(a);
  EXPECT_EQ(text, R"(automaton gripper {
  param gmax [count] = 256;
  param gob1 [count] = 256 in [0, gmax];
  param k = -0.5 in [-1, 0];
  param m = 1;
  var x;

  mode m {
  }

  init m { x = 0; }
}
)");
  EXPECT_TRUE(ParseAutomaton(text, "gripper.ha") == a) << text;
  // A value set later is printed with the range kept.
  a.SetParameter("gob1", 80);
  const std::string set = PrintAutomaton(a);
  EXPECT_NE(set.find("param gob1 [count] = 80 in [0, gmax];"), std::string::npos) << set;
  EXPECT_TRUE(ParseAutomaton(set, "gripper.ha") == a) << set;
}

TEST(PrinterTest, PrintSystemOfOneAutomatonIsTheAutomaton) {
  const System s = System::Of(Tank());
  EXPECT_EQ(PrintSystem(s), kTankText);
  EXPECT_TRUE(ParseModel(PrintSystem(s), "tank.ha") == s);
}

// --- round trips -----------------------------------------------------------------------------

/// Compares part by part first, so that a failure names the part that differs.
void AssertSameAutomaton(const Automaton& parsed, const Automaton& a) {
  RC_ASSERT(parsed.name() == a.name());
  RC_ASSERT(parsed.symbols() == a.symbols());
  RC_ASSERT(std::ranges::equal(parsed.variables(), a.variables()));
  RC_ASSERT(std::ranges::equal(parsed.discrete_variables(), a.discrete_variables()));
  RC_ASSERT(std::ranges::equal(parsed.inputs(), a.inputs()));
  RC_ASSERT(std::ranges::equal(parsed.parameters(), a.parameters()));
  for (const auto& [slot, value] : a.parameters()) {
    RC_ASSERT(parsed.ParameterRange(slot) == a.ParameterRange(slot));
  }
  RC_ASSERT(std::ranges::equal(parsed.modes(), a.modes()));
  RC_ASSERT(std::ranges::equal(parsed.transitions(), a.transitions()));
  RC_ASSERT(std::ranges::equal(parsed.initial_states(), a.initial_states()));
  RC_ASSERT(parsed.scenario() == a.scenario());
  RC_ASSERT(std::ranges::equal(parsed.properties(), a.properties()));
  RC_ASSERT(parsed == a);
}

RC_GTEST_PROP(PrinterProperty, PrintThenParseGivesAnEqualAutomaton, ()) {
  const Automaton a = *GenAutomaton();
  RC_CLASSIFY(
      std::ranges::any_of(a.parameters(),
                          [&](const auto& p) { return a.ParameterRange(p.first).has_value(); }),
      "a parameter with a range");
  const std::string text = PrintAutomaton(a);
  RC_LOG() << text;
  const Automaton parsed = ParseAutomaton(text, "x.ha");
  AssertSameAutomaton(parsed, a);
  RC_ASSERT(PrintAutomaton(parsed) == text);
}

RC_GTEST_PROP(PrinterProperty, PrintThenParseGivesAnEqualSystem, ()) {
  const System s = System::Of(*GenAutomaton());
  const std::string text = PrintSystem(s);
  RC_LOG() << text;
  RC_ASSERT(ParseModel(text, "x.ha") == s);
}

class SpecRoundTripTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SpecRoundTripTest, PrintThenParseGivesAnEqualSystem) {
  const std::filesystem::path path = std::filesystem::path(HYBRID_SOURCE_DIR) / "spec" / GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " does not exist";
  const System system = ParseModelFile(path);
  const std::string text = PrintSystem(system);
  const System reparsed = ParseModel(text, "x.ha");
  EXPECT_TRUE(reparsed == system) << text;
  EXPECT_EQ(PrintSystem(reparsed), text);
}

INSTANTIATE_TEST_SUITE_P(Spec, SpecRoundTripTest,
                         ::testing::Values("finger.ha", "bouncing_ball.ha", "thermostat.ha",
                                           "hand.ha", "controller.ha", "driven_finger.ha",
                                           "controlled_finger.ha", "controlled_hand.ha"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(0, info.param.find('.'));
                           return name;
                         });

}  // namespace
}  // namespace hybrid
