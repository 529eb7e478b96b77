#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"

namespace hybrid {

/// Taylor steps in one budget second (`hybrid check --budget`): about a second of exploration of
/// a five-dimensional model with guards (the spacecraft) on the development machine, a few
/// tenths of one for a two-dimensional model. A count, not a clock, so the same check stops at
/// the same point everywhere.
inline constexpr std::int64_t kFlowpipeStepsPerBudgetSecond = 4000;
/// Mode entries explored per budget second (at least 50 in all).
inline constexpr int kFlowpipeEntriesPerBudgetSecond = 20;

/// The `flowpipe` method of `hybrid check`: sound reachability for hybrid automata with affine
/// and polynomial dynamics (x' = A x + B u + c, Van der Pol's x' = y, y' = (1 - x^2) y - x, and
/// rational right-hand sides), by validated Taylor integration over affine forms.
///
/// Continuous part. A mode's flow is integrated step by step from the set where the mode was
/// entered. The set at a step's start is a vector of affine forms over shared noise symbols
/// (a zonotope plus an independent error box), so linear maps keep the correlations between
/// variables. For a step of length h: an a-priori box B with X + [0, h] f(B, U) inside B (the
/// Picard operator; it encloses every solution for s in [0, h], whatever the inputs do); the
/// Taylor coefficients x_0..x_K of the solution with the inputs at their midpoints, by Taylor-mode
/// differentiation of f in affine arithmetic; the Lagrange remainder h^{K+1} x_{K+1}(B) in
/// interval arithmetic; and, when inputs vary, the distance to the solutions of every other
/// input signal in U, bounded by Gronwall's inequality from the input gains |df/du| and the
/// Jacobian |df/dx| over B (inputs must enter affinely with constant coefficients). Uncertain
/// parameters are state components with zero flow, so their correlation with the state is kept
/// within a mode. Every floating-point operation is rounded outward and exactly where it is
/// exact (error-free transformations under round-to-nearest), so the enclosures are sound and a
/// bound that is attained, such as a ball's drop height, is not lost to rounding.
///
/// Discrete part. Each step gives a segment (the states of [t, t + h]); guards and invariants
/// are read in their closure (docs/model_language.md), property atoms exactly. Where a segment
/// may meet a guard, the segments of that crossing are cut to the guard and the invariant
/// (interval propagation through their affine comparisons) and joined into one box (the
/// clustering: a box per crossing, which loses the correlations between variables at every jump
/// but keeps the number of sets linear in the jumps); the reset maps it, the target invariant cuts
/// it, and it is explored from its earliest time unless a box already explored in the same mode
/// from no later a time contains it (a fixpoint). Steps shrink near urgent guards (a crossing is
/// refined to an eighth of the step). A mode's flow stops where its start set lies outside the
/// invariant or inside an urgent guard, or where a box that holds the flow so far (widened) is
/// positively invariant: on every face that the invariant does not exclude the vector field
/// points inward for every input (Nagumo's condition, checked in interval arithmetic), so the
/// rest of the flow stays in it for all time.
///
/// Verdicts. `always P` is `proved` (`never P` likewise, `reach P` `unreachable`) when no
/// segment may meet the bad states. When the exploration is complete (every set explored to its
/// end) this holds for all time; when the budget stops it first, the earliest time still
/// unexplored is the frontier, and a property is decided up to it only: `within T` properties
/// with T below the frontier as asked, unbounded ones as `proved` with CheckResult::within set
/// (shown `proved within T`). A segment that may meet the bad states leaves the property
/// `unknown` (an over-approximation cannot refute); `violated` and `reachable` come from
/// simulation (`auto` runs the falsifier after this engine).
///
/// Bounds: a deterministic budget of Taylor steps (Options::max_steps) and of explored sets; the
/// same check stops at the same point on any machine and under any load.
class FlowpipeReachability {
 public:
  struct Options {
    /// Taylor order K (1 to 12).
    int order = 6;
    /// The step in model time units; 0: automatic per mode entry (a power of two near
    /// 0.2 / |df/dx|). Steps are powers of two, so that powers of h are exact.
    double step = 0.0;
    /// Taylor steps over the whole exploration (the budget; positive).
    std::int64_t max_steps = 200000;
    /// Mode entries explored (sets taken from the worklist).
    int max_entries = 5000;
    /// Initial boxes at most: while a property is still open and the budget lasts, the whole
    /// exploration is run again with every initial box split in two along its widest component
    /// (variables and uncertain parameters), so the errors of the nonlinear terms, which grow
    /// with the square of a set's width, shrink (at most 1 << 20).
    int max_pieces = 16;
    /// Noise symbols kept per set before the smallest are boxed (Girard's reduction); 0:
    /// 10 per state component.
    int max_symbols = 0;
    /// Optional: called once, before the first split, with the properties still open; those
    /// for which it returns true (e.g. a few simulations found a violation) are not refined
    /// further. Saves the splitting of properties that are simply false; the verdicts do not
    /// depend on it (such a property stays `unknown` here, for a falsifier to decide).
    std::function<std::vector<bool>(const System&, std::span<const Property>)> evidently_false;
    /// Called now and then with the steps taken and the sets still queued (must not throw).
    std::function<void(std::int64_t steps, int queued)> progress;
  };

  /// What one Check explored.
  struct Usage {
    std::int64_t steps = 0;
    int entries = 0;
    /// Every set was explored to its end (the results hold for all time).
    bool complete = false;
    /// The earliest model time not explored (infinity when complete).
    double frontier = 0.0;
  };

  /// A box of the reach set: the states of mode `mode` during a step (or, for an invariant box,
  /// from `t_lo` on), one [lo, hi] per variable of ReachSet::variables.
  struct ReachBox {
    std::string mode;
    double t_lo = 0.0;
    double t_hi = 0.0;
    std::vector<std::pair<double, double>> box;
  };
  struct ReachSet {
    std::vector<std::string> variables;
    std::vector<ReachBox> boxes;
  };

  FlowpipeReachability();
  explicit FlowpipeReachability(Options options);

  /// Whether the engine applies: every mode's flow polynomial or rational in the variables and
  /// affine in the inputs (rectangular rates are inputs). `why` says which flow does not.
  static bool Handles(const System& system, std::span<const Property> properties, std::string* why);

  /// The verdicts of `properties` (see the class comment), each with method "flowpipe". With
  /// `reach_set`, also the boxes of every step (for plots). Throws std::invalid_argument for bad
  /// options.
  std::vector<CheckResult> Check(const System& system, std::span<const Property> properties,
                                 Usage* usage = nullptr, ReachSet* reach_set = nullptr) const;

 private:
  Options options_;
};

}  // namespace hybrid
