#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/automaton/predicate.h"
#include "hybrid/automaton/system.h"
#include "solvers/flowpipe/segment.h"
#include "solvers/flowpipe/taylor_tape.h"

namespace hybrid::flowpipe_internal {

/// Three-valued truth of a condition over a set of states.
enum class Truth { kFalse, kMaybe, kTrue };

/// A comparison `r REL 0` compiled for the engine: the residual with the parameters resolved
/// (System::ResolvedParameter: fixed ones as constants, uncertain ones as state components),
/// and its affine form over the slots when it is affine with coefficients that are exactly
/// those of the expression (a rounded one, such as the 1/3 of (x + y) / 3, would make the bounds
/// built on it unsound; such a residual is read by interval evaluation only).
struct Residual {
  Expression expression;
  Relation relation = Relation::kLessEqual;
  std::optional<hybrid::AffineForm> affine;
};

/// A system compiled for flowpipe reachability: the state components (the continuous
/// variables, then the uncertain parameters as components with zero flow), the environment of
/// the other slots as intervals (fixed parameters as points, inputs as their bounds, discrete
/// variables per mode), and the modes of the composition (tuples of component modes, made on
/// demand with System::ProductModeOf and System::StepsFrom).
class FlowpipeModel {
 public:
  struct Jump {
    std::string name;
    std::vector<Residual> guard;
    /// The guard and the source mode's invariant: where the jump may be taken.
    std::vector<Residual> guard_and_invariant;
    std::vector<std::pair<int, Residual>> resets;  ///< (state component, new value)
    bool urgent = true;
    int target = -1;  ///< mode index
  };
  struct CompiledMode {
    std::vector<int> tuple;
    std::string name;                ///< joined for messages
    std::vector<std::string> names;  ///< qualified component mode names (for `in M`)
    std::vector<TightInterval> env;  ///< the environment with this mode's discrete values
    std::optional<TaylorTape> tape;  ///< nullopt: unsupported flow (why in `unsupported`)
    std::string unsupported;
    std::vector<Residual> invariant;
    std::vector<Jump> jumps;
    bool jumps_made = false;
  };
  struct Initial {
    int mode = -1;
    std::vector<TightInterval> box;
  };

  /// Compiles `system` (throws std::invalid_argument for a system the engine cannot read, e.g. a
  /// product with too many modes).
  explicit FlowpipeModel(const System& system);

  const System& system() const { return system_; }
  int dimension() const { return static_cast<int>(component_slot_.size()); }
  int num_variables() const { return num_variables_; }
  int num_inputs() const { return static_cast<int>(input_slot_.size()); }
  const SlotMap& slots() const { return slots_; }
  /// The system name of state component i.
  const std::string& ComponentName(int i) const;
  /// The input boxes and their centres (the inputs' midpoints).
  const std::vector<TightInterval>& input_box() const { return input_box_; }

  /// The initial sets (one per combination of the components' `init` declarations).
  std::vector<Initial> Initials();
  /// Mode `index` (made on first use; its jumps with MakeJumps).
  CompiledMode& Mode(int index) { return *modes_[static_cast<std::size_t>(index)]; }
  void MakeJumps(int index);
  int num_modes() const { return static_cast<int>(modes_.size()); }

  Residual Compile(const Comparison& c) const;
  /// An enclosure of the residual's value over `segment` in environment `env` (state slots
  /// from the segment).
  TightInterval Bound(const Residual& r, const Segment& segment,
                      const std::vector<TightInterval>& env) const;
  /// The truth of `r REL 0` over the segment; strict relations read in their closure when
  /// `closure` (guards and invariants), exactly otherwise (properties).
  Truth Holds(const Residual& r, const Segment& segment, const std::vector<TightInterval>& env,
              bool closure) const;
  /// The truth of a conjunction (guard, invariant) in its closure.
  Truth HoldsAll(const std::vector<Residual>& conjunction, const Segment& segment,
                 const std::vector<TightInterval>& env) const;
  /// The truth of a property's predicate in mode `mode` over the segment (exact reading).
  Truth Evaluate(const Predicate& p, const Segment& segment, const CompiledMode& mode) const;
  /// Shrinks `box` to the states satisfying the conjunction (closure), by interval propagation
  /// through its affine comparisons; false when the box becomes empty.
  bool Contract(const std::vector<Residual>& conjunction, std::vector<TightInterval>& box,
                const std::vector<TightInterval>& env) const;
  /// Shrinks `box` (an enclosure of `segment`) to the segment's states that satisfy the
  /// conjunction (closure), using the correlations the segment keeps: for each state component
  /// x_i and each affine comparison n.x <= d, min x_i over the segment and the halfspace is at
  /// least max over lambda >= 0 of min over the segment of (e_i + lambda n).x - lambda d (weak
  /// duality, so every lambda tried gives a sound bound; a golden-section search picks a good
  /// one). Then Contract. False when no state of the segment satisfies the conjunction.
  bool ContractSegment(const std::vector<Residual>& conjunction, const Segment& segment,
                       std::vector<TightInterval>& box,
                       const std::vector<TightInterval>& env) const;
  /// The value of `r`'s expression over `box` (an enclosure).
  TightInterval Value(const Residual& r, const std::vector<TightInterval>& box,
                      const std::vector<TightInterval>& env) const;
  /// The value of `r`'s expression over the states of the forms `x` (one per state component),
  /// in affine arithmetic: an affine expression keeps the forms' correlations (up to rounding,
  /// bounded into the error term); a product, a quotient or a power bounds its non-affine part
  /// into the error term; any other function is an interval over the forms' ranges.
  AffineForm FormValue(const Residual& r, const std::vector<AffineForm>& x,
                       const std::vector<TightInterval>& env) const;

 private:
  int ModeIndex(const std::vector<int>& tuple);
  Expression Resolve(const Expression& e) const;
  std::vector<TightInterval> EnvironmentOf(const std::vector<TightInterval>& box,
                                           const std::vector<TightInterval>& env) const;

  System system_;
  int num_variables_ = 0;
  std::vector<int> component_slot_;  // state component -> system slot
  std::vector<int> input_slot_;      // input index -> system slot
  SlotMap slots_;
  std::vector<TightInterval> base_env_;
  std::vector<TightInterval> input_box_;
  std::vector<std::unique_ptr<CompiledMode>> modes_;
  std::map<std::vector<int>, int> mode_index_;
};

/// An enclosure of e over `env` (slots to intervals), tight where exact: + - * / and integer
/// powers with TightInterval, other functions with hybrid::Interval (one ulp outward).
TightInterval EvaluateTight(const Expression& e, const std::vector<TightInterval>& env);

}  // namespace hybrid::flowpipe_internal
