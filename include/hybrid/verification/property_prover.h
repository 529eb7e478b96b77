#pragma once

#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "hybrid/verification/solver_budget.h"

namespace hybrid {

/// Every property `system` declares, over System slots: the system's own, then, for composed
/// systems, each instantiated component's, named INSTANCE.NAME with `in` atoms qualified. What
/// `hybrid check` checks by default.
std::vector<Property> DeclaredProperties(const System& system);

/// The `prove` method of `hybrid check`: bounded model checking and k-induction with an SMT
/// solver over an encoding of the automaton (see SmtEncoding in solvers/verification/smt_encoding.h
/// for exactly what it covers), for every piecewise-constant input within the inputs' bounds and
/// every value of the parameters declared with a range.
///
/// Per model (each automaton checked gets an equal share of what is left of the budget; within
/// it, base case and induction may use up to half, the counterexample search up to 90%, the
/// unreachability proofs the rest):
/// 1. Candidates: the properties asked for plus every invariant the automaton declares (`always`
///    and `never`), which may serve as lemmas.
/// 2. Bounded model checking to `max_depth` steps (a step is a flow segment or a jump): a path
///    that breaks a candidate (or, for `reach`, ends in its target) is turned into a Trace
///    (parameter values, initial values, a step input) and replayed by the simulator. A replayed
///    violation is `violated` (`reachable` for `reach`); a path the simulator does not follow
///    (the encoding over-approximates) leaves the property `unknown`. Violations by at least
///    `robust_margin` are looked for first: they replay clear of rounding.
/// 3. k-induction, k = 1 .. max_induction, on the surviving candidates together (Houdini: a
///    candidate that fails the step is dropped and the rest re-checked): those left are
///    invariants of every run, hence `proved`; a `reach` target that no initial state meets and
///    whose negation is inductive relative to them is `unreachable`.
/// In time, the search of 2 comes in two parts: paths shorter than max_induction steps first (the
/// base case that k-induction needs), the longer ones after the induction. Every `violated` or
/// `reachable` verdict is confirmed at the end by a fresh replay of its trace (ConfirmTrace); one
/// that does not replay is reported `unknown`.
///
/// Systems: a property that reads one component whose continuous variables no other component
/// shares, and none of whose urgent transitions synchronises with another component, is checked
/// on that component alone (composition then only removes runs of the component: other
/// components cannot write its variables, and synchronisation only removes lazy jumps; an urgent
/// jump that waits for a partner would let time pass where the component alone cannot);
/// otherwise on the product of its interaction group (components joined by shared variables or
/// labels, System::Product, up to `max_product_modes`), else `unknown`. A component or product
/// that asks the same questions as an earlier instance of the same automaton (or a product of
/// instances bound alike) is not checked again: the earlier results are copied, each trace
/// renamed and replayed.
///
/// Logging (hybrid/automaton/log.h, topic "prove"; nothing is logged unless a sink is installed,
/// and logging changes no result):
/// - kInfo: one line per automaton checked (its name, goals and share of the budget) and one per
///   SMT query run (its purpose, result, resource units and seconds, and whether the CPU-time
///   safety net stopped it);
/// - kDebug: the start of each query, each query the budget refused, each path found that does
///   not replay in the simulator (with the path: parameters, then one line per state), and each
///   failed induction step (k, the mode, the candidates it breaks);
/// - kWarning: a query file that cannot be written (Options::query_dump_directory).
class PropertyProver {
 public:
  struct Options {
    /// Longest path searched for a counterexample or witness, in steps.
    int max_depth = 10;
    /// Largest k tried for k-induction.
    int max_induction = 1;
    /// Margin by which a counterexample is first looked for (a violation by at least this much
    /// replays clear of rounding), before exact ones.
    double robust_margin = 1e-3;
    /// The solver budget of a whole Check (or ReachableModes) call without an explicit
    /// SolverBudget, in budget seconds (see SolverBudget).
    double budget = 60.0;
    /// Former name of `budget`, kept for older callers: when positive, it is used instead.
    double search_seconds = 0.0;
    /// Most resource units one SMT query may use (less when less is left of the budget). A query
    /// that runs out makes its property `unknown` (an induction candidate that runs out is
    /// dropped).
    unsigned resource_limit = 25'000'000;
    /// Largest product of components checked, in modes (System::Product); a property that
    /// needs a larger one is `unknown`.
    int max_product_modes = 2000;
    /// A directory (which must exist) into which every SMT query is written before it runs, as
    /// SMT-LIB 2 preceded by a comment with its resource limit (`; rlimit N`): q0.smt2, q1.smt2,
    /// ... in the order the queries of one Check run (a later Check overwrites them), for
    /// reproducing a query with the SMT solver itself. Empty (the default): none is written.
    /// Writing them changes no result.
    std::string query_dump_directory;
  };

  PropertyProver() = default;
  explicit PropertyProver(Options options) : options_(options) {}

  /// One result per property of `properties` (System slots, as System::properties() or a
  /// component's declared properties qualified like the System), in order, within a budget of
  /// options().budget. Throws std::invalid_argument for a property that reads inputs, for a
  /// budget out of range, or for a query_dump_directory that is not a directory.
  std::vector<CheckResult> Check(const System& system, std::span<const Property> properties) const;
  /// The same, drawing from `budget` (shared with other calls).
  std::vector<CheckResult> Check(const System& system, std::span<const Property> properties,
                                 SolverBudget& budget) const;

  /// One discrete state of a component and whether some run reaches it.
  struct ModeReachability {
    std::string mode;                                   ///< qualified mode name
    std::vector<std::pair<std::string, int>> discrete;  ///< discrete values, by variable name
    /// kReachable (with a replayed witness), kUnreachable (proved) or kUnknown.
    Verdict verdict = Verdict::kUnknown;
    std::string reason;
    std::optional<Trace> trace;
  };
  /// Reachability of every mode of component `component` (`reach in MODE` for each), checked as
  /// Check does (within options().budget).
  std::vector<ModeReachability> ReachableModes(const System& system, int component) const;
  /// The same, drawing from `budget`.
  std::vector<ModeReachability> ReachableModes(const System& system, int component,
                                               SolverBudget& budget) const;
  /// The queries of ReachableModes: `reach in MODE` for each mode of component `component`, in
  /// mode order, named "reach MODE" (the qualified mode name).
  static std::vector<Property> ModeQueries(const System& system, int component);
  /// ReachableModes' answer from `results`, the verdicts of ModeQueries(system, component) in
  /// order (by any checker). A verdict up to a time only (CheckResult::within) is `unknown`
  /// here, its reason saying so: whether a run ever enters a mode has no horizon.
  static std::vector<ModeReachability> ModeResults(const System& system, int component,
                                                   std::span<const CheckResult> results);

  const Options& options() const { return options_; }

 private:
  /// options_.budget, or the former search_seconds when set.
  double BudgetSeconds() const;

  Options options_;
};

}  // namespace hybrid
