// Tests of `hybrid dot --group-by` (commands/mode_groups.h): the hand's modes by discrete
// variables, a named grouping, and the refusals.

#include "commands/mode_groups.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::cli {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;

TEST(ModeGroups, ByDiscreteVariables) {
  const System hand = ParseModelFile(kSource + "/spec/hand.ha");
  const auto by_c1 = ModeGroups("c1,l1", hand);
  const Automaton& a = hand.components()[0].automaton;
  const Mode* m0 = nullptr;
  for (const Mode& m : a.modes()) {
    if (m.name == "c000_l100" || m.name.ends_with("c000_l100")) m0 = &m;
  }
  ASSERT_NE(m0, nullptr);
  EXPECT_EQ(by_c1(a, *m0), "c1=0, l1=1");
}

// A named grouping is used by its name, and refused (naming what it needs) for a model it
// groups nothing of; without it the name is read as a discrete variable.
TEST(ModeGroups, NamedGrouping) {
  const System thermostat = ParseModelFile(kSource + "/spec/thermostat.ha");
  const NamedModeGrouping by_name{"by_name", [](const Automaton&, const Mode& m) { return m.name; },
                                  "modes"};
  EXPECT_EQ(
      ModeGroups("by_name", thermostat, {by_name})(thermostat.components()[0].automaton,
                                                   thermostat.components()[0].automaton.modes()[0]),
      thermostat.components()[0].automaton.modes()[0].name);
  const NamedModeGrouping none{"none", [](const Automaton&, const Mode&) { return std::string(); },
                               "nothing"};
  try {
    ModeGroups("none", thermostat, {none});
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "group_by");
    EXPECT_EQ(std::string(e.what()), "group_by none needs nothing");  // the API's words
    EXPECT_EQ(e.message(), Arg("group_by") + " none needs nothing");
  }
  EXPECT_THROW(ModeGroups("by_name", thermostat), OptionError);
}

TEST(ModeGroups, RefusesWhatTheModelDoesNotHave) {
  const System thermostat = ParseModelFile(kSource + "/spec/thermostat.ha");
  EXPECT_THROW(ModeGroups("c1", thermostat), OptionError);
  const System finger = ParseModelFile(kSource + "/spec/finger.ha");
  EXPECT_THROW(ModeGroups("c1,,l1", finger), OptionError);
  EXPECT_THROW(ModeGroups("nope", finger), OptionError);
}

}  // namespace
}  // namespace hybrid::cli
