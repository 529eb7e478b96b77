#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "automaton/system.h"
#include "solvers/checking/check_result.h"

namespace hybrid {

/// Every property `system` declares, over System slots: the system's own, then, for composed
/// systems, each instantiated component's, named INSTANCE.NAME with `in` atoms qualified. What
/// `hybrid check` checks by default.
std::vector<Property> DeclaredProperties(const System& system);

/// Z3 resource units (its deterministic `rlimit` count) in one budget second: about one second
/// of solver work on the machine it was calibrated on (see docs/verification.md).
inline constexpr std::uint64_t kResourceUnitsPerBudgetSecond = 2'500'000;

/// The solver budget of one check: every SMT query of the check draws Z3 resource units from it
/// (Z3's `rlimit` count, which depends on the formulas only, not on the machine or its load), so
/// the same check with the same budget always gives the same verdicts. A query is given at most
/// what is left; once nothing is left, no query runs and what is undecided stays `unknown`.
///
/// A safety net bounds CPU time where Z3's count misses its work (some nonlinear arithmetic; a
/// search query of the finger that allocates about 200 million times per second): with T = max(60
/// s, 10 s per budget second), no query starts after the process has used T of CPU time since the
/// budget's creation, and a query given u units runs at most 10 s of CPU time per budget second of
/// u (at least 10 s, at most T). CPU time, not wall-clock time, so that the machine's load does not
/// change where it fires; a query it stops is `unknown`, is charged its whole allowance, and its
/// solver gets no further query, so that what follows does not depend on where it stopped. Only the
/// machine's speed can then change a verdict, and the reasons say when the net fired.
class SolverBudget {
 public:
  /// A budget of `seconds` budget seconds (positive and finite, at most 10^6), i.e. seconds *
  /// kResourceUnitsPerBudgetSecond resource units. Throws std::invalid_argument otherwise.
  explicit SolverBudget(double seconds);

  double seconds() const { return seconds_; }
  std::uint64_t total() const { return total_; }
  std::uint64_t used() const { return used_; }
  std::uint64_t remaining() const { return used_ < total_ ? total_ - used_ : 0; }
  /// Records `units` spent (the budget may be overdrawn by the last query's overshoot).
  void Charge(std::uint64_t units) {
    used_ += units;
    if (observer_) observer_(*this);
  }
  /// Called after every Charge (for a progress report; it must not throw or charge).
  void SetObserver(std::function<void(const SolverBudget&)> observer) {
    observer_ = std::move(observer);
  }

  /// The safety net's deadline, in seconds of the process's CPU time from the budget's
  /// creation: max(60, 10 * seconds()).
  double SafetySeconds() const;
  /// The CPU-time limit of a query given `units` resource units, in seconds: 10 s per budget
  /// second of `units`, at least 10 s, at most SafetySeconds().
  double SafetyCpuSeconds(std::uint64_t units) const;
  /// Whether the deadline has passed (no query may start).
  bool SafetyExpired() const;
  /// Records that the safety net stopped a query; safety_stopped() tells.
  void NoteSafetyStop() { safety_stopped_ = true; }
  bool safety_stopped() const { return safety_stopped_; }

 private:
  double seconds_;
  std::uint64_t total_;
  std::uint64_t used_ = 0;
  double start_cpu_ = 0.0;  // the process's CPU time at creation, in seconds
  bool safety_stopped_ = false;
  std::function<void(const SolverBudget&)> observer_;
};

/// The `prove` method of `hybrid check`: bounded model checking and k-induction with the Z3 SMT
/// solver over an encoding of the automaton (see SmtEncoding in smt_encoding.h for exactly what
/// it covers), for every piecewise-constant input within the inputs' bounds and every value of
/// the parameters declared with a range.
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
/// Every `violated` or `reachable` verdict is confirmed at the end by a fresh replay of its trace
/// (ConfirmTrace); one that does not replay is reported `unknown`.
///
/// Systems: a property that reads one component whose continuous variables no other component
/// shares, and none of whose urgent transitions synchronises with another component, is checked
/// on that component alone (composition then only removes runs of the component: other
/// components cannot write its variables, and synchronisation only removes lazy jumps; an urgent
/// jump that waits for a partner would let time pass where the component alone cannot);
/// otherwise on the product of its interaction group (components joined by shared variables or
/// labels, System::Product, up to `max_product_modes`), else `unknown`.
class PropertyProver {
 public:
  struct Options {
    /// Longest path searched for a counterexample or witness, in steps.
    int max_depth = 10;
    /// Largest k tried for k-induction.
    int max_induction = 1;
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
    int max_product_modes = 2000;
  };

  PropertyProver() = default;
  explicit PropertyProver(Options options) : options_(options) {}

  /// One result per property of `properties` (System slots, as System::properties() or a
  /// component's declared properties qualified like the System), in order, within a budget of
  /// options().budget. Throws std::invalid_argument for a property that reads inputs, or for a
  /// budget out of range.
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

  const Options& options() const { return options_; }

 private:
  /// options_.budget, or the former search_seconds when set.
  double BudgetSeconds() const;

  Options options_;
};

}  // namespace hybrid
