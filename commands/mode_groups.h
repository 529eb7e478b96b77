#pragma once

#include <functional>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"

namespace hybrid::cli {

/// A grouping of modes for `hybrid dot --group-by`: the cluster name of mode `m` of `a`, or ""
/// for a mode left ungrouped.
using ModeGrouping = std::function<std::string(const Automaton&, const Mode&)>;

/// A grouping that a model family provides under a name (the gripper's "phase":
/// gripper/commands/phase_groups.h), and what a model needs for it, as a message ends
/// ("a finger automaton (...)").
struct NamedModeGrouping {
  std::string name;
  ModeGrouping group;
  std::string needs;
};

/// The grouping of `hybrid dot --group-by SPEC` (DotOptions::group) for `system`:
/// - the name of one of `named`: that grouping;
/// - "V1,V2,...": discrete variables (by name, or by name within an instance: `c1` matches
///   `A.c1`); a cluster per combination of their values, named "V1=0, V2=1".
/// Throws OptionError about "group_by" when no automaton of `system` has what SPEC asks for.
ModeGrouping ModeGroups(const std::string& spec, const System& system,
                        const std::vector<NamedModeGrouping>& named = {});

}  // namespace hybrid::cli
