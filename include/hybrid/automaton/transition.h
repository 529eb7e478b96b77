#pragma once

#include <string>
#include <vector>

#include "hybrid/automaton/constraint.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/id.h"

namespace hybrid {

/// When an enabled transition is taken.
enum class Urgency {
  /// Taken as soon as its guard holds (the default). Used for physical events: contact, limits.
  kUrgent,
  /// May be taken while its guard holds; a simulator takes it as late as possible, when staying
  /// would violate the source mode's invariant. Used for controller choices (thermostat).
  kLazy,
};

/// One assignment of a reset: the variable at `slot` gets `value`, evaluated in the state before
/// the jump. All assignments of a transition happen simultaneously.
struct Reset {
  int slot = -1;
  Expression value;
  friend bool operator==(const Reset&, const Reset&) = default;
};

/// A discrete jump source -> target. Its guard is a conjunction of comparisons (empty = true);
/// resets not listed keep their variables' values. The label, when non-empty, synchronises the
/// transition with equally labelled transitions of other components of a System.
struct Transition {
  std::string name;
  ModeId source;
  ModeId target;
  std::string label;
  Constraint guard;
  /// Sorted by slot, at most one per variable.
  std::vector<Reset> resets;
  Urgency urgency = Urgency::kUrgent;
  friend bool operator==(const Transition&, const Transition&) = default;
};

}  // namespace hybrid
