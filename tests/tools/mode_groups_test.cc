// Tests of `hybrid dot --group-by` (tools/mode_groups.h): the finger's modes by phase (against
// the phases tools/generate_finger.py wrote into spec/finger.ha), the hand's fingers by phase
// and its spread ungrouped, discrete variables, and the refusals.

#include "tools/mode_groups.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "automaton/parser.h"
#include "tools/options.h"

namespace hybrid::cli {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;

TEST(ModeGroups, FingerByPhase) {
  const System finger = ParseModelFile(kSource + "/spec/finger.ha");
  const auto group = ModeGroups("phase", finger);
  const Automaton& a = finger.components()[0].automaton;
  std::map<std::string, std::string> phase_of;
  for (const Mode& m : a.modes()) phase_of[m.name] = group(a, m);
  EXPECT_EQ(phase_of.at("c000_l000"), "phase 1");
  EXPECT_EQ(phase_of.at("c000_l00n"), "phase 1'");
  EXPECT_EQ(phase_of.at("c100_l00n"), "phase 2'");
  EXPECT_EQ(phase_of.at("c100_l010"), "phase 3");
  EXPECT_EQ(phase_of.at("c000_l11n"), "phase 4");  // against the palm (D3)
}

TEST(ModeGroups, HandFingersByPhaseAndVariables) {
  const System hand = ParseModelFile(kSource + "/spec/hand.ha");
  const auto group = ModeGroups("phase", hand);
  int grouped = 0, ungrouped = 0;
  for (const Component& c : hand.components()) {
    for (const Mode& m : c.automaton.modes())
      (group(c.automaton, m).empty() ? ungrouped : grouped)++;
  }
  EXPECT_EQ(grouped, 3 * 31);
  EXPECT_GT(ungrouped, 0);  // the spread actuator's modes
  const auto by_c1 = ModeGroups("c1,l1", hand);
  const Automaton& a = hand.components()[0].automaton;
  const Mode* m0 = nullptr;
  for (const Mode& m : a.modes()) {
    if (m.name == "c000_l100" || m.name.ends_with("c000_l100")) m0 = &m;
  }
  ASSERT_NE(m0, nullptr);
  EXPECT_EQ(by_c1(a, *m0), "c1=0, l1=1");
}

TEST(ModeGroups, RefusesWhatTheModelDoesNotHave) {
  const System thermostat = ParseModelFile(kSource + "/spec/thermostat.ha");
  EXPECT_THROW(ModeGroups("phase", thermostat), UsageError);
  EXPECT_THROW(ModeGroups("c1", thermostat), UsageError);
  const System finger = ParseModelFile(kSource + "/spec/finger.ha");
  EXPECT_THROW(ModeGroups("c1,,l1", finger), UsageError);
  EXPECT_THROW(ModeGroups("nope", finger), UsageError);
}

}  // namespace
}  // namespace hybrid::cli
