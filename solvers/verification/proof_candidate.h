#pragma once

// Internal to hybrid::verification.

#include "hybrid/automaton/predicate.h"
#include "hybrid/automaton/property.h"
#include "solvers/verification/proof_job.h"

namespace hybrid {

/// A goal as a proof run (ProofRun) checks it: the states that break it, and what the run has
/// learned about it so far.
struct ProofCandidate {
  /// How many paths found for one candidate are replayed at most (each replay a simulation): a
  /// candidate whose paths keep failing to replay is searched no further.
  static constexpr int kMaxReplays = 8;

  /// Borrowed from the job, which must outlive the candidate.
  const ProofGoal* goal;
  /// A state that is a counterexample (`always P`: not P; `never P`: P) or a witness (`reach
  /// P`: P).
  Predicate bad;
  /// `always` or `never` (else `reach`).
  bool invariant;
  bool decided = false;  ///< a verdict is in the results (or a lemma was refuted)
  bool refuted = false;  ///< the encoding reaches `bad`: not a lemma
  bool proved = false;   ///< an invariant of every run (usable as a lemma)
  int replays = 0;       ///< paths replayed for it so far

  /// The candidate of `goal` (borrowed), nothing learned yet. Bounded properties are checked
  /// like unbounded ones (sound for `proved`); their traces are replayed with the horizon.
  static ProofCandidate Of(const ProofGoal& goal) {
    const Property& p = goal.property;
    switch (p.kind) {
      case Property::Kind::kAlways:
        return {&goal, Predicate::Not(p.predicate), true};
      case Property::Kind::kNever:
        return {&goal, p.predicate, true};
      case Property::Kind::kReach:
        break;
    }
    return {&goal, p.predicate, false};
  }

  /// Still worth a path: undecided, and replayed fewer than kMaxReplays times.
  bool Pending() const { return !decided && replays < kMaxReplays; }
};

}  // namespace hybrid
