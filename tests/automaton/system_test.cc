// Tests of System: renaming of components, shared names, composition errors, and the product
// automaton (synchronisation on labels, interleaving, mode names and counts, limits).

#include "hybrid/automaton/system.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

Automaton Parse(const std::string& text) { return ParseAutomaton(text, "test.ha"); }

// The message of the std::invalid_argument that `f` throws, or "" (and a failure) if none. The
// message must speak of the model only: no C++ name such as "System::SetParameter" (messages
// reach users as they are, e.g. after `hybrid simulate --set NAME=VALUE`).
template <class F>
std::string InvalidArgument(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find("::"), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument thrown";
  return "";
}

std::vector<std::string> SymbolNames(const SymbolTable& symbols) {
  std::vector<std::string> out;
  for (int i = 0; i < symbols.size(); ++i) out.push_back(symbols[i].name);
  return out;
}

std::set<std::string> ModeNames(const Automaton& a) {
  std::set<std::string> out;
  for (const Mode& m : a.modes()) out.insert(m.name);
  return out;
}

// "source -> target [label]" for every transition of `a`.
std::multiset<std::string> Edges(const Automaton& a) {
  std::multiset<std::string> out;
  for (const Transition& t : a.transitions()) {
    out.insert(a.mode(t.source).name + " -> " + a.mode(t.target).name +
               (t.label.empty() ? "" : " [" + t.label + "]"));
  }
  return out;
}

const Transition* FindEdge(const Automaton& a, const std::string& source,
                           const std::string& target) {
  for (const Transition& t : a.transitions()) {
    if (a.mode(t.source).name == source && a.mode(t.target).name == target) return &t;
  }
  return nullptr;
}

// A component with everything that gets renamed.
const char* const kTank = R"(
automaton tank {
  param k = 2;
  var x;
  discrete d;
  input u in [0, 1];
  mode low (d = 0) { x' = k * u; inv x <= 10; }
  mode high (d = 1) { x' = -1; }
  transition low -> high { guard x >= 10; reset x := x - 1; label full; }
  transition high -> low { guard x <= 0; lazy; }
  init low { x = 0; }
  property bounded: always x <= 10 and d >= 0;
  property high_reached: reach in high;
}
)";

// Two modes p0/p1 (names prefixed by `prefix`) over variable `var`; p0 -> p1 labelled `label`
// (when non-empty) with the given urgency, p1 -> p0 unlabelled.
Automaton Toggle(const std::string& name, const std::string& prefix, const std::string& var,
                 const std::string& label, bool lazy = false) {
  std::string text = "automaton " + name + " {\n  var " + var + ";\n";
  text += "  mode " + prefix + "0 { " + var + "' = 1; inv " + var + " <= 5; }\n";
  text += "  mode " + prefix + "1 { " + var + "' = -1; }\n";
  text += "  transition " + prefix + "0 -> " + prefix + "1 { guard " + var + " >= 1; reset " + var +
          " := 0; " + (label.empty() ? "" : "label " + label + "; ") + (lazy ? "lazy; " : "") +
          "}\n";
  text += "  transition " + prefix + "1 -> " + prefix + "0 { guard " + var + " <= -1; }\n";
  text += "  init " + prefix + "0 { " + var + " = 0; }\n}\n";
  return Parse(text);
}

// ---------------------------------------------------------------------------------------------
// Renaming and sharing.

TEST(System, InstanceNamesPrefixSymbolsAndLabels) {
  const Automaton tank = Parse(kTank);
  System s("plant");
  s.AddComponent("A", tank);
  ASSERT_EQ(s.components().size(), 1u);
  const Component& c = s.components()[0];
  EXPECT_EQ(c.instance, "A");
  EXPECT_EQ(SymbolNames(c.automaton.symbols()),
            (std::vector<std::string>{"A.k", "A.x", "A.d", "A.u"}));
  EXPECT_EQ(SymbolNames(s.symbols()), (std::vector<std::string>{"A.k", "A.x", "A.d", "A.u"}));
  EXPECT_EQ(c.global_slot, (std::vector<int>{0, 1, 2, 3}));
  // Units and kinds are kept.
  EXPECT_EQ(s.symbols()[3].kind, SymbolKind::kInput);
  // Mode names are not renamed; they are qualified at system level.
  EXPECT_EQ(ModeNames(c.automaton), (std::set<std::string>{"low", "high"}));
  EXPECT_EQ(s.QualifiedModeName(0, ModeId(1)), "A.high");
  EXPECT_EQ(s.FindMode("A.high"), std::make_optional(std::make_pair(0, ModeId(1))));
  EXPECT_FALSE(s.FindMode("high").has_value());
  EXPECT_FALSE(s.FindMode("B.high").has_value());
  // Labels, expressions and properties use the qualified names.
  EXPECT_EQ(c.automaton.transitions()[0].label, "A.full");
  EXPECT_EQ(c.automaton.modes()[0].flows[0].second.ToString(), "A.k * A.u");
  EXPECT_EQ(c.automaton.transitions()[0].resets[0].value.ToString(), "A.x - 1");
  EXPECT_EQ(c.automaton.properties()[0].predicate.ToString(), "A.x <= 10 and A.d >= 0");
  // The source is the automaton as declared.
  EXPECT_EQ(c.source, tank);
  EXPECT_EQ(c.source.transitions()[0].label, "full");
}

TEST(System, BindsNameOneInstanceAfterAnother) {
  // The controller's motor position and label become the plant's: one variable, one label.
  System s("pair");
  s.AddComponent("A", Toggle("plant", "p", "x", "go"));
  const Automaton controller = Parse(R"(
automaton controller {
  var y;
  mode c0 { }
  mode c1 { }
  transition c0 -> c1 { guard y >= 1; label go; }
  init c0 { y = 0; }
})");
  s.AddComponent("ctl", controller, {{"y", "A.x"}, {"go", "A.go"}});
  const Component& c = s.components()[1];
  EXPECT_EQ(SymbolNames(c.automaton.symbols()), (std::vector<std::string>{"A.x"}));
  EXPECT_EQ(SymbolNames(s.symbols()), (std::vector<std::string>{"A.x"}));
  EXPECT_EQ(c.global_slot, (std::vector<int>{0}));
  EXPECT_EQ(c.automaton.transitions()[0].label, "A.go");
  EXPECT_EQ(c.binds.at("y"), "A.x");
  EXPECT_EQ(s.QualifiedModeName(1, ModeId(0)), "ctl.c0");
}

TEST(System, BoundNamesSynchroniseLikeSharedOnes) {
  // Two plant-controller pairs: each controller synchronises with its own plant only, where
  // `share go` would join all four.
  System s("pairs");
  const Automaton plant = Toggle("plant", "p", "x", "go", /*lazy=*/true);
  const Automaton controller = Toggle("controller", "c", "y", "go", /*lazy=*/true);
  s.AddComponent("A", plant);
  s.AddComponent("B", plant);
  s.AddComponent("ctlA", controller, {{"go", "A.go"}});
  s.AddComponent("ctlB", controller, {{"go", "B.go"}});
  const Automaton p = s.Product();
  // Labelled product transitions, without their "tN_" prefix.
  std::set<std::string> joint;
  for (const Transition& t : p.transitions()) {
    if (!t.label.empty()) joint.insert(t.name.substr(t.name.find('_') + 1));
  }
  EXPECT_EQ(joint,
            (std::set<std::string>{"A_p0_to_p1__ctlA_c0_to_c1", "B_p0_to_p1__ctlB_c0_to_c1"}));
}

TEST(System, BindErrors) {
  const Automaton plant = Toggle("plant", "p", "x", "go");
  System s("pair");
  s.Share("go");
  s.AddComponent("A", plant);
  EXPECT_EQ(InvalidArgument([&] {
              s.AddComponent("B", plant, {{"z", "A.x"}});
            }),
            "bind 'z': 'plant' has no variable, input, parameter or label 'z'");
  EXPECT_EQ(InvalidArgument([&] {
              s.AddComponent("B", plant, {{"go", "A.go"}});
            }),
            "bind 'go': the name is shared; it cannot be bound");
  EXPECT_EQ(InvalidArgument([&] {
              s.AddComponent("B", plant, {{"x", ""}});
            }),
            "bind 'x': bound to an empty name");
  // Both instances would give A.x a flow.
  EXPECT_NE(InvalidArgument([&] {
              s.AddComponent("B", plant, {{"x", "A.x"}});
            }).find("flow"),
            std::string::npos);
  EXPECT_EQ(s.components().size(), 1u);
  const Automaton two =
      Parse("automaton two { var x; var y; mode m { x' = 1; } init m { x = 0; y = 0; } }");
  EXPECT_EQ(InvalidArgument([&] {
              s.AddComponent("C", two, {{"x", "C.y"}});
            }),
            "'x' and 'y' of 'two' would both be named 'C.y'");
}

TEST(System, EmptyInstanceNameKeepsNames) {
  const Automaton tank = Parse(kTank);
  System s("plant");
  s.AddComponent("", tank);
  EXPECT_EQ(SymbolNames(s.symbols()), (std::vector<std::string>{"k", "x", "d", "u"}));
  EXPECT_EQ(s.QualifiedModeName(0, ModeId(0)), "low");
  EXPECT_EQ(s.FindMode("high"), std::make_optional(std::make_pair(0, ModeId(1))));
  EXPECT_EQ(s.components()[0].automaton.transitions()[0].label, "full");
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("", tank); }),
            "two unnamed instances (at most one instance may keep its names)");
}

TEST(System, OfKeepsPropertiesAndScenario) {
  const System s = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  const Automaton& finger = s.components()[0].source;
  const System of = System::Of(finger);
  EXPECT_EQ(of.name(), "finger");
  EXPECT_EQ(of.properties().size(), finger.properties().size());
  EXPECT_EQ(of.scenario(), finger.scenario());
  EXPECT_EQ(of, s);
}

TEST(System, DuplicateInstanceIsAnError) {
  const Automaton tank = Parse(kTank);
  System s("plant");
  s.AddComponent("A", tank);
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("A", tank); }), "duplicate instance 'A'");
  EXPECT_EQ(s.components().size(), 1u);
}

// SetParameter sets a qualified parameter in its component only, and a shared one everywhere.
TEST(System, SetParameterByQualifiedOrSharedName) {
  const Automaton tank = Parse(kTank);
  System s("plant");
  s.AddComponent("A", tank);
  s.AddComponent("B", tank);
  s.SetParameter("A.k", 5.0);
  EXPECT_EQ(s.components()[0].automaton.ParameterEnvironment()[0], 5.0);
  EXPECT_EQ(s.components()[0].source.ParameterEnvironment()[0], 5.0);  // printed back as set
  EXPECT_EQ(s.components()[1].automaton.ParameterEnvironment()[0], 2.0);
  EXPECT_THROW(s.SetParameter("k", 1.0), std::invalid_argument);    // no component has plain k
  EXPECT_THROW(s.SetParameter("A.x", 1.0), std::invalid_argument);  // a variable
  System shared("plant");
  shared.Share("k");
  shared.AddComponent("A", tank);
  shared.AddComponent("B", tank);
  shared.SetParameter("k", 7.0);
  for (const Component& c : shared.components()) {
    EXPECT_EQ(c.automaton.ParameterEnvironment()[0], 7.0);
  }
}

TEST(System, SharedVariablesAndInputsAreOneSymbol) {
  const Automaton tank = Parse(kTank);
  const Automaton reader = Parse(R"(
automaton reader {
  var y, x;
  input u in [0, 1];
  mode r { y' = x + u; }
  init r { y = 0; x = 0; }
})");
  System s("plant");
  s.Share("x");
  s.Share("u");
  s.AddComponent("A", tank);
  s.AddComponent("B", reader);
  EXPECT_EQ(SymbolNames(s.symbols()), (std::vector<std::string>{"A.k", "x", "A.d", "u", "B.y"}));
  EXPECT_EQ(s.components()[0].global_slot, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(s.components()[1].global_slot, (std::vector<int>{4, 1, 3}));
  EXPECT_EQ(s.components()[1].automaton.modes()[0].flows[0].second.ToString(), "x + u");

  // In the product, B's flow reads the variable that A's flow drives.
  const Automaton p = s.Product();
  EXPECT_EQ(SymbolNames(p.symbols()), SymbolNames(s.symbols()));
  EXPECT_EQ(p.variables().size(), 2u);
  EXPECT_EQ(p.inputs().size(), 1u);
  const Mode& m = p.modes()[0];
  ASSERT_EQ(m.flows.size(), 2u);
  EXPECT_EQ(m.flows[0].first, 1);
  EXPECT_EQ(m.flows[0].second.ToString(), "A.k * u");
  EXPECT_EQ(m.flows[1].first, 4);
  EXPECT_EQ(m.flows[1].second.ToString(), "x + u");
  EXPECT_EQ(m.flows[1].second.Slots(), (std::vector<int>{1, 3}));
}

TEST(System, SharedNameWithDifferentKindsIsAnError) {
  const Automaton a = Parse("automaton a { var x; mode m { x' = 1; } init m { x = 0; } }");
  const Automaton b =
      Parse("automaton b { input x in [0, 1]; var y; mode n { y' = x; } init n { y = 0; } }");
  System s("s");
  s.Share("x");
  s.AddComponent("A", a);
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("B", b); }),
            "'x' is an input in 'b' but a variable elsewhere");
  System t("t");
  t.Share("x");
  t.AddComponent("B", b);
  EXPECT_EQ(InvalidArgument([&] { t.AddComponent("A", a); }),
            "'x' is a variable in 'a' but an input elsewhere");
}

TEST(System, OnlyOneComponentMayGiveASharedVariableAFlow) {
  const Automaton writer = Parse("automaton w { var x; mode m { x' = 1; } init m { x = 0; } }");
  const Automaton reader =
      Parse("automaton r { var x, y; mode m { y' = x; } init m { x = 0; y = 0; } }");
  {
    System s("s");
    s.Share("x");
    s.AddComponent("A", writer);
    EXPECT_EQ(InvalidArgument([&] { s.AddComponent("B", writer); }),
              "shared variable 'x' has flows in two components");
  }
  {
    System s("s");
    s.Share("x");
    s.AddComponent("A", writer);
    EXPECT_NO_THROW(s.AddComponent("B", reader));
    EXPECT_NO_THROW(s.AddComponent("C", reader));
  }
  {
    System s("s");
    s.Share("x");
    s.AddComponent("B", reader);
    EXPECT_NO_THROW(s.AddComponent("A", writer));
    EXPECT_EQ(InvalidArgument([&] { s.AddComponent("C", writer); }),
              "shared variable 'x' has flows in two components");
  }
  {
    // Not shared: two independent variables A.x and B.x.
    System s("s");
    s.AddComponent("A", writer);
    EXPECT_NO_THROW(s.AddComponent("B", writer));
    EXPECT_EQ(SymbolNames(s.symbols()), (std::vector<std::string>{"A.x", "B.x"}));
  }
}

// A gripper-like component with an uncertain parameter whose range reads another parameter.
const char* const kContact = R"(
automaton contact {
  param gmax [count] = 256;
  param gob1 [count] = 256 in [0, gmax];
  var theta1 [deg], g;
  mode moving { theta1' = 1; g' = 1; inv g <= gob1; }
  init moving { theta1 = 0; g = 0; }
}
)";

// Renaming qualifies the range's expressions with the parameter; SetParameter keeps it and
// refuses values outside it; the product keeps it too.
TEST(System, ParameterRangeSurvivesComposition) {
  const Automaton contact = Parse(kContact);
  System s("hand");
  s.AddComponent("A", contact);
  s.AddComponent("B", contact);
  const Component& a = s.components()[0];
  const int gob1 = *a.automaton.symbols().Find("A.gob1");
  const std::optional<Range> range = a.automaton.ParameterRange(gob1);
  ASSERT_TRUE(range.has_value());
  EXPECT_EQ(range->lo, Expression::Constant(0));
  EXPECT_EQ(range->hi, Expression::Symbol("A.gmax", 0));
  EXPECT_EQ(a.source.ParameterRange(gob1), contact.ParameterRange(gob1));
  EXPECT_FALSE(a.automaton.ParameterRange(0).has_value());  // A.gmax has none

  s.SetParameter("A.gob1", 80.0);
  EXPECT_EQ(s.components()[0].automaton.ParameterEnvironment()[gob1], 80.0);
  EXPECT_EQ(s.components()[0].source.ParameterEnvironment()[gob1], 80.0);
  EXPECT_EQ(s.components()[0].automaton.ParameterRange(gob1), range);
  EXPECT_EQ(InvalidArgument([&] { s.SetParameter("A.gob1", 300.0); }),
            "value 300 of parameter 'A.gob1' is "
            "outside its range [0, 256]");
  EXPECT_EQ(s.components()[0].automaton.ParameterEnvironment()[gob1], 80.0);

  const Automaton product = s.Product();
  const int global = *product.symbols().Find("B.gob1");
  const std::optional<Range> product_range = product.ParameterRange(global);
  ASSERT_TRUE(product_range.has_value());
  EXPECT_EQ(product_range->hi, Expression::Symbol("B.gmax", *product.symbols().Find("B.gmax")));
  EXPECT_EQ(product.ParameterEnvironment()[*product.symbols().Find("A.gob1")], 80.0);
  EXPECT_EQ(product.ParameterRange(*product.symbols().Find("A.gob1")),
            (Range{Expression::Constant(0),
                   Expression::Symbol("A.gmax", *product.symbols().Find("A.gmax"))}));
}

// A shared parameter is one constant: its range must be the same (or absent) everywhere.
TEST(System, SharedParameterRangesMustAgree) {
  auto with_range = [](const std::string& name, const std::string& range) {
    return Parse("automaton " + name + " { param k = 2" + range +
                 "; var x; mode m { x' = k; } init m { x = 0; } }");
  };
  System s("s");
  s.Share("k");
  s.AddComponent("A", with_range("a", " in [0, 4]"));
  EXPECT_NO_THROW(s.AddComponent("B", with_range("b", " in [0, 2 * 2]")));
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("C", with_range("c", " in [1, 4]")); }),
            "shared parameter 'k' has range [1, 4] in 'c' but [0, 4] in "
            "'a'");
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("D", with_range("d", "")); }),
            "shared parameter 'k' has range none in 'd' but [0, 4] in 'a'");
  s.SetParameter("k", 3.0);
  EXPECT_EQ(InvalidArgument([&] { s.SetParameter("k", 5.0); }),
            "value 5 of parameter 'k' is outside "
            "its range [0, 4]");
}

// A value one component refuses (a parameter defined from it would leave its range) is set in
// none: a shared parameter stays one value.
TEST(System, SetParameterIsAllOrNothing) {
  System s("s");
  s.Share("k");
  s.AddComponent("B", Parse("automaton b { param k = 2; var x; mode m { x' = k; } "
                            "init m { x = 0; } }"));
  s.AddComponent("A", Parse("automaton a { param k = 2; param half = k / 2 in [0, 1]; var x; "
                            "mode m { x' = half; } init m { x = 0; } }"));
  EXPECT_EQ(InvalidArgument([&] { s.SetParameter("k", 4.0); }),
            "setting 'k' to 4 puts parameter "
            "'A.half' (2) outside its range [0, 1]");
  for (const Component& c : s.components()) {
    EXPECT_EQ(c.automaton.ParameterEnvironment()[0], 2.0) << c.instance;
    EXPECT_EQ(c.source.ParameterEnvironment()[0], 2.0) << c.instance;
  }
  s.SetParameter("k", 1.0);
  EXPECT_EQ(s.components()[0].automaton.ParameterEnvironment()[0], 1.0);
  EXPECT_EQ(s.components()[1].automaton.ParameterEnvironment()[1], 0.5);
}

// SetInitialValue sets a variable's initial point in every initial state of every component
// that has it, in the renamed automaton and the source alike.
TEST(System, SetInitialValueByQualifiedOrSharedName) {
  const Automaton contact = Parse(kContact);
  // Reads the shared g without giving it a flow; g is its slot 0.
  const Automaton watch =
      Parse("automaton watch { var g; mode w { inv g <= 300; } init w { g = 0; } }");
  System s("hand");
  s.AddComponent("B", contact);  // before the share: B.g is its own
  s.Share("g");
  s.AddComponent("A", contact);
  s.AddComponent("W", watch);
  const int theta1 = *contact.symbols().Find("theta1");
  const int g = *contact.symbols().Find("g");
  // The value of `slot` in the first initial state of `a`.
  auto initial_of = [](const Automaton& a, int slot) {
    const InitialState& init = a.initial_states()[0];
    const auto it = std::find_if(init.values.begin(), init.values.end(),
                                 [&](const InitialValue& v) { return v.slot == slot; });
    return it == init.values.end() ? InitialValue{} : *it;
  };
  auto initial = [&](int component, int slot) {
    return initial_of(s.components()[component].automaton, slot);
  };
  s.SetInitialValue("A.theta1", 12.5);
  const Expression point = Expression::Constant(12.5);
  EXPECT_EQ(initial(1, theta1), (InitialValue{theta1, Range{point, point}, true}));
  EXPECT_EQ(initial(0, theta1).range.lo, Expression::Constant(0));  // B untouched
  EXPECT_EQ(s.components()[1].source.initial_states()[0].values,
            s.components()[1].automaton.initial_states()[0].values);
  s.SetInitialValue("g", -3.0);  // shared: A and W
  EXPECT_EQ(initial(1, g).range.lo, Expression::Constant(-3));
  EXPECT_EQ(initial(2, 0).range.lo, Expression::Constant(-3));
  EXPECT_EQ(initial(0, g).range.lo, Expression::Constant(0));  // B.g untouched
  s.SetInitialValue("B.g", 7.0);
  EXPECT_EQ(initial(0, g).range.lo, Expression::Constant(7));
  EXPECT_EQ(initial_of(s.components()[2].source, 0).range.hi, Expression::Constant(-3));
  // The product starts there.
  const Automaton product = s.Product();
  EXPECT_EQ(initial_of(product, *product.symbols().Find("A.theta1")).range.lo, point);
  EXPECT_EQ(initial_of(product, *product.symbols().Find("B.theta1")).range.lo,
            Expression::Constant(0));
  EXPECT_EQ(initial_of(product, *product.symbols().Find("g")).range.lo, Expression::Constant(-3));

  EXPECT_EQ(InvalidArgument([&] { s.SetInitialValue("theta1", 1.0); }),
            "no component has a continuous variable 'theta1'");
  EXPECT_EQ(InvalidArgument([&] { s.SetInitialValue("A.nope", 1.0); }),
            "no component has a continuous variable 'A.nope'");
  EXPECT_EQ(InvalidArgument([&] { s.SetInitialValue("A.gob1", 1.0); }),
            "no component has a continuous variable 'A.gob1'");
  EXPECT_EQ(InvalidArgument([&] { s.SetInitialValue("A.theta1", std::nan("")); }),
            "initial value of 'A.theta1' is not finite");
  EXPECT_EQ(initial(1, theta1).range.lo, point);
}

TEST(System, SharedParametersMustAgree) {
  auto with_k = [](const std::string& name, const std::string& k) {
    return Parse("automaton " + name + " { param k = " + k +
                 "; var x; mode m { x' = k; } init m { x = 0; } }");
  };
  System s("s");
  s.Share("k");
  s.AddComponent("A", with_k("a", "2"));
  EXPECT_NO_THROW(s.AddComponent("B", with_k("b", "4 / 2")));
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("C", with_k("c", "3")); }),
            "shared parameter 'k' is 3 in 'c' but 2 in 'a'");
}

// ---------------------------------------------------------------------------------------------
// Product.

TEST(Product, SynchronisedLabelFiresOnlyJointly) {
  System s("sync");
  s.Share("go");
  s.AddComponent("A", Toggle("a", "a", "x", "go"));
  s.AddComponent("B", Toggle("b", "b", "y", "go"));
  const Automaton p = s.Product();
  EXPECT_EQ(p.name(), "sync");
  EXPECT_EQ(ModeNames(p), (std::set<std::string>{"a0__b0", "a1__b1", "a0__b1", "a1__b0"}));
  EXPECT_EQ(p.mode(p.initial_states()[0].mode).name, "a0__b0");
  // From a0__b0 only the joint step; a0__b1 and a1__b0 are reached by the unlabelled returns, and
  // there the labelled transition is blocked because the partner cannot take part.
  EXPECT_EQ(Edges(p), (std::multiset<std::string>{
                          "a0__b0 -> a1__b1 [go]",
                          "a1__b1 -> a0__b1",
                          "a1__b1 -> a1__b0",
                          "a0__b1 -> a0__b0",
                          "a1__b0 -> a0__b0",
                      }));
  const Transition* joint = FindEdge(p, "a0__b0", "a1__b1");
  ASSERT_NE(joint, nullptr);
  EXPECT_EQ(joint->name, "t0_A_a0_to_a1__B_b0_to_b1");
  // Guards conjoined, resets applied together.
  EXPECT_EQ(joint->guard.ToString(), "A.x >= 1 and B.y >= 1");
  ASSERT_EQ(joint->resets.size(), 2u);
  EXPECT_EQ(p.symbols()[joint->resets[0].slot].name, "A.x");
  EXPECT_EQ(p.symbols()[joint->resets[1].slot].name, "B.y");
  EXPECT_EQ(joint->urgency, Urgency::kUrgent);
  // Flows are the union, invariants the conjunction.
  const Mode& initial = p.modes()[p.initial_states()[0].mode.value()];
  EXPECT_EQ(initial.flows.size(), 2u);
  EXPECT_EQ(initial.invariant.ToString(), "A.x <= 5 and B.y <= 5");
  EXPECT_EQ(p.initial_states()[0].values.size(), 2u);
}

TEST(Product, JointUrgencyIsLazyOnlyWhenEveryPartIsLazy) {
  for (const bool a_lazy : {false, true}) {
    for (const bool b_lazy : {false, true}) {
      System s("sync");
      s.Share("go");
      s.AddComponent("A", Toggle("a", "a", "x", "go", a_lazy));
      s.AddComponent("B", Toggle("b", "b", "y", "go", b_lazy));
      const Automaton p = s.Product();
      const Transition* joint = FindEdge(p, "a0__b0", "a1__b1");
      ASSERT_NE(joint, nullptr);
      EXPECT_EQ(joint->urgency, a_lazy && b_lazy ? Urgency::kLazy : Urgency::kUrgent)
          << a_lazy << b_lazy;
    }
  }
}

TEST(Product, ComponentsWithoutTheLabelInterleave) {
  System s("sync");
  s.Share("go");
  s.AddComponent("A", Toggle("a", "a", "x", "go"));
  s.AddComponent("B", Toggle("b", "b", "y", "go"));
  s.AddComponent("C", Toggle("c", "c", "z", ""));
  const Automaton p = s.Product();
  EXPECT_EQ(p.num_modes(), 8);
  EXPECT_TRUE(ModeNames(p).count("a0__b0__c1"));
  // From the initial tuple: the joint step of A and B (C stays), or C alone.
  std::multiset<std::string> from_initial;
  for (const std::string& e : Edges(p)) {
    if (e.starts_with("a0__b0__c0 ->")) from_initial.insert(e);
  }
  EXPECT_EQ(from_initial, (std::multiset<std::string>{"a0__b0__c0 -> a1__b1__c0 [go]",
                                                      "a0__b0__c0 -> a0__b0__c1"}));
  // A never moves alone along its labelled transition.
  for (const Transition& t : p.transitions()) {
    const std::string source = p.mode(t.source).name, target = p.mode(t.target).name;
    if (source[1] == '0' && target[1] == '1') {
      EXPECT_EQ(target[5], '1') << source << " -> " << target;
    }
  }
}

TEST(Product, LabelNotSharedIsRenamedSoTransitionsInterleave) {
  System s("free");
  s.AddComponent("A", Toggle("a", "a", "x", "go"));
  s.AddComponent("B", Toggle("b", "b", "y", "go"));
  const Automaton p = s.Product();
  EXPECT_EQ(p.num_modes(), 4);
  std::multiset<std::string> from_initial;
  for (const std::string& e : Edges(p)) {
    if (e.starts_with("a0__b0 ->")) from_initial.insert(e);
  }
  EXPECT_EQ(from_initial,
            (std::multiset<std::string>{"a0__b0 -> a1__b0 [A.go]", "a0__b0 -> a0__b1 [B.go]"}));
}

TEST(Product, LabelThatNoOtherComponentUsesIsTakenAlone) {
  System s("alone");
  s.Share("go");
  s.AddComponent("A", Toggle("a", "a", "x", "go"));
  s.AddComponent("B", Toggle("b", "b", "y", "stop"));
  const Automaton p = s.Product();
  EXPECT_EQ(p.num_modes(), 4);
  EXPECT_NE(FindEdge(p, "a0__b0", "a1__b0"), nullptr);
  EXPECT_NE(FindEdge(p, "a0__b0", "a0__b1"), nullptr);
  EXPECT_EQ(FindEdge(p, "a0__b0", "a1__b1"), nullptr);
}

TEST(Product, EveryPartnerCombinationIsATransition) {
  // A has one `go` transition, B two from the same mode: two joint transitions.
  const Automaton b = Parse(R"(
automaton b {
  var y;
  mode b0 { y' = 1; }
  mode b1 { }
  mode b2 { }
  transition b0 -> b1 { label go; }
  transition b0 -> b2 { label go; }
  init b0 { y = 0; }
})");
  System s("s");
  s.Share("go");
  s.AddComponent("A", Toggle("a", "a", "x", "go"));
  s.AddComponent("B", b);
  const Automaton p = s.Product();
  EXPECT_NE(FindEdge(p, "a0__b0", "a1__b1"), nullptr);
  EXPECT_NE(FindEdge(p, "a0__b0", "a1__b2"), nullptr);
  EXPECT_EQ(FindEdge(p, "a0__b0", "a0__b1"), nullptr);
  EXPECT_EQ(FindEdge(p, "a0__b0", "a1__b0"), nullptr);
  EXPECT_EQ(p.num_modes(), 5);  // a0__b0, a1__b1, a1__b2, a0__b1, a0__b2
}

TEST(Product, SynchronisedResetsOfOneSharedVariableAreAnError) {
  const Automaton a = Parse(R"(
automaton a {
  var x;
  mode m { x' = 1; }
  mode n { }
  transition m -> n { reset x := 0; label go; }
  init m { x = 0; }
})");
  const Automaton b = Parse(R"(
automaton b {
  var x;
  mode m { }
  mode n { }
  transition m -> n { reset x := 1; label go; }
  init m { x = 0; }
})");
  System s("s");
  s.Share("x");
  s.Share("go");
  s.AddComponent("A", a);
  // Refused when the second writer joins, so that no engine picks one of the writes.
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("B", b); }),
            "transition 'm_to_n' of instance 'B' and 'm_to_n' of instance 'A' synchronise on 'go' "
            "and both reset 'x': only one of them may write it");
  EXPECT_EQ(s.components().size(), 1u);
}

// The index of the earlier component a ConflictError names, or -1 if `f` throws none.
template <typename F>
int ConflictWith(F&& f) {
  try {
    f();
  } catch (const ConflictError& e) {
    return e.other_component();
  }
  return -1;
}

TEST(System, ASharedVariableStartedAtTwoValuesIsRefused) {
  const Automaton a =
      Parse("automaton a { var x, k; mode m { x' = 1; } init m { x = 0; k = 0; } }");
  const Automaton b =
      Parse("automaton b { var y, k; mode p { y' = 1; } init p { y = 0; k = 5; } }");
  const Automaton same = Parse("automaton c { var k; mode q { } init q { k = 0; } }");
  System s("s");
  s.Share("k");
  s.AddComponent("A", a);
  s.AddComponent("C", same);  // agrees: accepted
  EXPECT_EQ(InvalidArgument([&] { s.AddComponent("B", b); }),
            "shared variable 'k' starts at 5 in instance 'B' but at 0 in instance 'A': give every "
            "instance one start");
  EXPECT_EQ(ConflictWith([&] { s.AddComponent("B", b); }), 0);
}

TEST(System, ABoundInputWithOtherBoundsIsRefused) {
  const Automaton host =
      Parse("automaton host { input v in [0, 10]; var z; mode h { z' = v; } init h { z = 0; } }");
  const Automaton proc =
      Parse("automaton proc { input u in [0, 1]; var x; mode a { x' = u; } init a { x = 0; } }");
  System s("s");
  s.AddComponent("H", host);
  EXPECT_EQ(InvalidArgument([&] {
              s.AddComponent("B", proc, {{"u", "H.v"}});
            }),
            "shared input 'H.v' is in [0, 1] in instance 'B' but in [0, 10] in instance 'H': "
            "declare the same bounds");
}

TEST(System, ADiscreteVariableSetByTheModesOfTwoInstancesIsRefused) {
  const Automaton a = Parse(
      "automaton a { discrete c; var x; mode m (c = 0) { x' = 1; } mode n (c = 1) { } "
      "transition m -> n { guard x >= 1; } init m { x = 0; } }");
  const Automaton b =
      Parse("automaton b { discrete c; var y; mode p (c = 5) { } init p { y = 0; } }");
  System s("s");
  s.Share("c");
  s.AddComponent("A", a);
  EXPECT_EQ(ConflictWith([&] { s.AddComponent("B", b); }), 0);
  System t("t");  // in either order
  t.Share("c");
  t.AddComponent("B", b);
  EXPECT_EQ(InvalidArgument([&] { t.AddComponent("A", a); }),
            "shared discrete variable 'c' is given values by the modes of both instance 'A' and "
            "instance 'B': one instance must own it");
}

TEST(System, ResolvedParameterIsAFunctionOfTheUncertainOnes) {
  const Automaton a = Parse(
      "automaton a { param p = 1 in [0, 2]; param k = 3; param q = 2 * p + k; param r = k * k; "
      "var x; mode m { x' = q; } init m { x = 0; } }");
  const System s = System::Of(a);
  const int p = *s.symbols().Find("p"), q = *s.symbols().Find("q"), r = *s.symbols().Find("r");
  EXPECT_EQ(s.ResolvedParameter(p), Expression::Symbol("p", p));
  const Expression resolved = s.ResolvedParameter(q);
  EXPECT_EQ(resolved.Slots(), std::vector<int>{p});
  for (double value : {0.0, 0.5, 2.0}) {  // 2p + 3, by evaluation at p
    std::vector<double> env(static_cast<std::size_t>(s.symbols().size()), 0.0);
    env[static_cast<std::size_t>(p)] = value;
    EXPECT_DOUBLE_EQ(resolved.Evaluate(env), 2 * value + 3);
  }
  EXPECT_EQ(s.ResolvedParameter(r), Expression::Constant(9));
  EXPECT_THROW(s.ResolvedParameter(*s.symbols().Find("x")), std::invalid_argument);
}

TEST(System, AlphabetIsTheLabelsOfAComponentsTransitions) {
  const Automaton a = Parse(R"(
automaton a { var x; mode m { x' = 1; } mode n { }
  transition m -> n { guard x >= 1; label go; } transition n -> m { label back; } init m { x = 0; } })");
  System s("s");
  s.Share("go");
  s.AddComponent("A", a);
  EXPECT_EQ(s.Alphabet(0), (std::set<std::string>{"A.back", "go"}));
  EXPECT_THROW(s.Alphabet(1), std::out_of_range);
}

TEST(Product, InitialStatesAreTheCartesianProduct) {
  const Automaton two_starts = Parse(R"(
automaton a {
  var x;
  mode m { x' = 1; }
  mode n { x' = 2; }
  init m { x = 0; }
  init n { x in [1, 2]; }
})");
  System s("s");
  s.AddComponent("A", two_starts);
  s.AddComponent("B", Toggle("b", "b", "y", ""));
  const Automaton p = s.Product();
  ASSERT_EQ(p.initial_states().size(), 2u);
  EXPECT_EQ(p.mode(p.initial_states()[0].mode).name, "m__b0");
  EXPECT_EQ(p.mode(p.initial_states()[1].mode).name, "n__b0");
  EXPECT_FALSE(p.initial_states()[1].values[0].is_point);
  EXPECT_EQ(p.num_modes(), 4);
}

TEST(Product, ModeCountAndLimit) {
  System s("s");
  s.AddComponent("A", Toggle("a", "a", "x", ""));
  s.AddComponent("B", Toggle("b", "b", "y", ""));
  s.AddComponent("C", Toggle("c", "c", "z", ""));
  EXPECT_EQ(s.Product().num_modes(), 8);
  EXPECT_EQ(s.Product(8).num_modes(), 8);
  EXPECT_EQ(InvalidArgument([&] { s.Product(7); }),
            "the composed system has more than 7 product modes");
  EXPECT_EQ(InvalidArgument([&] { s.Product(1); }),
            "the composed system has more than 1 product modes");
}

TEST(Product, OnlyReachableTuplesBecomeModes) {
  // B cannot leave b0 (no transitions), so no tuple with b1 exists.
  const Automaton stuck = Parse(R"(
automaton b {
  var y;
  mode b0 { y' = 1; }
  mode b1 { }
  init b0 { y = 0; }
})");
  System s("s");
  s.AddComponent("A", Toggle("a", "a", "x", ""));
  s.AddComponent("B", stuck);
  EXPECT_EQ(ModeNames(s.Product()), (std::set<std::string>{"a0__b0", "a1__b0"}));
}

TEST(Product, SingleComponentProductIsTheAutomaton) {
  const System finger = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  const Automaton& a = finger.components()[0].automaton;
  const Automaton p = finger.Product();
  EXPECT_EQ(p.num_modes(), 31);
  EXPECT_EQ(p.num_modes(), a.num_modes());
  EXPECT_EQ(p.num_transitions(), a.num_transitions());
  EXPECT_EQ(ModeNames(p), ModeNames(a));
  EXPECT_EQ(SymbolNames(p.symbols()), SymbolNames(a.symbols()));
  EXPECT_EQ(p.properties().size(), a.properties().size());
  EXPECT_EQ(p.scenario(), a.scenario());
}

TEST(Product, PropertiesWithModeAtomsStayOnTheSystem) {
  System s = ParseModel(R"(
automaton a { var x; mode m { x' = 1; } mode n { } transition m -> n { } init m { x = 0; } }
system s {
  instance A = a;
  instance B = a;
  property both: reach in A.n and in B.n;
  property small: always A.x <= 1;
}
)",
                        "s.ha");
  EXPECT_EQ(s.properties().size(), 2u);
  const Automaton p = s.Product();
  ASSERT_EQ(p.properties().size(), 1u);
  EXPECT_EQ(p.properties()[0].name, "small");
}

// ---------------------------------------------------------------------------------------------
// System properties and scenarios.

TEST(System, AddPropertyChecksModesAndInputs) {
  System s("s");
  s.AddComponent("A", Parse(kTank));
  Property bad_mode{"p", Property::Kind::kReach, Predicate::InMode("A.nowhere"), std::nullopt};
  EXPECT_EQ(InvalidArgument([&] { s.AddProperty(bad_mode); }),
            "property 'p': unknown mode 'A.nowhere'");
  Property reads_input{"q", Property::Kind::kAlways,
                       Predicate::Compare({Expression::Symbol("A.u", 3), Relation::kLessEqual,
                                           Expression::Constant(1)}),
                       std::nullopt};
  EXPECT_EQ(InvalidArgument([&] { s.AddProperty(reads_input); }),
            "property 'q': input 'A.u' is not allowed here");
  Property good{"r", Property::Kind::kReach, Predicate::InMode("A.high"), std::nullopt};
  s.AddProperty(good);
  EXPECT_EQ(InvalidArgument([&] { s.AddProperty(good); }), "duplicate property 'r'");
  // Deeper than a model may be (an `or` of kMaxExpressionDepth + 1 levels): refused like a parsed
  // one; at the limit it is accepted.
  Predicate deep = Predicate::InMode("A.high");
  while (deep.depth() < kMaxExpressionDepth) deep = Predicate::Or(deep, Predicate::InMode("A.low"));
  s.AddProperty({"at_limit", Property::Kind::kReach, deep, std::nullopt});
  EXPECT_EQ(InvalidArgument([&] {
              s.AddProperty({"too_deep", Property::Kind::kReach,
                             Predicate::Or(deep, Predicate::True()), std::nullopt});
            }),
            "property 'too_deep': expression too long or nested too deeply (" +
                std::to_string(kMaxExpressionDepth + 1) + " levels, more than " +
                std::to_string(kMaxExpressionDepth) + ")");
}

TEST(System, InputBounds) {
  System s("s");
  s.AddComponent("A", Parse(kTank));
  EXPECT_EQ(s.InputBounds(3), std::make_pair(0.0, 1.0));
  EXPECT_THROW(s.InputBounds(1), std::invalid_argument);
  EXPECT_THROW(s.InputBounds(99), std::invalid_argument);
}

TEST(System, SetScenarioValidatesLikeAnAutomaton) {
  System s("s");
  s.AddComponent("A", Parse(kTank));
  auto scenario = [](double until, std::vector<std::pair<double, double>> points) {
    Scenario sc;
    sc.until = until;
    sc.inputs.push_back({3, InputSignal::Shape::kStep, std::move(points)});
    return sc;
  };
  EXPECT_NO_THROW(s.SetScenario(scenario(10, {{0, 0}, {1, 1}})));
  EXPECT_EQ(InvalidArgument([&] {
              s.SetScenario(scenario(10, {{0, 0}, {1, 2}}));
            }),
            "signal for 'A.u' takes value 2 outside its bounds [0, 1]");
  EXPECT_EQ(InvalidArgument([&] {
              s.SetScenario(scenario(10, {{1, 0}, {1, 1}}));
            }),
            "signal for 'A.u': times must increase strictly");
  EXPECT_EQ(InvalidArgument([&] { s.SetScenario(scenario(10, {})); }),
            "signal for 'A.u' has no points");
  EXPECT_EQ(InvalidArgument([&] {
              s.SetScenario(scenario(0, {{0, 0}}));
            }),
            "'until' must be positive and finite");
  Scenario twice = scenario(10, {{0, 0}});
  twice.inputs.push_back(twice.inputs[0]);
  EXPECT_EQ(InvalidArgument([&] { s.SetScenario(twice); }), "input 'A.u' driven twice");
  Scenario not_input = scenario(10, {{0, 0}});
  not_input.inputs[0].slot = 1;
  EXPECT_EQ(InvalidArgument([&] { s.SetScenario(not_input); }),
            "signal for something that is not an input");
  // The product accepts whatever the system accepted.
  s.SetScenario(scenario(10, {{0, 1}}));
  EXPECT_EQ(s.Product().scenario(), s.scenario());
}

TEST(System, NoAdmissibleStartNamesTheComponentAndItsInvariant) {
  const Automaton outside =
      Parse("automaton a { var x; mode m { inv x < 1; } init m { x = 2; } init m { x = 3; } }");
  const Automaton boundary =
      Parse("automaton b { var y; mode p { inv y < 1; } init p { y = 1; } }");
  const Automaton box =
      Parse("automaton c { var z; mode q { inv z <= 1; } init q { z in [0, 5]; } }");
  EXPECT_EQ(System::Of(outside).NoAdmissibleStart(),
            "'a': the initial state of mode m violates its invariant 'x < 1'");
  EXPECT_EQ(System::Of(boundary).NoAdmissibleStart(), std::nullopt);  // closure: y = 1 is in
  EXPECT_EQ(System::Of(box).NoAdmissibleStart(), std::nullopt);       // a box: some start may be
  System s("s");
  s.AddComponent("B", boundary);
  s.AddComponent("A", outside);
  EXPECT_EQ(s.NoAdmissibleStart(),
            "instance 'A': the initial state of mode m violates its invariant 'A.x < 1'");
}

TEST(System, ADeclaredLabelIsInTheAlphabetAndBlocksPartners) {
  const Automaton mover = Parse(
      "automaton mover { var x; mode a { x' = 1; } mode b { } "
      "transition a -> b { guard x >= 1; label go; } init a { x = 0; } }");
  Automaton blocker = Parse("automaton blocker { var y; mode p { } init p { y = 0; } }");
  blocker.DeclareLabel("go");
  blocker.DeclareLabel("go");  // twice: once
  EXPECT_EQ(blocker.declared_labels(), (std::set<std::string>{"go"}));
  EXPECT_THROW(blocker.DeclareLabel(""), std::invalid_argument);
  System s("s");
  s.AddComponent("A", mover, {{"go", "B.go"}});  // bound to B's declared label
  s.AddComponent("B", blocker);
  EXPECT_EQ(s.Alphabet(1), (std::set<std::string>{"B.go"}));
  EXPECT_TRUE(s.StepsFrom(std::vector<int>{0, 0}).empty());  // B never takes go
  EXPECT_EQ(s.Product().num_transitions(), 0);
}

TEST(System, InteractionGroupsJoinSharedVariablesAndLabelsNotInputsOrParameters) {
  const Automaton clock = Parse(
      "automaton clock { var x; input u in [0, 1]; param p = 1; mode a { x' = u + p; } "
      "mode b { } transition a -> b { guard x >= 1; label go; } init a { x = 0; } }");
  const Automaton reader = Parse(
      "automaton reader { var y; mode r { } transition r -> r { guard y >= 2; } "
      "init r { y = 0; } }");
  System s("s");
  s.Share("u");
  s.Share("p");
  s.AddComponent("A", clock);
  s.AddComponent("B", clock, {{"go", "A.go"}});  // synchronised with A
  s.AddComponent("C", clock);                    // meets them only through u and p
  s.AddComponent("D", reader, {{"y", "C.x"}});   // reads C's variable
  s.AddComponent("E", clock);
  EXPECT_EQ(s.InteractionGroups(), (std::vector<int>{0, 0, 2, 2, 4}));
}

}  // namespace
}  // namespace hybrid
