#pragma once

#include "commands/mode_groups.h"

namespace hybrid::cli {

/// `hybrid dot --group-by phase`: the Robotiq finger's phases 1, 1', 2, 2', 3, 4
/// (gripper::PhaseOfState) from the discrete variables c1..c3, l1..l3 of each automaton that has
/// them (a finger, alone or as an instance of the hand); modes of other automata stay ungrouped.
NamedModeGrouping PhaseGrouping();

}  // namespace hybrid::cli
