// Tests of the compiled model (solvers/simulation/compiled_model.h): the state vector's variables,
// components with their alphabets, mode names, and parameters set for a run (derived ones follow,
// misuse is refused with the parameter's name).

#include "solvers/simulation/compiled_model.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

constexpr const char* kSystem = R"(
automaton worker {
  param rate = 2;
  param twice = 2 * rate;
  param scale = 3;
  param start = 1;
  var x;
  var busy_time;
  mode idle { x' = 0; }
  mode busy { x' = twice; busy_time' = 1; inv scale * x <= 100; }
  transition begin: idle -> busy { guard x >= 0; label go; }
  transition end: busy -> idle { guard x >= 10; }
  init idle { x = start; busy_time = 0; }
}
automaton boss {
  var t;
  mode wait { t' = 1; }
  transition order: wait -> wait { guard t >= 1; reset t := 0; label go; }
  init wait { t = 0; }
}
system shop { instance W = worker; instance boss; }
)";

// `parameters` set for a run, as the value of parameter `name`.
double ValueWith(const CompiledModel& model, const std::string& name,
                 std::vector<std::pair<std::string, double>> parameters) {
  const std::vector<double> env = model.ParameterEnvironment(parameters);
  return env[*model.system().symbols().Find(name)];
}

// The message of ParameterEnvironment(parameters), or "" if it does not throw.
std::string Refusal(const CompiledModel& model,
                    std::vector<std::pair<std::string, double>> parameters) {
  try {
    model.ParameterEnvironment(parameters);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CompiledModelTest, VariablesComponentsAndAlphabets) {
  const System system = ParseModel(kSystem, "shop.ha");
  const CompiledModel model(system);
  EXPECT_EQ(&model.system(), &system);
  EXPECT_EQ(model.variable_names(), (std::vector<std::string>{"W.x", "W.busy_time", "t"}));
  ASSERT_EQ(model.variable_slots().size(), 3u);
  EXPECT_EQ(model.variable_slots()[0], *system.symbols().Find("W.x"));
  ASSERT_EQ(model.components().size(), 2u);
  EXPECT_EQ(model.components()[0].alphabet, system.Alphabet(0));
  EXPECT_EQ(model.components()[1].alphabet.count("go"), 1u);
  EXPECT_EQ(model.components()[0].transitions[0].name, "W.begin");
  EXPECT_EQ(model.components()[1].transitions[0].name, "order");
}

TEST(CompiledModelTest, ModeNamesAreQualifiedByTheInstance) {
  const System system = ParseModel(kSystem, "shop.ha");
  const CompiledModel model(system);
  EXPECT_EQ(model.ModeName(0, 1), "W.busy");
  EXPECT_EQ(model.ModeName(1, 0), "wait");
  const std::vector<int> modes = {1, 0};
  EXPECT_EQ(model.ModeLabel(modes), "W.busy|wait");
  EXPECT_THROW(model.ModeName(2, 0), std::out_of_range);
  EXPECT_THROW(model.ModeName(0, 2), std::out_of_range);
}

TEST(CompiledModelTest, ParametersSetForARunAndTheirDerivedOnes) {
  const System system = ParseModel(kSystem, "shop.ha");
  const CompiledModel model(system);
  EXPECT_EQ(ValueWith(model, "W.twice", {}), 4.0);
  EXPECT_EQ(ValueWith(model, "W.rate", {{"W.rate", 5.0}}), 5.0);
  EXPECT_EQ(ValueWith(model, "W.twice", {{"W.rate", 5.0}}), 10.0);
  EXPECT_EQ(ValueWith(model, "W.x", {{"W.rate", 5.0}}), 0.0);  // not a parameter
}

TEST(CompiledModelTest, MisuseOfParametersIsRefusedByName) {
  const System system = ParseModel(kSystem, "shop.ha");
  const CompiledModel model(system);
  EXPECT_EQ(Refusal(model, {{"W.nothing", 1.0}}), "'W.nothing' is not a parameter of the model");
  EXPECT_EQ(Refusal(model, {{"W.x", 1.0}}), "'W.x' is not a parameter of the model");
  EXPECT_EQ(Refusal(model, {{"W.rate", std::numeric_limits<double>::infinity()}}),
            "value of parameter 'W.rate' is not finite");
  // An initial value reads `start`; `scale` scales x in an invariant.
  for (const char* fixed : {"W.start", "W.scale"}) {
    EXPECT_NE(Refusal(model, {{fixed, 1.0}}).find("cannot be set for a run"), std::string::npos)
        << fixed;
  }
}

TEST(CompiledModelTest, AParameterAFixedOneIsDefinedFromIsFixedToo) {
  const System system = ParseModel(R"(
automaton a {
  param base = 2;
  param gain = 3 * base;
  var x;
  mode m { x' = 1; inv gain * x <= 100; }
  init m { x = 0; }
})",
                                   "a.ha");
  const CompiledModel model(system);
  EXPECT_NE(Refusal(model, {{"gain", 1.0}}).find("cannot be set for a run"), std::string::npos);
  EXPECT_NE(Refusal(model, {{"base", 1.0}}).find("cannot be set for a run"), std::string::npos);
}

}  // namespace
}  // namespace hybrid
