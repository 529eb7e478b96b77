#pragma once

#include <cstdint>
#include <optional>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"

namespace hybrid {

/// The `sample` method of `hybrid check`: property-based exploration with rapidcheck generators.
/// It simulates random runs of a system, looking for a counterexample to an invariant (`always P`,
/// `never P`) or a witness of a reachability query (`reach P`), and shrinks the first one it finds
/// to a minimal one. Sampling finds bugs; it never proves anything.
///
/// A run is a Trace (include/hybrid/checking/trace.h), drawn from:
/// - for every input of the system (bounds from System::InputBounds, under the drawn parameter
///   values), a step signal of 1 to
///   Options::max_segments pieces over the horizon. Each piece has a value, drawn from the
///   input's upper end (30%), its lower end (30%), "zero" (0 clamped into the bounds, 15%) and
///   uniform values in the bounds (25%), and a duration weight in 1..20: the pieces' durations are
///   the horizon split in proportion to the weights (positive, summing to the horizon). Full-speed
///   runs and reversals (u: +1 then -1) are frequent. Early runs have fewer pieces (the number of
///   pieces grows with the run index over the first half of the runs, as in rapidcheck).
/// - for every uncertain parameter (UncertainParameters: `param p = v in [lo, hi];`), a value in
///   [lo, hi]: the nominal value, lo, hi (25% each) or uniform.
/// - for every component with several `init` declarations, one of them (uniformly; shrinking
///   towards the first), named in the trace (Trace::initial_states);
/// - for every continuous variable whose initial value in the chosen initial state of its
///   component is an interval (`x in [lo, hi]`), a value in it: the midpoint (what a simulation
///   starts from, 20%), lo, hi (30% each) or uniform (a shared variable: the first component's).
///   The bounds are evaluated under the drawn parameter values.
/// Each drawn trace is replayed (ReplayTrace). A run that ends early (invariant violated, Zeno,
/// solver failure) still counts: its recorded states are real states of the model. A draw that
/// the model rejects (ReplayTrace or the simulator throws std::invalid_argument, e.g. an initial
/// value that violates its mode's invariant) is skipped and counted as rejected.
///
/// Shrinking (rapidcheck's shrink trees, searched greedily: take the first simpler candidate that
/// is still a counterexample or witness, repeat until none is) makes a trace simpler for a reader,
/// in this order of priority:
/// 1. inputs: fewer pieces (adjacent pieces with equal values count as one); each value towards
///    "zero" (the input off), then the upper end, then the lower end, then uniform values towards
///    zero; duration weights towards 1, i.e. towards pieces of equal length;
/// 2. parameters: towards the nominal value, then hi, then lo, then values towards nominal;
/// 3. initial values: towards the midpoint, then hi, then lo, then values towards the midpoint.
/// A candidate that denotes the same run as the current trace (e.g. "zero" and the lower end of an
/// input in [0, 1]) is taken without a replay and not counted as a step.
/// So a minimal counterexample has as few input pieces as possible, with values at "zero" or at
/// the ends of the bounds where it can, equal durations where timing does not matter, and
/// parameters and initial values at their nominal values where they do not matter.
class PropertySampler {
 public:
  struct Options {
    /// Random runs per property (>= 1). A system with no input of non-zero width, no uncertain
    /// parameter and no interval initial value has a single run.
    int runs = 200;
    /// Runs are repeatable: the same seed (and options, system, property) gives the same result.
    std::uint64_t seed = 1;
    /// Largest number of pieces of each input's step signal (>= 1).
    int max_segments = 8;
    /// Horizon of every run (> 0, finite); default: the property's `within T`, else the system's
    /// scenario horizon, else 100.
    std::optional<double> horizon;
    /// Accepted shrink steps at most (>= 0; 0 reports the trace as found).
    int max_shrink_steps = 500;
    /// Shrink candidates examined at most (>= 0; each costs at most one replay): bounds the time
    /// spent shrinking.
    int max_shrink_replays = 5000;
  };

  /// Default options.
  PropertySampler();
  /// Throws std::invalid_argument ("sampling: ...") for options out of range.
  explicit PropertySampler(Options options);

  const Options& options() const { return options_; }

  /// Samples runs of `system` for `property` (any property over the system's names, not
  /// necessarily one of system.properties()). Returns verdict kViolated (`always`, `never`) or
  /// kReachable (`reach`) with the shrunk, replayed trace and a reason such as "counterexample in
  /// run 17 of 200, shrunk in 12 steps from 6 to 2 input pieces"; otherwise kUnknown with reason
  /// "no counterexample in N sampled runs (sampling never proves)" ("no witness ..." for `reach`)
  /// and no trace. Never returns kProved or kUnreachable. method is "sample", seconds the wall
  /// clock time. The trace lists every uncertain parameter and every interval initial value, also
  /// those left at their nominal value or midpoint.
  ///
  /// Throws std::invalid_argument ("sampling: ...") for misuse: a non-positive or
  /// non-finite horizon, an input with non-finite or empty bounds, an uncertain parameter whose
  /// nominal value lies outside its range, a system the simulator rejects (no initial state), or a
  /// model that rejects every drawn run.
  CheckResult Check(const System& system, const Property& property) const;

 private:
  Options options_;
};

}  // namespace hybrid
