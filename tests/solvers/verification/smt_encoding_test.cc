// Tests of the bounded-path encoding (solvers/verification/smt_encoding.h), with Z3 directly: flows
// are classified as documented; every flow segment the simulator runs (with a constant input, not
// crossing a guard) is a model of the encoding (soundness, a rapidcheck property); a segment that
// passes through an urgent guard's region is not (urgency); and on the finger's phase-3 law
// (separable), a segment from a state on the law's curve reaches exactly the point on the curve.

#include "solvers/verification/smt_encoding.h"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <z3++.h>

#include <algorithm>
#include <random>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/random_hybrid_automata.h"

namespace hybrid {
namespace {

using testing::ReplaceOnce;

// One mode per flow class.
constexpr std::string_view kClassesModel = R"(
automaton classes {
  param k = 3;
  var x, y;
  input u in [-1, 1];
  input v in [0, 2];
  mode rate { x' = 2 * u; }
  mode rate_drift { x' = k - u + 2 * v; y' = -1; }
  mode decay { x' = -x; }
  mode product { x' = x * u; }
  mode still { }
  mode zero_flow { x' = 0; y' = k - 3; }
  init rate { x = 0; y = 0; }
}
)";

// Two constant-rate modes: `a` (one input, no drift) with an urgent guard whose crossing the
// encoding follows exactly, `b` (drift and input) whose urgent guard it does not encode.
constexpr std::string_view kTwoModeModel = R"(
automaton two {
  var x, y;
  input u in [-1, 1];
  mode a { x' = u; y' = 2 * u; }
  mode b { x' = 1 - u; y' = -0.5; }
  transition up: a -> b { guard x >= 5; }
  transition down: b -> a { guard y <= -5; }
  init a { x = 0; y = 0; }
}
)";

Automaton FingerAutomaton() {
  static const System finger = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  return finger.components()[0].automaton;
}

// The finger with the release of link 2 from c010_l000 (to c000_l000) made lazy.
Automaton FingerWithLazyRelease() {
  const std::string text = ReplaceOnce(
      testing::SpecText("finger"),
      "c010_l000 -> c000_l000 {\n    guard theta3 == theta3_s and u < 0 and theta3_s > theta3_min;",
      "c010_l000 -> c000_l000 {\n    guard theta3 == theta3_s and u < 0 and theta3_s > theta3_min;"
      " lazy;");
  return ParseModel(text, "finger.ha").components()[0].automaton;
}

ModeId Mode(const Automaton& a, const std::string& name) {
  const auto m = a.FindMode(name);
  if (!m) throw std::invalid_argument("no mode " + name);
  return *m;
}

// `name` == `value` at s_k, exactly (tolerance 0) or within `tolerance`.
z3::expr Pin(SmtEncoding& enc, int k, const std::string& name, double value,
             double tolerance = 0.0) {
  const auto slot = enc.automaton().symbols().Find(name);
  if (!slot) throw std::invalid_argument("no symbol " + name);
  return enc.Holds(Predicate::Compare({Expression::Symbol(name, *slot), Relation::kEqual,
                                       Expression::Constant(value)}),
                   k, tolerance);
}

// Queries about one step s_0 -> s_1 of an automaton's encoding: State(0), State(1) and
// Transition(0) asserted once, each query in its own solver scope.
class StepChecker {
 public:
  explicit StepChecker(const Automaton& automaton)
      : automaton_(automaton), enc_(ctx_, automaton_), solver_(ctx_) {
    z3::params p(ctx_);
    p.set("timeout", 5000u);
    solver_.set(p);
    solver_.add(enc_.State(0) && enc_.State(1) && enc_.Transition(0));
    solver_.add(enc_.TakeDefinitions());
  }

  SmtEncoding& encoding() { return enc_; }
  z3::solver& solver() { return solver_; }

  // Whether s_0 in mode `from` with `values0` can step to s_1 in mode `to` with `values1`
  // (pinned within `tolerance`).
  z3::check_result Check(const std::string& from,
                         const std::vector<std::pair<std::string, double>>& values0,
                         const std::string& to,
                         const std::vector<std::pair<std::string, double>>& values1,
                         double tolerance = 0.0) {
    solver_.push();
    solver_.add(enc_.InMode(0, Mode(automaton_, from)) && enc_.InMode(1, Mode(automaton_, to)));
    for (const auto& [name, v] : values0) solver_.add(Pin(enc_, 0, name, v));
    for (const auto& [name, v] : values1) solver_.add(Pin(enc_, 1, name, v, tolerance));
    solver_.add(enc_.TakeDefinitions());
    const z3::check_result r = solver_.check();
    solver_.pop();
    return r;
  }

 private:
  z3::context ctx_;
  const Automaton automaton_;
  SmtEncoding enc_;
  z3::solver solver_;
};

TEST(FlowClassName, NamesEveryClass) {
  EXPECT_EQ(FlowClassName(FlowClass::kStill), "still");
  EXPECT_EQ(FlowClassName(FlowClass::kConstantRate), "constant_rate");
  EXPECT_EQ(FlowClassName(FlowClass::kSeparable), "separable");
  EXPECT_EQ(FlowClassName(FlowClass::kGeneral), "general");
}

TEST(SmtEncoding, ClassifiesFlows) {
  const Automaton a = ParseAutomaton(kClassesModel, "classes.ha");
  z3::context ctx;
  const SmtEncoding enc(ctx, a);
  EXPECT_EQ(enc.flow_class(Mode(a, "rate")), FlowClass::kConstantRate);
  EXPECT_EQ(enc.flow_class(Mode(a, "rate_drift")), FlowClass::kConstantRate);
  EXPECT_EQ(enc.flow_class(Mode(a, "decay")), FlowClass::kGeneral);
  EXPECT_EQ(enc.flow_class(Mode(a, "product")), FlowClass::kGeneral);
  EXPECT_EQ(enc.flow_class(Mode(a, "still")), FlowClass::kStill);
  // Flows that fold to 0 (parameters at their values) do not move anything.
  EXPECT_EQ(enc.flow_class(Mode(a, "zero_flow")), FlowClass::kStill);
}

TEST(SmtEncoding, ClassifiesTheFingerModes) {
  const Automaton a = FingerAutomaton();
  z3::context ctx;
  const SmtEncoding enc(ctx, a);
  EXPECT_EQ(enc.flow_class(Mode(a, "c000_l000")), FlowClass::kConstantRate);  // phase 1
  EXPECT_EQ(enc.flow_class(Mode(a, "c100_l000")), FlowClass::kConstantRate);  // phase 2
  for (const char* m :
       {"c010_l000", "c000_l010", "c110_l000", "c100_l010", "c010_l100", "c000_l110"}) {  // phase 3
    EXPECT_EQ(enc.flow_class(Mode(a, m)), FlowClass::kSeparable) << m;
  }
  // Phase 4 (link 3 blocked or at its limit): nothing moves.
  int still = 0;
  for (const hybrid::Mode& m : a.modes()) {
    if (m.flows.empty()) {
      EXPECT_EQ(enc.flow_class(Mode(a, m.name)), FlowClass::kStill) << m.name;
      ++still;
    }
  }
  EXPECT_EQ(still, 19);
  for (const char* m : {"c001_l000", "c111_l000", "c000_l111", "c001_l10n", "c000_l11n"}) {
    EXPECT_EQ(enc.flow_class(Mode(a, m)), FlowClass::kStill) << m;
  }
}

// The random models of RandomDynamics::kSeparable (the prover's differential test on separable
// flows, soundness_test.cc) have modes the encoding classifies as separable: most of those with
// an input and two variables or more.
TEST(SmtEncoding, ClassifiesRandomSeparableModes) {
  int separable = 0, eligible = 0;
  for (int i = 0; i < 100; ++i) {
    std::mt19937_64 rng(1000 + i);
    const testing::RandomHybridAutomaton r =
        testing::GenerateRandomAutomaton(rng, {testing::RandomDynamics::kSeparable});
    if (r.inputs.empty() || r.variables.size() < 2) continue;
    const Automaton a = ParseAutomaton(r.Text(), "random.ha");
    z3::context ctx;
    const SmtEncoding enc(ctx, a);
    for (int m = 0; m < a.num_modes(); ++m) {
      ++eligible;
      separable += enc.flow_class(ModeId(m)) == FlowClass::kSeparable ? 1 : 0;
    }
  }
  EXPECT_GT(eligible, 50);
  EXPECT_GT(separable, eligible / 3) << separable << " of " << eligible;
}

// Soundness: the endpoint of every simulated segment (constant input, start and end clear of
// the guards) satisfies the encoded flow relation, urgency included.
RC_GTEST_PROP(SmtEncodingProperty, SimulatedSegmentsAreModels, ()) {
  static const System from_a = ParseModel(kTwoModeModel, "two.ha");
  static const System from_b =
      ParseModel(ReplaceOnce(std::string(kTwoModeModel), "init a {", "init b {"), "two.ha");
  const bool in_a = *rc::gen::arbitrary<bool>();
  const double u = *rc::gen::inRange(-1000, 1001) / 1000.0;
  double d = *rc::gen::inRange(1, 5001) / 1000.0;
  double x0 = 0.0, y0 = 0.0;
  if (in_a) {
    // x moves at u: keep x below the guard x >= 5 at both ends.
    x0 = *rc::gen::inRange(-10000, 4990) / 1000.0;
    y0 = *rc::gen::inRange(-10000, 10000) / 1000.0;
    if (u > 0) d = std::min(d, (4.999 - x0) / u);
  } else {
    // y falls at 0.5: keep y above the guard y <= -5 at both ends.
    x0 = *rc::gen::inRange(-10000, 10000) / 1000.0;
    y0 = *rc::gen::inRange(-4990, 10000) / 1000.0;
    d = std::min(d, (y0 + 4.999) / 0.5);
  }
  RC_PRE(d > 0.0);
  System system = in_a ? from_a : from_b;
  system.SetInitialValue("x", x0);
  system.SetInitialValue("y", y0);
  const Simulator sim(system);
  SimulationOptions options;
  options.until = d;
  InputSignal signal;
  signal.slot = system.symbols().Find("u").value();
  signal.points = {{0.0, u}};
  const SimulationResult run = sim.Run(options, std::vector<InputSignal>{signal});
  RC_ASSERT(run.status == SimulationStatus::kCompleted);
  RC_ASSERT(run.events.empty());
  const StateSample& end = run.samples.back();
  const double x1 = end.x[0], y1 = end.x[1];
  RC_LOG() << (in_a ? "a" : "b") << ": (" << x0 << ", " << y0 << ") -> (" << x1 << ", " << y1
           << ") with u = " << u << " for " << d << "\n";
  const std::string mode = in_a ? "a" : "b";
  static StepChecker checker(from_a.components()[0].automaton);  // the same flows as from_b
  const z3::check_result r =
      checker.Check(mode, {{"x", x0}, {"y", y0}}, mode, {{"x", x1}, {"y", y1}}, 1e-9);
  RC_ASSERT(r == z3::sat);
}

TEST(SmtEncoding, ConstantRateEndpointsAreExact) {
  StepChecker step(ParseAutomaton(kTwoModeModel, "two.ha"));
  // In a, y - 2 x is constant.
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 2}, {"y", 4}}), z3::sat);
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 2}, {"y", 4.001}}), z3::unsat);
  EXPECT_EQ(step.Check("a", {{"x", 1}, {"y", 0}}, "a", {{"x", -3}, {"y", -8}}), z3::sat);
  // In b, y falls at 0.5 and x moves at 1 - u in [0, 2]: x1 - x0 within [0, 2 d].
  EXPECT_EQ(step.Check("b", {{"x", 0}, {"y", 0}}, "b", {{"x", 4}, {"y", -1}}), z3::sat);
  EXPECT_EQ(step.Check("b", {{"x", 0}, {"y", 0}}, "b", {{"x", 4.01}, {"y", -1}}), z3::unsat);
  EXPECT_EQ(step.Check("b", {{"x", 0}, {"y", 0}}, "b", {{"x", -0.01}, {"y", -1}}), z3::unsat);
  EXPECT_EQ(step.Check("b", {{"x", 0}, {"y", 0}}, "b", {{"x", 0}, {"y", 1}}), z3::unsat);
}

TEST(SmtEncoding, UrgentGuardOnTheSegmentForbidsIt) {
  StepChecker step(ParseAutomaton(kTwoModeModel, "two.ha"));
  // Through the guard region x >= 5: the urgent transition would have fired at x = 5.
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 10}, {"y", 20}}), z3::unsat);
  // Up to the guard's boundary (it holds only at the end) or short of it: allowed.
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 5}, {"y", 10}}), z3::sat);
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 4.9}, {"y", 9.8}}), z3::sat);
  // Starting inside the guard region (the jump is due at once), in either direction.
  EXPECT_EQ(step.Check("a", {{"x", 6}, {"y", 0}}, "a", {{"x", 7}, {"y", 2}}), z3::unsat);
  EXPECT_EQ(step.Check("a", {{"x", 6}, {"y", 0}}, "a", {{"x", 4}, {"y", -4}}), z3::unsat);
  // The jump itself is allowed there.
  EXPECT_EQ(step.Check("a", {{"x", 6}, {"y", 0}}, "b", {{"x", 6}, {"y", 0}}), z3::sat);
  EXPECT_EQ(step.Check("a", {{"x", 4}, {"y", 0}}, "b", {{"x", 4}, {"y", 0}}), z3::unsat);
}

TEST(SmtEncoding, LazyGuardDoesNotForbidTheSegment) {
  StepChecker step(ParseAutomaton(
      ReplaceOnce(std::string(kTwoModeModel), "guard x >= 5; }", "guard x >= 5; lazy; }"),
      "lazy.ha"));
  EXPECT_EQ(step.Check("a", {{"x", 0}, {"y", 0}}, "a", {{"x", 10}, {"y", 20}}), z3::sat);
}

// A mode whose flows are not all constant rates (x' = k v with v a variable: kGeneral) still
// follows a variable with a constant flow (m' = 2) exactly, and an urgent guard that reads only
// that variable stops the segment; one that reads x is not encoded (x is not followed). In a mode
// where nothing moves (`wait`), an urgent guard that holds allows no flow at all.
constexpr std::string_view kMotorModel = R"(
automaton motor {
  param k = 3;
  var x, m, v, target;
  mode run { x' = k * v; m' = 2; }
  mode held { }
  mode wait { }
  transition arrive: run -> held { guard m >= target; }
  transition far: run -> held { guard x >= 100; }
  transition go: wait -> run { guard target >= 5; }
  init run { x = 0; m = 0; v = 1; target = 10; }
}
)";

TEST(SmtEncoding, GeneralModeFollowsConstantFlowsExactly) {
  const Automaton a = ParseAutomaton(kMotorModel, "motor.ha");
  StepChecker step(a);
  // m moves at exactly 2: 0 -> 4 takes d = 2; x is free (kGeneral).
  EXPECT_EQ(step.Check("run", {{"m", 0}, {"x", 0}, {"target", 10}}, "run", {{"m", 4}, {"x", 77}}),
            z3::sat);
  EXPECT_EQ(step.Check("run", {{"m", 0}, {"target", 10}}, "run", {{"m", -1}}), z3::unsat);
  // The urgent guard m >= target stops the segment at m = 10.
  EXPECT_EQ(step.Check("run", {{"m", 0}, {"target", 10}}, "run", {{"m", 10}}), z3::sat);
  EXPECT_EQ(step.Check("run", {{"m", 0}, {"target", 10}}, "run", {{"m", 10.5}}), z3::unsat);
  // x >= 100 is not encoded: a segment may end with x past it (sound: more paths).
  EXPECT_EQ(step.Check("run", {{"m", 0}, {"x", 0}, {"target", 10}}, "run", {{"m", 1}, {"x", 150}}),
            z3::sat);
  // The mode is kGeneral: the constant flow is followed inside it.
  SmtEncoding& enc = step.encoding();
  EXPECT_EQ(enc.flow_class(*a.FindMode("run")), FlowClass::kGeneral);
  // kStill: waiting is a flow only while `go` is not due.
  EXPECT_EQ(enc.flow_class(*a.FindMode("wait")), FlowClass::kStill);
  EXPECT_EQ(step.Check("wait", {{"target", 10}}, "wait", {{"target", 10}}), z3::unsat);
  EXPECT_EQ(step.Check("wait", {{"target", 1}}, "wait", {{"target", 1}}), z3::sat);
}

// Kept for the whole run: deleting a Z3 context that holds the finger's encoding takes about a
// second (Z3 4.8.12), which would dominate the tests.
StepChecker& FingerChecker() {
  static StepChecker checker(FingerAutomaton());
  return checker;
}

// The finger's phase-3 law (c010_l000): theta3' = K / (255 - g)^2 * u, g' = u with
// K = (theta3_max - theta3_s)(255 - g_s), whose solution from (g_s, theta3_s) is the curve
// (theta3 - theta3_s)(255 - g) = (theta3_max - theta3_s)(g - g_s). With theta3_s = -20,
// g_s = 100 (theta3_max = 43): theta3 = -20 + 63 (g - 100) / (255 - g), so theta3 = 10 at g = 150
// and 25.5 at g = 165.
TEST(SmtEncoding, SeparableFlowFollowsThePhase3Law) {
  static StepChecker& step = FingerChecker();
  const std::vector<std::pair<std::string, double>> start = {
      {"theta1", 30}, {"theta2", 0}, {"theta3", 10}, {"g", 150}, {"theta3_s", -20}, {"g_s", 100}};
  auto end = [&](double theta3, double g) {
    std::vector<std::pair<std::string, double>> out = start;
    for (auto& [name, v] : out) {
      if (name == "theta3") v = theta3;
      if (name == "g") v = g;
    }
    return out;
  };
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", end(25.5, 165)), z3::sat);
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", end(26, 165)), z3::unsat);
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", end(25, 165)), z3::unsat);
  // Opening (u < 0) follows the same curve back: theta3 = -20 + 63 * 25 / 130 at g = 125.
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", end(-20 + 63.0 * 25 / 130, 125), 1e-9),
            z3::sat);
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", end(10, 125)), z3::unsat);
  // Variables without a flow keep their values.
  auto moved = end(25.5, 165);
  moved[0].second = 31;
  EXPECT_EQ(step.Check("c010_l000", start, "c010_l000", moved), z3::unsat);
}

// Opening from the same state, theta3 falls back along the curve and reaches theta3_s = -20 at
// g = g_s = 100, where the urgent release of link 2 (theta3 == theta3_s and u < 0) fires: a
// segment on to g = 90 (theta3 = -20 - 630 / 165) passes through the guard.
TEST(SmtEncoding, SeparableFlowStopsAtAnUrgentGuard) {
  const std::vector<std::pair<std::string, double>> start = {
      {"theta1", 30}, {"theta2", 0}, {"theta3", 10}, {"g", 150}, {"theta3_s", -20}, {"g_s", 100}};
  auto end = [&](double theta3, double g) {
    std::vector<std::pair<std::string, double>> out = start;
    for (auto& [name, v] : out) {
      if (name == "theta3") v = theta3;
      if (name == "g") v = g;
    }
    return out;
  };
  StepChecker& urgent = FingerChecker();
  EXPECT_EQ(urgent.Check("c010_l000", start, "c010_l000", end(-20, 100)), z3::sat);
  EXPECT_EQ(urgent.Check("c010_l000", start, "c010_l000", end(-20 - 630.0 / 165, 90), 1e-9),
            z3::unsat);
  // The same segment is allowed when the release is lazy.
  static StepChecker lazy(FingerWithLazyRelease());
  EXPECT_EQ(lazy.Check("c010_l000", start, "c010_l000", end(-20 - 630.0 / 165, 90), 1e-9), z3::sat);
}

// ---------------------------------------------------------------------------------------------
// Names: the encoding's constants are named by kind and index, never by a model name.

// The tank of issue 12 (h rises at 0.5 + d, d in [-0.2, 0]): its input is named d.
constexpr std::string_view kTankModel = R"(
automaton tank {
  var h in [0, 10];
  input d in [-0.2, 0];
  mode fill { h' = 0.5 + d; inv h <= 8; }
  init fill { h = 5; }
}
)";

// With the input's constant at s_0 named "d@0", as the duration of the flow from s_0 once was,
// the duration equalled the input (at most 0) and no flow could move h.
TEST(SmtEncodingNames, AnInputNamedDIsNotTheDuration) {
  StepChecker step(ParseAutomaton(kTankModel, "tank.ha"));
  // h from 5 to 7: 4 s at d = 0, 2 / 0.3 s at d = -0.2.
  EXPECT_EQ(step.Check("fill", {{"h", 5}}, "fill", {{"h", 7}}), z3::sat);
  EXPECT_EQ(step.Check("fill", {{"h", 5}, {"d", -0.2}}, "fill", {{"h", 7}}), z3::sat);
  // h never falls.
  EXPECT_EQ(step.Check("fill", {{"h", 5}}, "fill", {{"h", 4.9}}), z3::unsat);
}

// Every constant in the formulas of an encoding whose model uses the encoding's own words as
// names is named KIND[.INDEX][@STEP] with KIND one of the encoding's fixed kinds.
TEST(SmtEncodingNames, ConstantsAreNamedByKindAndIndexOnly) {
  const Automaton a = ParseAutomaton(R"(
automaton flow {
  param p = 1 in [0, 2];
  param aux = 2;
  var d, x, amo;
  input u in [-1, 1];
  input V in [0, 1];
  mode mode_ { d' = p * u + V; x' = d / (amo + 2); amo' = sin(x); inv d <= 10; }
  mode jump { d' = 1; }
  transition flow: mode_ -> jump { guard d >= aux; reset x := d / amo; }
  transition d: jump -> mode_ { guard d >= 3; reset d := 0; }
  init mode_ { d = 0; x in [0, 1]; amo = 1; }
}
)",
                                     "names.ha");
  z3::context ctx;
  SmtEncoding enc(ctx, a);
  z3::expr_vector all(ctx);
  all.push_back(enc.Initial());
  for (int k = 0; k <= 2; ++k) all.push_back(enc.State(k));
  for (int k = 0; k < 2; ++k) all.push_back(enc.Transition(k));
  all.push_back(enc.TakeDefinitions());
  const std::regex pattern(R"((x|u|V|d|flow|mode|jump|amo|p|aux)(\.[0-9]+)?(@[0-9]+)?)");
  std::set<std::string> names;
  std::vector<z3::expr> todo;
  for (unsigned i = 0; i < all.size(); ++i) todo.push_back(all[i]);
  std::set<unsigned> seen;
  while (!todo.empty()) {
    const z3::expr e = todo.back();
    todo.pop_back();
    if (!seen.insert(e.id()).second) continue;
    if (e.is_const() && !e.is_numeral() && !e.is_true() && !e.is_false()) {
      names.insert(e.decl().name().str());
    }
    if (e.is_app()) {
      for (unsigned i = 0; i < e.num_args(); ++i) todo.push_back(e.arg(i));
    }
  }
  EXPECT_GT(names.size(), 20u);
  for (const std::string& name : names) {
    EXPECT_TRUE(std::regex_match(name, pattern)) << name;
  }
  // Distinct roles, distinct constants: the variable d, the input u and the duration at s_0.
  EXPECT_TRUE(names.count("x.0@0") && names.count("u.0@0") && names.count("d@0"));
  EXPECT_EQ(SmtEncoding::ConstantName("x", 3, 2), "x.3@2");
  EXPECT_EQ(SmtEncoding::ConstantName("d", -1, 0), "d@0");
  EXPECT_EQ(SmtEncoding::ConstantName("p", 4, -1), "p.4");
}

// ---------------------------------------------------------------------------------------------
// Size: linear in the number of modes.

// A chain of `n` modes x' = 1, each left at x >= i + 1.
Automaton Chain(int n) {
  std::string text = "automaton chain {\n  var x;\n";
  for (int i = 0; i < n; ++i) {
    text +=
        "  mode m" + std::to_string(i) + " { x' = 1; inv x <= " + std::to_string(i + 1) + "; }\n";
  }
  for (int i = 0; i + 1 < n; ++i) {
    text += "  transition m" + std::to_string(i) + " -> m" + std::to_string(i + 1) +
            " { guard x >= " + std::to_string(i + 1) + "; }\n";
  }
  text += "  init m0 { x = 0; }\n}\n";
  return ParseAutomaton(text, "chain.ha");
}

// The number of distinct subterms of `e`.
std::size_t Size(const z3::expr& e) {
  std::vector<z3::expr> todo = {e};
  std::set<unsigned> seen;
  while (!todo.empty()) {
    const z3::expr x = todo.back();
    todo.pop_back();
    if (!seen.insert(x.id()).second || !x.is_app()) continue;
    for (unsigned i = 0; i < x.num_args(); ++i) todo.push_back(x.arg(i));
  }
  return seen.size();
}

// Exactly one mode per state once took a clause per pair of modes (n^2 / 2: 5 * 10^7 for
// 10^4 modes, gigabytes); a ladder takes 3 per mode.
TEST(SmtEncodingSize, StatesAndTransitionsAreLinearInTheModes) {
  std::vector<double> per_mode;
  for (int n : {100, 400, 1600}) {
    const Automaton a = Chain(n);
    z3::context ctx;
    SmtEncoding enc(ctx, a);
    const std::size_t state = Size(enc.State(0));
    const std::size_t step = Size(enc.State(0) && enc.State(1) && enc.Transition(0));
    EXPECT_LT(state, 16u * n) << n;
    EXPECT_LT(step, 60u * n) << n;
    per_mode.push_back(static_cast<double>(step) / n);
  }
  // Linear: the size per mode does not grow with the number of modes.
  EXPECT_LT(per_mode.back(), 1.1 * per_mode.front());
}

// Exactly one mode: the ladder forbids two modes at once and allows each one alone.
TEST(SmtEncodingSize, ExactlyOneModeHolds) {
  const Automaton a = Chain(5);
  z3::context ctx;
  SmtEncoding enc(ctx, a);
  z3::solver s(ctx);
  s.add(enc.State(0));
  s.add(enc.TakeDefinitions());
  for (int i = 0; i < 5; ++i) {
    s.push();
    s.add(enc.InMode(0, ModeId(i)));
    EXPECT_EQ(s.check(), z3::sat) << i;
    for (int j = 0; j < 5; ++j) {
      if (j == i) continue;
      s.push();
      s.add(enc.InMode(0, ModeId(j)));
      EXPECT_EQ(s.check(), z3::unsat) << i << " " << j;
      s.pop();
    }
    s.pop();
  }
  z3::expr_vector none(ctx);
  for (int i = 0; i < 5; ++i) none.push_back(!enc.InMode(0, ModeId(i)));
  s.add(z3::mk_and(none));
  EXPECT_EQ(s.check(), z3::unsat);
}

// Sets of flagged modes of an automaton of n modes (n >= 10) for StateIn and HoldsIn: the first
// or the last alone, and a few together, as a flag per mode.
std::vector<std::vector<bool>> FlagSets(int n) {
  std::vector<std::vector<bool>> out;
  for (const std::vector<int>& flagged :
       std::vector<std::vector<int>>{{0}, {n - 1}, {1, 4, 9}, {0, 2, n - 1}}) {
    std::vector<bool> flags(static_cast<std::size_t>(n), false);
    for (int m : flagged) flags[static_cast<std::size_t>(m)] = true;
    out.push_back(std::move(flags));
  }
  return out;
}

// StateIn(k, flags) is State(k) with the unflagged modes ruled out, up to the exactly-one
// ladder's auxiliaries (amo.*): State and the unflagged modes out imply StateIn, and StateIn
// implies that some values of the auxiliaries make State hold with the unflagged modes out;
// checked by Z3 on the finger's 31 modes for several sets of flagged modes. It carries only the
// flagged modes' invariants (smaller than State).
TEST(SmtEncodingSize, StateInIsTheStateInTheFlaggedModes) {
  const Automaton a = FingerAutomaton();
  const int n = a.num_modes();
  for (const std::vector<bool>& flags : FlagSets(n)) {
    const auto flagged = std::count(flags.begin(), flags.end(), true);
    z3::context ctx;
    SmtEncoding enc(ctx, a);
    z3::expr_vector out(ctx), ladder(ctx);
    for (int m = 0; m < n; ++m) {
      if (!flags[static_cast<std::size_t>(m)]) out.push_back(!enc.InMode(0, ModeId(m)));
      ladder.push_back(ctx.bool_const(SmtEncoding::ConstantName("amo", m, 0).c_str()));
    }
    const z3::expr full = enc.State(0) && z3::mk_and(out);
    const z3::expr in = enc.StateIn(0, flags);
    const z3::expr definitions = enc.TakeDefinitions();
    z3::solver s(ctx);
    s.add(definitions);
    s.push();
    s.add(full && !in);
    EXPECT_EQ(s.check(), z3::unsat) << flagged << " flagged modes";
    s.pop();
    s.add(in && !z3::exists(ladder, full));
    EXPECT_EQ(s.check(), z3::unsat) << flagged << " flagged modes";
    EXPECT_LT(Size(in), Size(enc.State(0)));
  }
}

// HoldsIn(p, k, flags) is Holds(p, k) where s_k is in a flagged mode (StateIn(k, flags)): the
// two differ in no model, for every property of the finger (its discrete variables c1 .. l3 and
// its modes read) and several sets of flagged modes; and it is smaller where few are flagged.
TEST(SmtEncodingSize, HoldsInIsHoldsInTheFlaggedModes) {
  const System finger = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  const Automaton& a = finger.components()[0].automaton;
  const int n = a.num_modes();
  for (const std::vector<bool>& flags : FlagSets(n)) {
    const auto flagged = std::count(flags.begin(), flags.end(), true);
    z3::context ctx;
    SmtEncoding enc(ctx, a);
    z3::solver s(ctx);
    s.add(enc.StateIn(0, flags));
    s.add(enc.TakeDefinitions());
    ASSERT_FALSE(finger.properties().empty());
    for (const Property& p : finger.properties()) {
      const z3::expr all = enc.Holds(p.predicate, 0);
      const z3::expr in = enc.HoldsIn(p.predicate, 0, flags);
      s.push();
      s.add(enc.TakeDefinitions());
      s.add(all != in);
      EXPECT_EQ(s.check(), z3::unsat) << p.name << ", " << flagged << " flagged modes";
      s.pop();
      if (flagged == 1) EXPECT_LE(Size(in), Size(all)) << p.name;
    }
  }
}

// TransitionFrom(k, m) is the disjunction of MoveFrom(k, m, move) over m's moves (its flow and
// each transition from it), for every mode of the finger: Z3 finds no model where they differ.
// And a move's s_k+1 is in one mode: m for the flow, the transition's target for a jump.
TEST(SmtEncoding, TheStepFromAModeIsTheDisjunctionOfItsMoves) {
  const Automaton a = FingerAutomaton();
  z3::context ctx;
  SmtEncoding enc(ctx, a);
  z3::solver s(ctx);
  s.add(enc.State(0) && enc.State(1));
  s.add(enc.TakeDefinitions());
  for (int m = 0; m < a.num_modes(); ++m) {
    z3::expr_vector moves(ctx);
    moves.push_back(enc.MoveFrom(0, ModeId(m), std::nullopt));
    std::vector<int> targets = {m};
    for (int t = 0; t < a.num_transitions(); ++t) {
      if (a.transitions()[t].source.value() != m) continue;
      moves.push_back(enc.MoveFrom(0, ModeId(m), TransitionId(t)));
      targets.push_back(a.transitions()[t].target.value());
    }
    const z3::expr whole = enc.TransitionFrom(0, ModeId(m));
    s.add(enc.TakeDefinitions());  // of the auxiliaries the moves' formulas name
    s.push();
    s.add(whole != z3::mk_or(moves));
    EXPECT_EQ(s.check(), z3::unsat) << a.modes()[m].name;
    s.pop();
    for (unsigned i = 0; i < moves.size(); ++i) {
      s.push();
      s.add(moves[i] && !enc.InMode(1, ModeId(targets[i])));
      EXPECT_EQ(s.check(), z3::unsat) << a.modes()[m].name << ", move " << i;
      s.pop();
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Reading a path back: the representative input reaches the encoded endpoint.

// A flow with drift (h' = 0.5 + d) from h = 5 to h = 7 with the model's input at -0.2: the
// segment's input integral decides the endpoint, so the path read back holds the mean input
// V / duration over the duration (5 + (0.5 + u) T = 7), not the model's -0.2 (which with the
// model's duration missed the endpoint, and the witness did not replay).
TEST(SmtEncodingReadPath, DriftSegmentHoldsTheMeanInput) {
  StepChecker step(ParseAutomaton(kTankModel, "tank.ha"));
  SmtEncoding& enc = step.encoding();
  z3::solver& s = step.solver();
  s.push();
  s.add(enc.InMode(0, ModeId(0)) && enc.InMode(1, ModeId(0)));
  s.add(Pin(enc, 0, "h", 5) && Pin(enc, 1, "h", 7) && Pin(enc, 0, "d", -0.2));
  s.add(enc.TakeDefinitions());
  ASSERT_EQ(s.check(), z3::sat);
  const auto path = enc.ReadPath(s.get_model(), 1);
  s.pop();
  ASSERT_EQ(path.size(), 2u);
  ASSERT_TRUE(path[0].flow);
  const double u = path[0].input.at(0), T = path[0].duration;
  EXPECT_GE(u, -0.2);
  EXPECT_LE(u, 0.0);
  EXPECT_GT(T, 0.0);
  EXPECT_NEAR(5 + (0.5 + u) * T, 7.0, 1e-9) << "u = " << u << ", T = " << T;
}

}  // namespace
}  // namespace hybrid
