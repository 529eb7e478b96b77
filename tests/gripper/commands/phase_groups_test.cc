// Tests of `hybrid dot --group-by phase` (gripper/commands/phase_groups.h): the finger's modes
// by phase (against the phases tools/generate_finger.py wrote into spec/finger.ha), the hand's
// fingers by phase and its spread ungrouped, and the refusal of a model without fingers.

#include "gripper/commands/phase_groups.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::cli {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;

TEST(PhaseGroups, FingerByPhase) {
  const System finger = ParseModelFile(kSource + "/spec/finger.ha");
  const auto group = ModeGroups("phase", finger, {PhaseGrouping()});
  const Automaton& a = finger.components()[0].automaton;
  std::map<std::string, std::string> phase_of;
  for (const Mode& m : a.modes()) phase_of[m.name] = group(a, m);
  EXPECT_EQ(phase_of.at("c000_l000"), "phase 1");
  EXPECT_EQ(phase_of.at("c000_l00n"), "phase 1'");
  EXPECT_EQ(phase_of.at("c100_l00n"), "phase 2'");
  EXPECT_EQ(phase_of.at("c100_l010"), "phase 3");
  EXPECT_EQ(phase_of.at("c000_l11n"), "phase 4");  // against the palm (D3)
}

TEST(PhaseGroups, HandFingersByPhase) {
  const System hand = ParseModelFile(kSource + "/spec/hand.ha");
  const auto group = ModeGroups("phase", hand, {PhaseGrouping()});
  int grouped = 0, ungrouped = 0;
  for (const Component& c : hand.components()) {
    for (const Mode& m : c.automaton.modes())
      (group(c.automaton, m).empty() ? ungrouped : grouped)++;
  }
  EXPECT_EQ(grouped, 3 * 31);
  EXPECT_GT(ungrouped, 0);  // the spread actuator's modes
}

TEST(PhaseGroups, RefusesAModelWithoutFingers) {
  const System thermostat = ParseModelFile(kSource + "/spec/thermostat.ha");
  try {
    ModeGroups("phase", thermostat, {PhaseGrouping()});
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "group_by");
    EXPECT_EQ(std::string(e.what()),
              "group_by phase needs a finger automaton (discrete variables c1, c2, c3, l1, l2, "
              "l3)");
  }
}

}  // namespace
}  // namespace hybrid::cli
