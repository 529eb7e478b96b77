#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/system.h"
#include "solvers/reachability/convex_polyhedron.h"
#include "solvers/reachability/variable_liveness.h"

namespace hybrid {

/// A location's jump in the linear view: where it leads, when it may fire, what it resets.
struct LinearEdge {
  /// The component modes after the jump.
  std::vector<int> target;
  /// The joint guard (conjunction) over the dimensions.
  std::vector<LinearConstraint> guard;
  /// The guard as a polyhedron (made once, intersected many times).
  ConvexPolyhedron guard_set = ConvexPolyhedron::Universe(0);
  /// x_d := f_d(x), simultaneous.
  std::vector<std::pair<int, AffineMap>> resets;
  /// The joint transition's name (System::Step) and urgency.
  std::string name;
  Urgency urgency = Urgency::kUrgent;
  /// The component transitions taken (component index, transition index).
  std::vector<std::pair<int, TransitionId>> participants;
};

/// A location (tuple of component modes) of the linear view.
struct LinearLocation {
  std::vector<int> tuple;
  /// Its invariant (conjunction).
  std::vector<LinearConstraint> invariant;
  /// What time elapse must also keep: the invariant plus, for each urgent edge whose guard is one
  /// inequality g(x) REL 0, the closure of its complement (time cannot pass a point where an
  /// urgent guard holds, so it stops on the boundary). Sound: every real run satisfies it.
  std::vector<LinearConstraint> elapse_invariant;
  /// `invariant` and `elapse_invariant` as polyhedra.
  ConvexPolyhedron invariant_set = ConvexPolyhedron::Universe(0);
  ConvexPolyhedron elapse_set = ConvexPolyhedron::Universe(0);
  /// The derivatives flows allow (over all dimensions; parameters and untouched variables 0).
  ConvexPolyhedron rates = ConvexPolyhedron::Universe(0);
  /// Whether `rates` is exact: false when a rate reading an uncertain parameter was replaced by
  /// an interval over the parameter's range (an over-approximation).
  bool exact_rates = true;
  /// Each flow in terms of the inputs: for variable dimension d, rate_d = c_d + sum B_dk u_k
  /// over the input slots k of `inputs` (exact rates only).
  std::vector<AffineMap> input_rates;
  std::vector<LinearEdge> edges;
  /// The qualified component modes joined with ", " (for messages).
  std::string name;
  /// The discrete variables' values in this location (System slots).
  std::vector<std::pair<int, int>> discrete_values;
  /// Variable dimensions dead here (VariableLiveness): nothing reads them before a reset writes
  /// them, so exploration may forget their values on entry.
  std::vector<int> dead;
};

/// The linear hybrid automaton behind a System, built location by location as exploration
/// reaches them (no explicit product).
///
/// Dimensions: the System's continuous variables in slot order, then its uncertain parameters
/// (rate 0, constant along runs), then optionally a clock (rate 1, starting at 0) for bounded
/// properties. Parameters without a range and discrete variables (whose values each mode fixes)
/// are replaced by their values.
///
/// The class: every flow is constant or affine in bounded inputs (rectangular rates are such
/// flows), or reads uncertain parameters (then over-approximated by an interval); every
/// invariant, guard, reset and property comparison is affine in the variables and uncertain
/// parameters. Anything else makes At (or the constructor, for initial states) throw
/// NotLinearError naming what.
class LinearHybridSystem {
 public:
  /// Thrown when the system is not in the class; the message names the mode or transition.
  struct NotLinearError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
  };

  /// The view of `system`; with `clock`, a clock dimension is added. `observed`: the properties
  /// to be checked (the variables they read are live in every location).
  LinearHybridSystem(const System& system, bool clock,
                     const std::vector<const Property*>& observed);
  /// The same with the System slots the checked properties read given directly (`read`: live in
  /// every location).
  LinearHybridSystem(const System& system, bool clock, const std::vector<int>& read);
  /// The System slots `properties` read (their comparisons' symbols).
  static std::vector<int> ReadSlots(const std::vector<const Property*>& properties);
  ~LinearHybridSystem();

  const System& system() const { return system_; }
  int dims() const { return static_cast<int>(names_.size()); }
  int num_variables() const { return num_variables_; }
  /// Name of each dimension (System names; the clock is "time").
  const std::vector<std::string>& names() const { return names_; }
  /// System slot of each variable dimension, then of each parameter dimension.
  const std::vector<int>& slots() const { return slots_; }
  /// Input slots (the k of LinearLocation::input_rates) and their bounds.
  const std::vector<int>& inputs() const { return inputs_; }
  const std::vector<std::pair<double, double>>& input_bounds() const { return input_bounds_; }
  /// Dimension of the clock, or -1.
  int clock() const { return clock_; }

  /// One initial location with its initial set (initial values and parameter ranges, within
  /// the invariant) and, per component, which `init` declaration it comes from.
  struct Initial {
    std::vector<int> tuple;
    std::vector<int> init_index;
    ConvexPolyhedron set;
  };
  std::vector<Initial> InitialSets() const;

  /// The location `tuple`, computed on first use.
  const LinearLocation& At(const std::vector<int>& tuple);
  /// Number of locations computed so far.
  int num_locations() const { return static_cast<int>(locations_.size()); }

  /// The states of `location` where `predicate` holds (negated: fails), as a union of
  /// conjunctions (empty: none); throws NotLinearError if a comparison is not affine or the
  /// union would have more than 256 parts.
  std::vector<std::vector<LinearConstraint>> States(const Predicate& predicate, bool negated,
                                                    const LinearLocation& location) const;

  /// The polyhedron of a conjunction over the dimensions.
  ConvexPolyhedron Polyhedron(const std::vector<LinearConstraint>& conjunction) const;

 private:
  struct Forms;
  LinearLocation Build(const std::vector<int>& tuple) const;
  // Intersects `set` with the initial value `iv` of component `c` for dimension d.
  void ConstrainInitial(const Component& c, const InitialValue& iv, int d,
                        ConvexPolyhedron& set) const;

  const System& system_;
  int num_variables_ = 0;
  int clock_ = -1;
  std::vector<std::string> names_;
  std::vector<int> slots_;
  std::vector<int> inputs_;
  std::vector<std::pair<double, double>> input_bounds_;
  std::unique_ptr<Forms> forms_;
  std::unique_ptr<VariableLiveness> liveness_;
  std::map<std::vector<int>, LinearLocation> locations_;
};

}  // namespace hybrid
