#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"

namespace hybrid {

/// Reach units (the deterministic count that bounds polyhedral reachability) in one budget
/// second: about one second of exploration on the machine it was calibrated on, as the prover's
/// kResourceUnitsPerBudgetSecond is for the SMT solver (docs/verification.md, "The budget"). What
/// costs units:
/// - a polyhedron operation (intersection, time elapse, reset, hull, emptiness, containment,
///   intersection test, pre-image, optimisation, projection): kReachUnitsPerOperation plus one
///   unit per kReachBytesPerUnit bytes of the representations it reads or makes
///   (ConvexPolyhedron::RepresentationBytes, so larger polyhedra and longer coefficients cost
///   more);
/// - comparing the bounding boxes of two states at one location (a new state is compared with
///   every state stored there, so these grow with the square of the states of a location):
///   kReachUnitsPerBoxComparison;
/// - building a location (its invariant, rates and edges): kReachUnitsPerLocation;
/// - replaying a run found (ConfirmTrace): kReachUnitsPerReplayedStep per symbolic state of its
///   path.
inline constexpr std::uint64_t kReachUnitsPerBudgetSecond = 100'000'000;
inline constexpr std::uint64_t kReachUnitsPerOperation = 4;
inline constexpr std::uint64_t kReachBytesPerUnit = 16;
inline constexpr std::uint64_t kReachUnitsPerBoxComparison = 2;
inline constexpr std::uint64_t kReachUnitsPerLocation = 20'000;
inline constexpr std::uint64_t kReachUnitsPerReplayedStep = 2'000;

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
/// `unknown` otherwise. The exploration is exact (no widening, no hull); beside it, for
/// properties without a horizon, an exploration on convex hulls (Options::hull_units) may prove
/// properties (never refute them) at its own fixpoint.
///
/// The budget is deterministic: the exploration charges reach units for its work (see
/// kReachUnitsPerBudgetSecond: per polyhedron operation, by the size of the polyhedra it reads;
/// per comparison of a new state's bounding box with a stored one's; per step of a run
/// replayed), a count that depends on the model and the properties only, so the same check
/// stops at the same point, with the same verdicts and the same number of symbolic states, on any
/// machine and under any load. A CPU-time safety net bounds what the count misses; when it fires
/// the reasons say so (that verdict may then differ on another machine). Either bound, and the
/// optional bound on symbolic states, leaves undecided properties `unknown`, never `proved`.
class PolyhedralReachability {
 public:
  struct Options {
    /// The deterministic budget of one Check, in budget seconds of kReachUnitsPerBudgetSecond
    /// reach units (positive and finite, at most 10^6; Check throws std::invalid_argument
    /// otherwise). The exploration stops once it has used them; the explorations of properties
    /// with different horizons (one per horizon) each get an equal share of what is left.
    double budget = 60.0;
    /// Most symbolic states stored per exploration (a deterministic bound too); 0: no bound.
    int max_states = 0;
    /// Safety net: no exploration continues once the checking thread has used this much CPU
    /// time (seconds) since Check began; 0: max(60, 10 * budget), the prover's rule.
    double cpu_seconds = 0.0;
    /// If set, called every 64 expanded states with the symbolic states found so far and those
    /// still queued (for a progress report; it must not throw).
    std::function<void(int states, int queued)> progress;
    /// For properties without a horizon on a System of several interaction groups
    /// (System::InteractionGroups): the reach units the exact exploration uses before the
    /// groups, each explored alone, take their first turn (1/32 of that); each later turn of
    /// both doubles. Once every group is complete, a property whose bad states the product of
    /// their reachable sets misses holds (GroupProduct: solvers/reachability/group_product.h).
    /// So the groups cost at most 1/32 of the exact exploration's work. 0: the groups take
    /// their turn first, to their fixpoint (or the budget).
    std::uint64_t group_turn_units = 1'000'000;
    /// For properties without a horizon: the reach units of the first turn of reachability on
    /// convex hulls (HullExploration: one polyhedron per location and per value of the
    /// variables constant there, an over-approximation: solvers/reachability/hull_exploration.h),
    /// taken before the exact exploration (at most a quarter of the exploration's share of the
    /// budget); later turns get as many units as each of the exact exploration's turns. At its
    /// fixpoint a property whose bad states the hulls miss holds; the hull proves nothing else (a
    /// bad state met is left to the exact exploration), and it is abandoned once every property
    /// left is met or its coefficients grow too long. 0: no hull. The default, 2 budget seconds,
    /// lets the hulls of FISCS05 (143 million units) end in their first turn.
    std::uint64_t hull_units = 200'000'000;
    /// Another engine's turn (say, a cheap proof by induction), taken once the exploration of
    /// the properties without a horizon has used `pause_units` reach units without deciding all
    /// of them: `pause` is called once with the system and the properties still open (over its
    /// slots) and returns one result
    /// each (same order); a definite one (which must keep the PropertyChecker contract: a
    /// `violated` or `reachable` verdict with its replayed trace) becomes that property's result
    /// and the exploration stops seeking it; then it goes on where it was. An exploration that
    /// ends first never pauses. Not set: no pause.
    std::function<std::vector<CheckResult>(const System& system, const std::vector<Property>& open)>
        pause;
    std::uint64_t pause_units = 0;
  };

  /// What one Check spent, and why its explorations ended (for reports such as `check --json`).
  struct Usage {
    /// What stopped an exploration early: kNone when every exploration reached its fixpoint or
    /// decided all its properties; else the bound that stopped one, kSafetyNet if the CPU-time
    /// safety net stopped any (its verdicts may then depend on the machine), else kBudget if the
    /// deterministic budget stopped any, else kStateBound.
    enum class Stop { kNone, kStateBound, kBudget, kSafetyNet };
    std::uint64_t units_total = 0;  ///< the budget, in reach units
    std::uint64_t units_used = 0;   ///< reach units charged (may pass units_total by one step)
    long long states = 0;           ///< symbolic states stored, over every exploration
    Stop stop = Stop::kNone;
  };

  PolyhedralReachability() = default;
  explicit PolyhedralReachability(Options options) : options_(options) {}

  /// Whether `system` and `properties` are in the engine's class; if not, `why` says what is
  /// not (a non-linear flow, guard, reset or property, inputs in guards, ...).
  static bool Handles(const System& system, const std::vector<Property>& properties,
                      std::string* why);

  /// One result per property (method "reach"), in order. Properties outside the class are
  /// `unknown` with the reason.
  /// With `usage` (if not null), what the check spent. Throws std::invalid_argument for a budget
  /// out of range.
  std::vector<CheckResult> Check(const System& system, const std::vector<Property>& properties,
                                 Usage* usage = nullptr) const;

 private:
  Options options_;
};

}  // namespace hybrid
