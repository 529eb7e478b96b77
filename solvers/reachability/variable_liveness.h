#pragma once

#include <vector>

#include "hybrid/automaton/system.h"

namespace hybrid {

/// Which continuous variables of a System are dead at each component mode: their value there
/// cannot influence anything observed (a property, an invariant, a guard, a reset, a flow)
/// before the variable is next written by a reset. Reachability may then forget a dead
/// variable's value (let it take any value) without changing what it decides: the reachable
/// states projected on the live variables stay exact ("active clock reduction", Daws and
/// Yovine 1996, for linear hybrid automata).
///
/// Only variables private to one component are ever dead: a variable mentioned by one component
/// alone (its modes' invariants and flows, its transitions' guards and resets) and not in
/// `observed` (the System slots the checked properties read). For such a variable x of
/// component c, liveness is the least fixpoint over c's modes of
///
///   live(m) = reads(m, x) or exists t: m -> m' with reads(t, x) or (t does not reset x and
///             live(m')),
///
/// where reads(m, x) means m's invariant or a flow of m reads x, and reads(t, x) that t's guard
/// or a right-hand side of its resets does. Every transition of c counts, whatever it
/// synchronises with, so the result is sound for every composition of c.
class VariableLiveness {
 public:
  /// `observed`: System slots live everywhere (those the checked properties read).
  VariableLiveness(const System& system, const std::vector<int>& observed);

  /// System slots of the variables dead at mode `mode` of component `component`, ascending.
  const std::vector<int>& DeadAt(int component, int mode) const;

 private:
  // dead_[c][m]: the slots dead at mode m of component c.
  std::vector<std::vector<std::vector<int>>> dead_;
};

}  // namespace hybrid
