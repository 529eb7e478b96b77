#pragma once

#include <functional>
#include <string>
#include <vector>

#include "automaton/system.h"
#include "solvers/verification/check_result.h"

namespace hybrid {

/// The `reach` method of `hybrid check`: exact polyhedral reachability for linear hybrid
/// automata (LinearHybridSystem: constant, rectangular and input-affine rates; linear
/// invariants, guards and resets; uncertain parameters as constant dimensions), composed
/// systems explored location by location without building the product.
///
/// From the initial sets, each symbolic state (a location and a convex polyhedron) is let flow
/// (time elapse at the location's rates, kept inside its invariant and stopped where an urgent
/// single-inequality guard starts to hold), then every edge is taken (guard, reset, target
/// invariant). On entering a location the values of the variables dead there are forgotten
/// (VariableLiveness: nothing reads them before a reset writes them; the variables the checked
/// properties read are never dead), so states that differ only in them coincide. A new state
/// contained in one already found at its location is dropped (before its time elapse where that is
/// exact), and states it contains are not expanded; when none is left the reachable set is
/// complete (a fixpoint) and every property it does not meet is `proved` (`unreachable` for
/// `reach`): exact on the live variables. A state that meets a property's bad (target) states is
/// turned into a concrete run along its path, exactly: the states from which the rest of the path
/// reaches the bad states with a margin are propagated backward (inverse time elapse, guard,
/// reset pre-image), the margin (at most 1) is maximised over the initial set, and the run is
/// picked forward flow by flow inside those sets (a central point each: dwell time and one input
/// value per flow), so its cost grows linearly with the path's length. The run is replayed by the
/// simulator with its jump schedule (ConfirmTrace): `violated` (`reachable`) if it replays,
/// `unknown` otherwise. The exploration is exact (no widening, no hull) and bounded by
/// `max_states` symbolic states (deterministic), with a CPU-time safety net; hitting either leaves
/// undecided properties `unknown`.
class PolyhedralReachability {
 public:
  struct Options {
    /// Most symbolic states explored per check (a deterministic bound).
    int max_states = 50000;
    /// Safety net: the exploration stops after this much CPU time of the process.
    double cpu_seconds = 120.0;
    /// If set, called every 64 expanded states with the symbolic states found so far and those
    /// still queued (for a progress report; it must not throw).
    std::function<void(int states, int queued)> progress;
  };

  PolyhedralReachability() = default;
  explicit PolyhedralReachability(Options options) : options_(options) {}

  /// Whether `system` and `properties` are in the engine's class; if not, `why` says what is
  /// not (a non-linear flow, guard, reset or property, inputs in guards, ...).
  static bool Handles(const System& system, const std::vector<Property>& properties,
                      std::string* why);

  /// One result per property (method "reach"), in order. Properties outside the class are
  /// `unknown` with the reason.
  std::vector<CheckResult> Check(const System& system,
                                 const std::vector<Property>& properties) const;

 private:
  Options options_;
};

}  // namespace hybrid
