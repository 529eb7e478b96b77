#pragma once

// The discrete step at one instant: what the instant reached (invariant boundaries, guard
// crossings) and which jumps may fire there, in priority order, with their synchronisation
// partners.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/simulation/simulator.h"
#include "solvers/simulation/compiled_component.h"
#include "solvers/simulation/run_state.h"

namespace hybrid {

/// A candidate jump: the participating (component, transition) pairs, the leader first.
using Jump = std::vector<std::pair<int, int>>;

/// What the current instant reached and no jump has acted on yet, per component: the text of an
/// invariant comparison whose boundary it reached (none: empty) and the transitions whose guard
/// comparisons crossed. Noted from the root functions that fired; kept through the event
/// iteration at that instant for the components that have not jumped, so that one component's
/// jump does not discard what another one reached at the same instant; forgotten when time
/// advances (ForgetAll).
///
/// Candidates reads the guards at the run's current environment and modes: urgent transitions
/// before lazy ones, then component order, then declaration order. An urgent transition is
/// enabled when its guard holds in its closure if one of its comparisons crossed at this instant,
/// strictly otherwise; a lazy one only in a component that reached its invariant boundary, when
/// its guard holds in its closure. A labelled transition needs a partner in every other component
/// whose alphabet has the label (AddPartners).
class JumpSelector {
 public:
  /// Keeps references to `components` and `run`, which must outlive the selector; `run` gives
  /// the modes, the root functions and the guards' values.
  JumpSelector(const std::vector<CompiledComponent>& components, const RunState& run);

  /// A new instant: forgets everything reached.
  void ForgetAll();
  /// Notes what the root functions `crossed` (indices into run.roots()) reached: an invariant's
  /// boundary, or a guard comparison.
  void Note(const std::vector<int>& crossed);
  /// Component c reached the boundary of its invariant comparison `text` (an input jump left it
  /// outside).
  void ReachInvariant(size_t c, std::string text);
  /// The components of `jump` are in new modes: forgets what they reached.
  void Forget(const Jump& jump);
  /// The invariant comparison reached by the first component that reached one, if any.
  std::optional<std::string> FirstReachedInvariant() const;
  /// Whether a comparison of the guard of transition `ti` of component c crossed at this instant.
  bool GuardReached(int c, int ti) const;

  /// The jumps that can fire now, best first (see the class comment).
  std::vector<Jump> Candidates() const;
  /// The cause of the next jump of an event iteration, `jumps` its candidates: kInvariant for a
  /// lazy leader, kCrossing when a guard of the first jump crossed at this instant, else kEnabled
  /// (also when there is none).
  EventRecord::Cause CauseInIteration(const std::vector<Jump>& jumps) const;

 private:
  // Completes `jump`, transition of component c labelled `label`, with the first enabled
  // transition of that label of every other component that uses the label (its guard in its
  // closure where it crossed at this instant, strictly otherwise). False if some component has
  // none (the jump is blocked).
  bool AddPartners(size_t c, const std::string& label, Jump* jump) const;

  const std::vector<CompiledComponent>& components_;
  const RunState& run_;
  std::vector<std::string> reached_invariant_;
  std::vector<std::vector<int>> reached_guards_;
};

}  // namespace hybrid
