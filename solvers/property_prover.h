#pragma once

#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "automaton/system.h"
#include "solvers/check_result.h"

namespace hybrid {

/// Every property `system` declares, over System slots: the system's own, then, for composed
/// systems, each instantiated component's, named INSTANCE.NAME with `in` atoms qualified. What
/// `hybrid check` checks by default.
std::vector<Property> DeclaredProperties(const System& system);

/// The `prove` method of `hybrid check`: bounded model checking and k-induction with the Z3 SMT
/// solver over an encoding of the automaton (see SmtEncoding in smt_encoding.h for exactly what
/// it covers), for every piecewise-constant input within the inputs' bounds and every value of
/// the parameters declared with a range.
///
/// Per model:
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
///    invariants of every run, hence `proved`; a `reach` target whose negation joins them is
///    `unreachable`.
///
/// Systems: a property that reads one component whose continuous variables no other component
/// shares is checked on that component alone (composition only removes runs of a component:
/// other components cannot write its variables, and synchronisation only restricts its jumps);
/// otherwise on System::Product (up to `max_product_modes`), else `unknown`.
class PropertyProver {
 public:
  struct Options {
    /// Longest path searched for a counterexample or witness, in steps.
    int max_depth = 10;
    /// Largest k tried for k-induction.
    int max_induction = 1;
    double robust_margin = 1e-3;
    /// Per SMT query, in Z3 resource units (`rlimit`: deterministic, unlike a time limit; about
    /// 2.5 million per second here). A query that runs out makes its property `unknown`
    /// (an induction candidate that runs out is dropped).
    unsigned resource_limit = 25'000'000;
    /// Wall-clock budget of the search for counterexamples and witnesses (step 2) per
    /// automaton; when it runs out, undecided properties are `unknown`.
    double search_seconds = 30.0;
    int max_product_modes = 2000;
  };

  PropertyProver() = default;
  explicit PropertyProver(Options options) : options_(options) {}

  /// One result per property of `properties` (System slots, as System::properties() or a
  /// component's declared properties qualified like the System), in order. Throws
  /// std::invalid_argument (naming "PropertyProver") for a property that reads inputs.
  std::vector<CheckResult> Check(const System& system, std::span<const Property> properties) const;

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
  /// Check does.
  std::vector<ModeReachability> ReachableModes(const System& system, int component) const;

 private:
  Options options_;
};

}  // namespace hybrid
