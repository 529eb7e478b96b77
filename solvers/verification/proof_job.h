#pragma once

// Internal to hybrid::verification: what the prover's plan (ProofPlan) hands to its proof runs
// (ProofRun) and to the copies of shared proofs (SharedProof).

#include <chrono>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/property.h"

namespace hybrid {

/// One question to decide on one automaton: a property over the automaton's own slots and mode
/// names, the result it answers and the property as asked, over System slots, for the replay.
struct ProofGoal {
  Property property;      ///< local: the job's automaton's slots and mode names
  int result = -1;        ///< index into the Check's results; -1 for a lemma only
  Property original;      ///< as asked (System slots and names), for the replay of a trace
  std::vector<int> also;  ///< further results asking the same question
};

/// One automaton to check and the goals it is asked: a component of the System alone, or the
/// product of several components (System::Product). The job's slot i is System slot
/// to_system[i]; its goals come in the order the plan added them (asked properties first, then
/// the component's declared invariants as lemmas).
struct ProofJob {
  /// Borrowed: a component's automaton in the System, or a product the plan owns; the referent
  /// must outlive the job.
  const Automaton* automaton = nullptr;
  /// Its component's index in the System, or -1 for a product of components.
  int component = -1;
  /// For a product: its components (System indices, in product order). The product's initial
  /// states are the cartesian product of theirs, the first component varying slowest
  /// (System::Product).
  std::vector<int> product_components;
  /// Automaton slot -> System slot.
  std::vector<int> to_system;
  std::vector<ProofGoal> goals;
};

/// Seconds of wall-clock time since `start`: CheckResult::seconds of a result decided now in a
/// Check that started at `start`.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace hybrid
