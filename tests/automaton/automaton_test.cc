// The Automaton API validates every declaration; its messages speak of the model, not of the API.
#include "hybrid/automaton/automaton.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace hybrid {
namespace {

Expression Sym(const Automaton& a, const std::string& name) {
  return Expression::Symbol(name, *a.symbols().Find(name));
}

// Expects `f` to throw std::invalid_argument whose message contains `detail` and speaks of the
// model only: no C++ name such as "Automaton::AddMode" (messages reach users as they are).
template <class F>
void ExpectInvalid(F f, const std::string& detail) {
  try {
    f();
    FAIL() << "no exception; expected " << detail;
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(detail), std::string::npos) << message;
    EXPECT_EQ(message.find("::"), std::string::npos) << message;
  }
}

class AutomatonTest : public ::testing::Test {
 protected:
  AutomatonTest() : a_("ball") {
    a_.AddParameter("g", Expression::Constant(9.81));
    a_.AddVariable("h", "m", Range{Expression::Constant(0), Expression::Constant(100)});
    a_.AddVariable("v");
    a_.AddInput("u", {Expression::Constant(-1), Expression::Constant(1)});
    Mode falling;
    falling.name = "falling";
    falling.flows = {{Slot("h"), Sym(a_, "v")}, {Slot("v"), -Sym(a_, "g")}};
    falling.invariant.comparisons.push_back(
        {Sym(a_, "h"), Relation::kGreaterEqual, Expression::Constant(0)});
    falling_ = a_.AddMode(falling);
  }
  int Slot(const std::string& name) const { return *a_.symbols().Find(name); }

  Automaton a_;
  ModeId falling_;
};

TEST_F(AutomatonTest, SlotsFollowDeclarationOrder) {
  EXPECT_EQ(Slot("g"), 0);
  EXPECT_EQ(Slot("h"), 1);
  EXPECT_EQ(Slot("v"), 2);
  EXPECT_EQ(Slot("u"), 3);
  EXPECT_EQ(a_.variables().size(), 2u);
  EXPECT_EQ(a_.symbols()[1].unit, "m");
}

TEST_F(AutomatonTest, ParameterEnvironmentEvaluatesInOrder) {
  a_.AddParameter("g2", Sym(a_, "g") * Expression::Constant(2));
  const std::vector<double> env = a_.ParameterEnvironment();
  EXPECT_DOUBLE_EQ(env[Slot("g2")], 19.62);
  EXPECT_DOUBLE_EQ(env[Slot("h")], 0.0);
}

// SetParameter replaces a parameter by a constant; parameters defined from it follow, and a
// value that makes one of them non-finite is refused with the old value kept.
TEST_F(AutomatonTest, SetParameterReplacesTheValueAndDependentsFollow) {
  a_.AddParameter("inv_g", Expression::Constant(1) / Sym(a_, "g"));
  a_.SetParameter("g", 2.0);
  EXPECT_EQ(a_.ParameterEnvironment()[Slot("g")], 2.0);
  EXPECT_EQ(a_.ParameterEnvironment()[Slot("inv_g")], 0.5);
  ExpectInvalid([&] { a_.SetParameter("g", 0.0); }, "makes parameter 'inv_g' non-finite");
  EXPECT_EQ(a_.ParameterEnvironment()[Slot("g")], 2.0);
  ExpectInvalid([&] { a_.SetParameter("h", 1.0); }, "'h' is not a parameter");
  ExpectInvalid([&] { a_.SetParameter("g", std::nan("")); }, "not finite");
}

// SetGuard replaces a transition's guard, validated like AddTransition.
TEST_F(AutomatonTest, SetGuardReplacesAGuard) {
  const TransitionId t =
      a_.AddTransition(Transition{"bounce", falling_, falling_, "", {}, {}, Urgency::kUrgent});
  Constraint guard;
  guard.comparisons.push_back({Sym(a_, "h"), Relation::kLessEqual, Expression::Constant(0)});
  a_.SetGuard(t, guard);
  EXPECT_EQ(a_.transition(t).guard, guard);
  Constraint bad;
  bad.comparisons.push_back(
      {Expression::Symbol("ghost", 42), Relation::kLessEqual, Expression::Constant(0)});
  ExpectInvalid([&] { a_.SetGuard(t, bad); }, "guard of 'bounce'");
  ExpectInvalid([&] { a_.SetGuard(TransitionId(7), guard); },
                "guard for a transition that automaton 'ball' does not have");
}

// SetInitialValue gives a variable added after the initial states its value in every one.
TEST_F(AutomatonTest, SetInitialValueCompletesInitialStates) {
  const Expression zero = Expression::Constant(0);
  a_.AddInitialState({falling_,
                      {{Slot("h"), {Expression::Constant(10), Expression::Constant(10)}, true},
                       {Slot("v"), {zero, zero}, true}}});
  const int w = a_.AddVariable("w");
  a_.SetInitialValue(w, {w, {Expression::Constant(3), Expression::Constant(3)}, true});
  ASSERT_EQ(a_.initial_states()[0].values.size(), 3u);
  EXPECT_EQ(a_.initial_states()[0].values[2].slot, w);
  EXPECT_EQ(a_.initial_states()[0].values[2].range.lo, Expression::Constant(3));
  // Replacing keeps one value per variable, sorted by slot.
  a_.SetInitialValue(Slot("h"), {Slot("h"), {zero, zero}, true});
  EXPECT_EQ(a_.initial_states()[0].values.size(), 3u);
  EXPECT_EQ(a_.initial_states()[0].values[0].range.lo, zero);
  ExpectInvalid(
      [&] {
        a_.SetInitialValue(Slot("g"), {Slot("g"), {zero, zero}, true});
      },
      "not a continuous variable");
  ExpectInvalid(
      [&] {
        a_.SetInitialValue(w, {w, {Expression::Constant(2), Expression::Constant(1)}, false});
      },
      "empty initial range");
}

TEST_F(AutomatonTest, RejectsDuplicateNames) {
  ExpectInvalid([&] { a_.AddVariable("h"); }, "duplicate name 'h'");
  ExpectInvalid([&] { a_.AddParameter("v", Expression::Constant(1)); },
                "already declared as variable");
}

TEST_F(AutomatonTest, ParametersReadOnlyEarlierParameters) {
  ExpectInvalid([&] { a_.AddParameter("k", Sym(a_, "h")); }, "variable 'h' is not allowed");
  ExpectInvalid([&] { a_.AddParameter("k", Expression::Constant(1) / Expression::Constant(0)); },
                "not finite");
}

// The std::invalid_argument message `f` throws ("" and a test failure if none).
template <class F>
std::string InvalidArgumentMessage(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return "";
}

// A parameter may declare the range of values a verifier must cover; the nominal value must lie
// in it, the bounds read earlier parameters only and must be finite.
TEST_F(AutomatonTest, ParameterRangeIsStoredAndValidated) {
  const Expression C0 = Expression::Constant(0);
  const int gmax = a_.AddParameter("gmax", Expression::Constant(256));
  const Range range{C0, Sym(a_, "gmax")};
  const int gob1 = a_.AddParameter("gob1", Expression::Constant(256), "count", range);
  EXPECT_EQ(a_.ParameterRange(gob1), range);
  EXPECT_EQ(a_.ParameterRange(gmax), std::nullopt);       // a parameter without a range
  EXPECT_EQ(a_.ParameterRange(Slot("h")), std::nullopt);  // not a parameter
  EXPECT_EQ(a_.ParameterRange(-1), std::nullopt);
  EXPECT_EQ(a_.ParameterRange(99), std::nullopt);
  EXPECT_EQ(a_.ParameterEnvironment()[gob1], 256.0);  // the nominal value

  const Expression C1 = Expression::Constant(1), C2 = Expression::Constant(2);
  EXPECT_EQ(InvalidArgumentMessage([&] {
              a_.AddParameter("k", C1, "", Range{C2, C1});
            }),
            "empty range [2, 1] for parameter 'k'");
  EXPECT_EQ(
      InvalidArgumentMessage([&] { a_.AddParameter("k", Expression::Constant(300), "", range); }),
      "value 300 of parameter 'k' is outside its range [0, 256]");
  EXPECT_EQ(InvalidArgumentMessage([&] {
              a_.AddParameter("k", C0, "", Range{C1, C2});
            }),
            "value 0 of parameter 'k' is outside its range [1, 2]");
  EXPECT_EQ(InvalidArgumentMessage([&] {
              a_.AddParameter("k", C0, "", Range{C0, C1 / C0});
            }),
            "range of 'k': '1 / 0' is not finite");
  EXPECT_EQ(InvalidArgumentMessage([&] {
              a_.AddParameter("k", C0, "", Range{Sym(a_, "h"), C1});
            }),
            "range of 'k': variable 'h' is not allowed here");
  EXPECT_FALSE(a_.symbols().Find("k"));  // nothing was declared
  // The bounds may be equal to the value.
  const int k = a_.AddParameter("k", C1, "", Range{C1, C1});
  EXPECT_EQ(a_.ParameterRange(k), (Range{C1, C1}));
}

// SetParameter keeps the range and refuses values outside it, for the parameter set and for
// every parameter defined from it, keeping the old value.
TEST_F(AutomatonTest, SetParameterStaysInTheDeclaredRange) {
  const Expression C0 = Expression::Constant(0);
  a_.AddParameter("gmax", Expression::Constant(256));
  const Range range{C0, Sym(a_, "gmax")};
  const int gob1 = a_.AddParameter("gob1", Expression::Constant(256), "count", range);
  a_.SetParameter("gob1", 80.0);
  EXPECT_EQ(a_.ParameterEnvironment()[gob1], 80.0);
  EXPECT_EQ(a_.ParameterRange(gob1), range);
  a_.SetParameter("gob1", 0.0);  // the bounds themselves are in the range
  a_.SetParameter("gob1", 200.0);
  EXPECT_EQ(InvalidArgumentMessage([&] { a_.SetParameter("gob1", 300.0); }),
            "value 300 of parameter 'gob1' is outside its range [0, 256]");
  EXPECT_EQ(InvalidArgumentMessage([&] { a_.SetParameter("gob1", -1.0); }),
            "value -1 of parameter 'gob1' is outside its range [0, 256]");
  EXPECT_EQ(a_.ParameterEnvironment()[gob1], 200.0);
  // Setting the parameter a range reads: the range follows.
  EXPECT_EQ(InvalidArgumentMessage([&] { a_.SetParameter("gmax", 100.0); }),
            "setting 'gmax' to 100 puts parameter 'gob1' (200) outside its "
            "range [0, 100]");
  EXPECT_EQ(InvalidArgumentMessage([&] { a_.SetParameter("gmax", -5.0); }),
            "setting 'gmax' to -5 makes the range of parameter 'gob1' "
            "empty");
  EXPECT_EQ(a_.ParameterEnvironment()[Slot("gmax")], 256.0);
  a_.SetParameter("gmax", 255.0);
  EXPECT_EQ(a_.ParameterEnvironment()[Slot("gmax")], 255.0);
  // A parameter defined from the one set must stay in its own range.
  a_.SetParameter("gob1", 100.0);
  a_.AddParameter("half", Sym(a_, "gob1") / Expression::Constant(2), "",
                  Range{C0, Expression::Constant(100)});
  EXPECT_EQ(InvalidArgumentMessage([&] { a_.SetParameter("gob1", 250.0); }),
            "setting 'gob1' to 250 puts parameter 'half' (125) outside "
            "its range [0, 100]");
  EXPECT_EQ(a_.ParameterEnvironment()[gob1], 100.0);
}

TEST_F(AutomatonTest, EqualityComparesParameterRanges) {
  Automaton with = a_, without = a_;
  const Expression C1 = Expression::Constant(1);
  with.AddParameter("k", C1, "", Range{Expression::Constant(0), C1});
  without.AddParameter("k", C1);
  EXPECT_NE(with, without);
  Automaton same = a_;
  same.AddParameter("k", C1, "", Range{Expression::Constant(0), C1});
  EXPECT_EQ(with, same);
}

TEST_F(AutomatonTest, RejectsFlowsOfNonVariablesAndUnsortedFlows) {
  Mode m;
  m.name = "m";
  m.flows = {{Slot("g"), Expression::Constant(1)}};
  ExpectInvalid([&] { a_.AddMode(m); }, "not a continuous variable");
  m.flows = {{Slot("v"), Expression::Constant(1)}, {Slot("h"), Expression::Constant(1)}};
  ExpectInvalid([&] { a_.AddMode(m); }, "not sorted");
  m.flows = {};
  m.name = "falling";
  ExpectInvalid([&] { a_.AddMode(m); }, "duplicate mode 'falling'");
}

TEST_F(AutomatonTest, RejectsExpressionsReadingUndeclaredSlots) {
  Mode m;
  m.name = "m";
  m.flows = {{Slot("h"), Expression::Symbol("ghost", 99)}};
  ExpectInvalid([&] { a_.AddMode(m); }, "undeclared slot 99");
}

TEST_F(AutomatonTest, DiscreteVariablesMustPrecedeModesAndBeSetByEveryMode) {
  ExpectInvalid([&] { a_.AddDiscreteVariable("c"); }, "after the first mode");
  Automaton b("b");
  b.AddDiscreteVariable("c");
  Mode m;
  m.name = "m";
  ExpectInvalid([&] { b.AddMode(m); }, "does not set discrete variable 'c'");
  m.discrete_values = {{0, 1}};
  EXPECT_NO_THROW(b.AddMode(m));
}

TEST_F(AutomatonTest, TransitionsNeedKnownModesAndResetVariables) {
  Transition t;
  t.name = "bounce";
  t.source = falling_;
  t.target = ModeId(7);
  ExpectInvalid([&] { a_.AddTransition(t); }, "unknown target mode");
  t.target = falling_;
  t.resets = {{Slot("u"), Expression::Constant(0)}};
  ExpectInvalid([&] { a_.AddTransition(t); }, "not a continuous variable");
  t.resets = {{Slot("v"), -Sym(a_, "v")}};
  EXPECT_EQ(a_.AddTransition(t), TransitionId(0));
  ExpectInvalid([&] { a_.AddTransition(t); }, "duplicate transition 'bounce'");
}

TEST_F(AutomatonTest, InitialStatesGiveEveryVariable) {
  InitialState s{falling_, {{Slot("h"), {Expression::Constant(1), Expression::Constant(1)}, true}}};
  ExpectInvalid([&] { a_.AddInitialState(s); }, "no value for 'v'");
  s.values.push_back({Slot("v"), {Expression::Constant(2), Expression::Constant(1)}, false});
  ExpectInvalid([&] { a_.AddInitialState(s); }, "empty initial range");
  s.values[1].range = {Expression::Constant(0), Expression::Constant(1)};
  EXPECT_NO_THROW(a_.AddInitialState(s));
  EXPECT_EQ(a_.initial_states().size(), 1u);
}

TEST_F(AutomatonTest, PropertiesMayNotReadInputsOrUnknownModes) {
  Property p{"p",
             Property::Kind::kAlways,
             Predicate::Compare({Sym(a_, "u"), Relation::kLess, Expression::Constant(0)}),
             {}};
  ExpectInvalid([&] { a_.AddProperty(p); }, "input 'u' is not allowed");
  p.predicate = Predicate::InMode("nowhere");
  ExpectInvalid([&] { a_.AddProperty(p); }, "unknown mode 'nowhere'");
  p.predicate = Predicate::InMode("falling");
  p.horizon = -1.0;
  ExpectInvalid([&] { a_.AddProperty(p); }, "horizon");
}

TEST_F(AutomatonTest, ScenarioSignalsStayInBoundsAndIncrease) {
  Scenario s{10.0, {{Slot("u"), InputSignal::Shape::kStep, {{0.0, 2.0}}}}};
  ExpectInvalid([&] { a_.SetScenario(s); }, "outside its bounds");
  s.inputs[0].points = {{0.0, 1.0}, {0.0, -1.0}};
  ExpectInvalid([&] { a_.SetScenario(s); }, "increase strictly");
  s.inputs[0].points = {{0.0, 1.0}, {5.0, -1.0}};
  s.until = 0.0;
  ExpectInvalid([&] { a_.SetScenario(s); }, "positive");
  s.until = 10.0;
  EXPECT_NO_THROW(a_.SetScenario(s));
}

// Expressions and predicates built in C++ are held to the model language's depth limit, like
// parsed ones: the solvers' recursive walks of them are sized for kMaxExpressionDepth.
TEST_F(AutomatonTest, ExpressionsDeeperThanTheModelLimitAreRefused) {
  const Expression h = Sym(a_, "h"), C0 = Expression::Constant(0);
  // h + h + ... with `levels` levels.
  auto sum = [&](const Expression& term, int levels) {
    Expression e = term;
    while (e.depth() < levels) e = e + term;
    return e;
  };
  const std::string too_deep = "expression too long or nested too deeply (" +
                               std::to_string(kMaxExpressionDepth + 1) + " levels, more than " +
                               std::to_string(kMaxExpressionDepth) + ")";
  Mode m;
  m.name = "deep";
  m.flows = {{Slot("h"), sum(h, kMaxExpressionDepth + 1)}};
  ExpectInvalid([&] { a_.AddMode(m); }, "flow of 'h' in mode 'deep': " + too_deep);
  m.flows = {};
  m.invariant.comparisons = {{sum(h, kMaxExpressionDepth), Relation::kLessEqual, C0}};
  ExpectInvalid([&] { a_.AddMode(m); }, "invariant of mode 'deep': " + too_deep);
  m.invariant.comparisons = {{sum(h, kMaxExpressionDepth - 1), Relation::kLessEqual, C0}};
  m.flows = {{Slot("h"), sum(h, kMaxExpressionDepth)}};
  EXPECT_NO_THROW(a_.AddMode(m));  // at the limit

  Transition t{"t", falling_, falling_, "", {}, {}, Urgency::kUrgent};
  t.guard.comparisons = {{C0, Relation::kLessEqual, sum(h, kMaxExpressionDepth)}};
  ExpectInvalid([&] { a_.AddTransition(t); }, "guard of 't': " + too_deep);
  t.guard.comparisons = {};
  t.resets = {{Slot("h"), sum(h, kMaxExpressionDepth + 1)}};
  ExpectInvalid([&] { a_.AddTransition(t); }, "reset of 'h' in 't': " + too_deep);
  ExpectInvalid(
      [&] { a_.AddParameter("k", sum(Expression::Constant(1), kMaxExpressionDepth + 1)); },
      "value of k: " + too_deep);

  Predicate deep = Predicate::Compare({h, Relation::kGreaterEqual, C0});  // 2 levels
  while (deep.depth() < kMaxExpressionDepth + 1) deep = Predicate::Not(deep);
  ExpectInvalid(
      [&] {
        a_.AddProperty({"p", Property::Kind::kAlways, deep, {}});
      },
      "property 'p': " + too_deep);
  EXPECT_NO_THROW(a_.AddProperty({"q", Property::Kind::kAlways, deep.operands()[0], {}}));
}

TEST_F(AutomatonTest, EqualityIsStructural) {
  Automaton copy = a_;
  EXPECT_EQ(copy, a_);
  copy.AddVariable("w");
  EXPECT_NE(copy, a_);
}

}  // namespace
}  // namespace hybrid
