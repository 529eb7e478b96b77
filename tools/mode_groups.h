#pragma once

#include <functional>
#include <string>

#include "automaton/system.h"

namespace hybrid::cli {

/// The grouping of `hybrid dot --group-by SPEC` (DotOptions::group) for `system`:
/// - "phase": the Robotiq finger's phases 1, 1', 2, 2', 3, 4 (gripper::PhaseOfState) from the
///   discrete variables c1..c3, l1..l3 of each automaton that has them (a finger, alone or as an
///   instance of the hand); modes of other automata stay ungrouped;
/// - "V1,V2,...": discrete variables (by name, or by name within an instance: `c1` matches
///   `A.c1`); a cluster per combination of their values, named "V1=0, V2=1".
/// Throws UsageError naming the option when no automaton of `system` has what SPEC asks for.
std::function<std::string(const Automaton&, const Mode&)> ModeGroups(const std::string& spec,
                                                                     const System& system);

}  // namespace hybrid::cli
