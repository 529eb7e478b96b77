// Tests of a run's initial values (commands/initial_values.h): the values land in the IR (every
// initial state of every component declaring the variable, nothing else changed), and bad names
// and values are OptionErrors about `init` whose messages were written out by hand.

#include "commands/initial_values.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::cli {
namespace {

// Two initial states of `x`, a domain [lo, hi] over the parameter `hi`, and a composed copy.
constexpr const char* kModel = R"(automaton tank {
  param top = 8;
  var x in [-1, top], y;
  input u in [0, 1];
  mode a { x' = u; }
  mode b { x' = -1; }
  init a { x = 0; y = 1; }
  init b { x in [1, 2]; y = 1; }
}
system pair {
  share y;
  instance A = tank;
  instance B = tank;
})";

// The constant value of the initial range of System variable `name` in initial state `index` of
// component `c`, as [lo, hi].
std::pair<double, double> Initial(const System& s, int c, int index, const std::string& name) {
  const Automaton& a = s.components()[static_cast<std::size_t>(c)].automaton;
  const int slot = *a.symbols().Find(name);
  for (const InitialValue& v : a.initial_states()[static_cast<std::size_t>(index)].values) {
    if (v.slot == slot)
      return {a.EvaluateConstant(v.range.lo, ""), a.EvaluateConstant(v.range.hi, "")};
  }
  ADD_FAILURE() << name << " has no initial value";
  return {NAN, NAN};
}

// The message of the OptionError SetInitialValues throws for `values` (its argument `init`).
std::string Refusal(const std::vector<InitialValueSetting>& values) {
  System s = ParseModel(kModel, "m.ha");
  try {
    SetInitialValues(values, s);
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "init");
    return e.what();
  }
  return "no error";
}

TEST(InitialValues, ParsesNameEqualsValue) {
  EXPECT_EQ(ParseInitialValues({"A.x=2.5", "y=-1e-3"}),
            (std::vector<InitialValueSetting>{{"A.x", 2.5}, {"y", -0.001}}));
  auto error = [](const std::string& spec) {
    try {
      (void)ParseInitialValues({spec});
    } catch (const OptionError& e) {
      EXPECT_EQ(e.argument(), "init");
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("x"), "init 'x': expected NAME=VALUE");
  EXPECT_EQ(error("=1"), "init '=1': expected NAME=VALUE");
  EXPECT_EQ(error("x=0x10"), "init x: '0x10' is not a decimal number");
  EXPECT_EQ(error("x=inf"), "init x: 'inf' is not a decimal number");
}

TEST(InitialValues, SetsEveryInitialStateOfTheNamedVariableOnly) {
  System s = ParseModel(kModel, "m.ha");
  SetInitialValues({{"A.x", 3.0}, {"y", 4.0}, {"A.x", 5.0}}, s);  // the later A.x wins
  for (int index : {0, 1}) {
    EXPECT_EQ(Initial(s, 0, index, "A.x"), std::make_pair(5.0, 5.0)) << index;
    EXPECT_EQ(Initial(s, 0, index, "y"), std::make_pair(4.0, 4.0)) << index;  // shared
    EXPECT_EQ(Initial(s, 1, index, "y"), std::make_pair(4.0, 4.0)) << index;
  }
  EXPECT_EQ(Initial(s, 1, 0, "B.x"), std::make_pair(0.0, 0.0));  // B as declared
  EXPECT_EQ(Initial(s, 1, 1, "B.x"), std::make_pair(1.0, 2.0));
  // The domain's ends are inside it.
  EXPECT_NO_THROW(SetInitialValues({{"B.x", -1.0}, {"B.x", 8.0}}, s));
}

TEST(InitialValues, RefusesWhatIsNoContinuousVariableOrOutsideItsDomain) {
  EXPECT_EQ(Refusal({{"x", 1.0}}),
            "init: 'x' is not a continuous variable of the model; did you mean 'A.x' or 'B.x'? "
            "(a composed system's names are qualified by the instance)");
  EXPECT_EQ(Refusal({{"A.xx", 1.0}}),
            "init: 'A.xx' is not a continuous variable of the model; did you mean 'A.x'?");
  EXPECT_EQ(Refusal({{"speed", 1.0}}),
            "init: 'speed' is not a continuous variable of the model (variables: A.x y B.x)");
  EXPECT_EQ(Refusal({{"A.top", 1.0}}),
            "init: 'A.top' is a parameter, not a continuous variable (set it with parameters)");
  EXPECT_EQ(Refusal({{"A.u", 1.0}}),
            "init: 'A.u' is an input, not a continuous variable (drive it with inputs)");
  // [-1, top] with top = 8.
  EXPECT_EQ(Refusal({{"A.x", 8.5}}),
            "init A.x: 8.5 lies outside the declared domain [-1, 8] of 'A.x'");
  EXPECT_EQ(Refusal({{"B.x", -1.25}}),
            "init B.x: -1.25 lies outside the declared domain [-1, 8] of 'B.x'");
  EXPECT_EQ(Refusal({{"y", std::numeric_limits<double>::infinity()}}),
            "init y: the value must be finite (got inf)");
  EXPECT_EQ(Refusal({{"y", std::nan("")}}), "init y: the value must be finite (got nan)");
}

}  // namespace
}  // namespace hybrid::cli
