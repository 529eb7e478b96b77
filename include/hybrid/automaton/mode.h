#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/constraint.h"
#include "hybrid/automaton/expression.h"

namespace hybrid {

/// A location of the automaton: its flow, its invariant and its discrete valuation.
///
/// Flow: one right-hand side per continuous variable, dx/dt = f(x, u, p); a variable without a
/// flow in this mode keeps its value (dx/dt = 0). Invariant: a conjunction that every state in the
/// mode must satisfy; the automaton must leave the mode (by an urgent transition, or a lazy one at
/// the latest when the invariant would be violated) before it fails. Discrete values: each discrete
/// variable of the automaton has one integer value in the mode.
struct Mode {
  std::string name;
  /// (variable slot, right-hand side), sorted by slot, at most one per variable.
  std::vector<std::pair<int, Expression>> flows;
  Constraint invariant;
  /// (discrete-variable slot, value), sorted by slot, one per discrete variable of the automaton.
  std::vector<std::pair<int, int>> discrete_values;

  /// The right-hand side for `slot`, or nullopt when the variable is constant in this mode.
  std::optional<Expression> FlowOf(int slot) const;
  /// The value of discrete variable `slot`, or nullopt if unset.
  std::optional<int> DiscreteValueOf(int slot) const;
  friend bool operator==(const Mode&, const Mode&) = default;
};

}  // namespace hybrid
