// Tests of the compiled form of one component (solvers/simulation/compiled_component.h): modes,
// transitions and their outgoing lists, qualified names, linearity of comparisons, operations that
// may jump, constant-rate modes, the first initial state and the parameters held as constants.

#include "solvers/simulation/compiled_component.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

// The System's slot maps as CompiledModel builds them, and component c compiled.
struct Compiled {
  explicit Compiled(const std::string& text, int c = 0) : system(ParseModel(text, "test.ha")) {
    const SymbolTable& symbols = system.symbols();
    x_index.assign(symbols.size(), -1);
    int n = 0;
    for (int s = 0; s < symbols.size(); ++s) {
      if (symbols[s].kind == SymbolKind::kVariable) x_index[s] = n++;
    }
    parameter_env.assign(symbols.size(), 0.0);
    for (const Component& comp : system.components()) {
      const std::vector<double> local = comp.automaton.ParameterEnvironment();
      for (const auto& [slot, value] : comp.automaton.parameters()) {
        parameter_env[comp.global_slot[slot]] = local[slot];
      }
    }
    fixed.assign(symbols.size(), 0);
    component = CompileComponent(symbols, system.components()[c], x_index, parameter_env, fixed);
  }
  bool Fixed(const std::string& name) const { return fixed[*system.symbols().Find(name)] != 0; }

  System system;
  std::vector<int> x_index;
  std::vector<double> parameter_env;
  std::vector<char> fixed;
  CompiledComponent component;
};

constexpr const char* kModel = R"(
automaton a {
  param k = 2;
  param b = 3;
  param x0 = 1;
  var x;
  var y;
  input u in [-1, 1];
  mode m1 {
    x' = u + k;
    y' = 1;
    inv x <= 10;
  }
  mode m2 {
    x' = -y;
    inv x >= -10 and k * y <= 5;
  }
  transition go: m1 -> m2 { guard x >= b; reset y := 2 * x; label l; }
  transition back: m2 -> m1 { guard sign(x) < 0; }
  transition again: m1 -> m1 { guard x / y > 1; lazy; }
  init m1 { x = x0; y in [0, 4]; }
})";

TEST(CompiledComponentTest, ModesTransitionsAndOutgoingLists) {
  const Compiled c(kModel);
  const CompiledComponent& cc = c.component;
  EXPECT_EQ(cc.instance, "");
  EXPECT_EQ(cc.mode_names, (std::vector<std::string>{"m1", "m2"}));
  ASSERT_EQ(cc.transitions.size(), 3u);
  EXPECT_EQ(cc.transitions[0].name, "go");
  EXPECT_EQ(cc.transitions[0].label, "l");
  EXPECT_EQ(cc.transitions[0].source, 0);
  EXPECT_EQ(cc.transitions[0].target, 1);
  EXPECT_EQ(cc.transitions[2].urgency, Urgency::kLazy);
  EXPECT_EQ(cc.modes[0].outgoing, (std::vector<int>{0, 2}));
  EXPECT_EQ(cc.modes[1].outgoing, (std::vector<int>{1}));
  ASSERT_EQ(cc.transitions[0].resets.size(), 1u);
  EXPECT_EQ(cc.transitions[0].resets[0].first, 1);  // y
  EXPECT_TRUE(cc.alphabet.empty());                 // CompiledModel sets it
}

TEST(CompiledComponentTest, ConstantRateModesReadNoVariable) {
  const Compiled c(kModel);
  EXPECT_TRUE(c.component.modes[0].constant_rate);   // x' = u + k, y' = 1
  EXPECT_FALSE(c.component.modes[1].constant_rate);  // x' = -y
  ASSERT_EQ(c.component.modes[0].flows.size(), 2u);
  EXPECT_EQ(c.component.modes[0].flows[0].first, 0);
}

TEST(CompiledComponentTest, ComparisonsKnowTheirLinearityAndJumps) {
  const Compiled c(kModel);
  const CompiledComparison& go = c.component.transitions[0].guard[0];  // x >= b
  EXPECT_EQ(go.text, "x >= b");
  EXPECT_EQ(go.relation, Relation::kGreaterEqual);
  ASSERT_TRUE(go.linearity.terms.has_value());
  ASSERT_EQ(go.linearity.terms->size(), 1u);
  EXPECT_EQ((*go.linearity.terms)[0], std::make_pair(0, 1.0));
  EXPECT_FALSE(go.may_jump);
  const std::vector<double> env = [&] {
    std::vector<double> e = c.parameter_env;
    e[*c.system.symbols().Find("x")] = 5.0;
    return e;
  }();
  EXPECT_DOUBLE_EQ(go.residual.Evaluate(env.data()), 2.0);  // 5 - 3
  // sign(x) may jump; x / y divides by a variable: both exempt, neither affine.
  EXPECT_TRUE(c.component.transitions[1].guard[0].may_jump);
  EXPECT_TRUE(c.component.transitions[2].guard[0].may_jump);
  EXPECT_FALSE(c.component.transitions[2].guard[0].linearity.terms.has_value());
  // k * y <= 5: affine with k folded (coefficient 2 on y).
  const CompiledComparison& scaled = c.component.modes[1].invariant[1];
  ASSERT_TRUE(scaled.linearity.terms.has_value());
  EXPECT_EQ((*scaled.linearity.terms)[0], std::make_pair(1, 2.0));
}

TEST(CompiledComponentTest, InitialStateAtTheMidpointAndFixedParameters) {
  const Compiled c(kModel);
  EXPECT_EQ(c.component.initial_mode, 0);
  EXPECT_EQ(c.component.initial_values, (std::vector<std::pair<int, double>>{{0, 1.0}, {1, 2.0}}));
  EXPECT_TRUE(c.Fixed("x0"));  // an initial value reads it
  EXPECT_TRUE(c.Fixed("k"));   // it scales y in an invariant
  EXPECT_FALSE(c.Fixed("b"));  // a plain offset: settable per run
}

TEST(CompiledComponentTest, InstanceNamesQualifyTransitions) {
  const Compiled c(std::string(kModel) + "\nsystem s { instance A = a; }");
  EXPECT_EQ(c.component.instance, "A");
  EXPECT_EQ(c.component.transitions[0].name, "A.go");
  EXPECT_EQ(c.component.mode_names[0], "m1");
}

TEST(CompiledComponentTest, AComponentWithoutInitialStateIsRefused) {
  Automaton a("lonely");
  const int x = a.AddVariable("x");
  a.AddMode(Mode{"m", {{x, Expression::Constant(1.0)}}, {}, {}});
  const Component comp{"", a, {x}, a, {}};
  const std::vector<int> x_index = {0};
  const std::vector<double> env = {0.0};
  std::vector<char> fixed = {0};
  try {
    CompileComponent(a.symbols(), comp, x_index, env, fixed);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "component 'lonely' has no initial state: it cannot be simulated");
  }
}

TEST(CompiledComponentTest, MayJumpFindsJumpingOperations) {
  const auto varies = [](int slot) { return slot == 0; };
  const Expression x = Expression::Symbol("x", 0);
  const Expression p = Expression::Symbol("p", 1);
  EXPECT_FALSE(MayJump(x * p + Expression::Constant(1.0), varies));
  EXPECT_TRUE(MayJump(Expression::Unary(Op::kSign, x), varies));
  EXPECT_TRUE(MayJump(p / x, varies));
  EXPECT_FALSE(MayJump(x / p, varies));  // a division by a constant of the run
}

}  // namespace
}  // namespace hybrid
