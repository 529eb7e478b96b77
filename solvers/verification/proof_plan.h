#pragma once

// Internal to hybrid::verification.

#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "solvers/verification/proof_job.h"
#include "solvers/verification/shared_proof.h"

namespace hybrid {

/// The plan of a PropertyProver::Check: which automata are checked and what each is asked.
///
/// - A property that reads one component whose continuous variables no other component shares,
///   and none of whose urgent transitions synchronises with another component, goes to that
///   component's job, over its own slots and mode names; one asked twice is answered once
///   (ProofGoal::also).
/// - Any other property goes to the job of the product of the interaction groups it reads
///   (components joined by shared variables or labels; System::Product up to
///   `max_product_modes` modes, made once per group set), its `in A.m` atoms becoming
///   disjunctions of product modes; when the product is too large, its result is `unknown`
///   right away, with the reason.
/// - A component's job, when asked anything, also gets the component's declared invariants
///   (`always`, `never`) not asked already as lemmas (ProofGoal::result -1).
/// - A job whose questions an earlier job already asks of an automaton equal up to names (an
///   instance of the same automaton; a product of instances bound alike) is not run: the earlier
///   job's results are copied (SharedProof).
///
/// The steps come in a fixed order: the components' jobs by component index (each run or
/// copied), then the products' jobs to run (by their components), then the products' copies.
/// Each result gets its property's name, kind and the method "prove" at construction.
class ProofPlan {
 public:
  /// One step: run `job` (`from` null), or copy the results of the earlier job `from` to `job`
  /// by `how`. Both point into the plan.
  struct Step {
    const ProofJob* job = nullptr;
    const ProofJob* from = nullptr;
    std::optional<SharedProof> how;
  };

  /// The product of a group of components, made on first use, and its job.
  struct Product {
    std::optional<Automaton> automaton;
    std::vector<int> components;           ///< the System's components, in product order
    std::vector<std::vector<int>> tuples;  ///< product mode -> component modes
    std::string failure;                   ///< why the product could not be made
    ProofJob job;
  };

  /// Plans the check of `properties` (System slots) on `system`, which is borrowed and must
  /// outlive the plan. `results` (one per property) get their names, kinds and method, and
  /// `unknown` for a property whose product is too large. Throws std::invalid_argument for a
  /// property that reads an input.
  ProofPlan(const System& system, std::span<const Property> properties, int max_product_modes,
            std::vector<CheckResult>& results);

  /// Not copyable or movable: the steps and jobs point into the plan.
  ProofPlan(const ProofPlan&) = delete;
  ProofPlan& operator=(const ProofPlan&) = delete;

  /// The steps, in the order they are to be taken.
  const std::vector<Step>& steps() const { return steps_; }
  /// How many steps run a job (the rest copy).
  int runs() const { return runs_; }

 private:
  // Components' jobs, then products' jobs: which need a run of their own, which are copies.
  void PlanComponents(const System& system);
  void PlanProducts(const System& system);

  std::vector<ProofJob> jobs_;  // per component (empty goals: not checked)
  // Keyed by the components (ascending indices); a map, so that automata stay where they are.
  std::map<std::vector<int>, Product> products_;
  std::vector<Step> steps_;
  int runs_ = 0;
};

}  // namespace hybrid
