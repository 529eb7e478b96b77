#pragma once

// The compiled form of one component of a System: what the simulator evaluates at every step
// (flows, guards, resets, invariants as CompiledExpressions over the System's slots) and what it
// needs to know about each comparison (linearity for exact segments, operations that may jump for
// the resolution check). Built once per Simulator (CompiledModel); read by every run.

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/compiled_expression.h"
#include "hybrid/automaton/system.h"

namespace hybrid {

/// Whether an expression can be followed exactly along a straight-line trajectory: its affine
/// coefficients on the continuous variables (parameters folded), or none when it is not affine in
/// them, and every System slot it reads (to reject inputs that vary within a segment).
struct Linearity {
  /// (index in x, coefficient) of g = sum coefficient * x[index] + constant; nullopt when the
  /// expression is not affine in the state.
  std::optional<std::vector<std::pair<int, double>>> terms;
  /// Every System slot the expression reads.
  std::vector<int> slots;
};

/// A guard or invariant comparison `lhs REL rhs` compiled over the System's slots.
struct CompiledComparison {
  /// lhs - rhs over System slots: the root function of the comparison.
  CompiledExpression residual;
  Relation relation;
  /// The comparison as written, for messages.
  std::string text;
  Linearity linearity;
  /// The two sides, for the scale of the resolution tolerance.
  CompiledExpression lhs;
  CompiledExpression rhs;
  /// The residual may jump (sign, tan, atan2, a division by a non-constant): exempt from the
  /// resolution check, since a located crossing of a jump is not on its boundary.
  bool may_jump = false;
};

/// A transition of a component, compiled.
struct CompiledTransition {
  /// Qualified by the instance ("A.t1"; the plain name for an unqualified component).
  std::string name;
  std::string label;
  /// Mode indices of the component.
  int source = 0;
  int target = 0;
  Urgency urgency = Urgency::kUrgent;
  /// A conjunction (empty: true).
  std::vector<CompiledComparison> guard;
  /// (index in x, value), all evaluated in the state before the jump.
  std::vector<std::pair<int, CompiledExpression>> resets;
};

/// A mode of a component, compiled.
struct CompiledMode {
  /// (index in x, right-hand side); a variable without a flow is constant.
  std::vector<std::pair<int, CompiledExpression>> flows;
  /// The flows read no continuous variable: the state moves on a straight line between events
  /// while the inputs they read (flow_slots) are constant.
  bool constant_rate = false;
  /// Every System slot a flow reads (repeated as often as read).
  std::vector<int> flow_slots;
  /// A conjunction (empty: true).
  std::vector<CompiledComparison> invariant;
  /// Indices of the transitions leaving this mode, in declaration order.
  std::vector<int> outgoing;
  /// (System slot, value) of the discrete variables in this mode.
  std::vector<std::pair<int, double>> discrete;
};

/// One component of a System, compiled: its modes and transitions (indices as in its automaton),
/// its synchronisation alphabet and its first initial state.
struct CompiledComponent {
  /// Empty for a component whose names are not qualified.
  std::string instance;
  /// Unqualified, by mode index.
  std::vector<std::string> mode_names;
  std::vector<CompiledMode> modes;
  std::vector<CompiledTransition> transitions;
  /// The labels this component synchronises on (System::Alphabet); set by CompiledModel.
  std::set<std::string> alphabet;
  int initial_mode = 0;
  /// (index in x, value): interval initial values at their midpoint.
  std::vector<std::pair<int, double>> initial_values;
};

/// Compiles `component` of a System whose symbol table is `symbols`: its flows, guards, resets and
/// invariants as expressions over the System's slots (through component.global_slot), with the
/// linearity of every comparison (its affine terms with the parameters of `parameter_env` folded)
/// and whether it may jump, each mode's outgoing transitions, and the first initial state
/// (interval values at their midpoint, evaluated with the automaton's own parameters). `x_index`:
/// System slot -> index in x (-1 for a slot that is not a continuous variable); `parameter_env`:
/// the System's slots with the parameters filled. Sets `fixed[slot]` (System slots) for every
/// parameter the compiled component holds as a constant: one that an initial value reads, or one
/// that a comparison reads when it is affine in x only with that parameter folded (a parameter
/// scaling a variable). The alphabet is left empty. Throws std::invalid_argument if the component
/// has no initial state.
CompiledComponent CompileComponent(const SymbolTable& symbols, const Component& component,
                                   const std::vector<int>& x_index,
                                   const std::vector<double>& parameter_env,
                                   std::vector<char>& fixed);

/// Whether `e` contains an operation whose value may jump as the state moves continuously: sign,
/// tan, atan2, or a division by something that reads a slot for which `varies` holds. Shared
/// subexpressions are visited once.
bool MayJump(const Expression& e, const std::function<bool(int)>& varies);

}  // namespace hybrid
