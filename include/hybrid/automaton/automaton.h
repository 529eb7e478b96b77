#pragma once

#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/id.h"
#include "hybrid/automaton/mode.h"
#include "hybrid/automaton/property.h"
#include "hybrid/automaton/scenario.h"
#include "hybrid/automaton/symbol_table.h"
#include "hybrid/automaton/transition.h"

namespace hybrid {

/// A closed interval given by two expressions over parameters (e.g. `[-1, 1]`, `[0, theta1_max]`).
struct Range {
  Expression lo;
  Expression hi;
  friend bool operator==(const Range&, const Range&) = default;
};

/// Initial value of one continuous variable: a point (`x = e`) or a box side (`x in [lo, hi]`).
struct InitialValue {
  int slot = -1;
  Range range;  ///< lo == hi (the same expression) for a point
  bool is_point = true;
  friend bool operator==(const InitialValue&, const InitialValue&) = default;
};

/// An initial mode with initial values for every continuous variable, sorted by slot.
struct InitialState {
  ModeId mode;
  std::vector<InitialValue> values;
  friend bool operator==(const InitialState&, const InitialState&) = default;
};

/// Declared domain of a continuous variable.
struct VariableInfo {
  int slot = -1;
  std::optional<Range> domain;
  friend bool operator==(const VariableInfo&, const VariableInfo&) = default;
};

/// Bounds of an input.
struct InputInfo {
  int slot = -1;
  Range bounds;
  friend bool operator==(const InputInfo&, const InputInfo&) = default;
};

/// A hybrid automaton: symbols, modes, transitions, initial states, properties and a default
/// scenario. The model IR every solver consumes.
///
/// Built incrementally; each Add* validates its argument against what is already declared and
/// throws std::invalid_argument naming the method and the offending name (duplicate names,
/// expressions reading undeclared slots, flows of non-variables, unknown modes, parameters that
/// read anything but earlier parameters, discrete valuations that are incomplete, ...). So a model
/// is valid by construction, and names must be declared before use.
///
/// Environment layout: every expression of the automaton reads a flat array indexed by slot
/// (SymbolTable); ParameterEnvironment() gives one with the parameters filled in.
class Automaton {
 public:
  /// `name` must be non-empty.
  explicit Automaton(std::string name);

  const std::string& name() const { return name_; }
  const SymbolTable& symbols() const { return symbols_; }

  int AddVariable(std::string name, std::string unit = "", std::optional<Range> domain = {});
  int AddDiscreteVariable(std::string name);
  int AddInput(std::string name, Range bounds, std::string unit = "");
  /// Declares parameter `name` with nominal value `value` (what simulation uses) and, optionally,
  /// the `range` of values a verifier must cover (`param k = 2 in [1, 3];`). `value` and the range
  /// bounds may read only parameters declared earlier and must evaluate to finite numbers, with
  /// lo <= value <= hi. Returns the slot. Throws std::invalid_argument (a message naming the
  /// parameter) otherwise, or on a duplicate name.
  int AddParameter(std::string name, Expression value, std::string unit = "",
                   std::optional<Range> range = {});
  /// Replaces the defining expression of parameter `name` by the constant `value`; parameters
  /// defined from it follow (they are evaluated in declaration order); declared ranges are kept.
  /// Throws std::invalid_argument (a message naming the parameter) if `name` is not a parameter,
  /// `value` is not finite or outside the declared range of `name`, or a parameter defined from
  /// it (or a range bound) becomes non-finite or leaves its range; the old value is then kept.
  void SetParameter(std::string_view name, double value);
  /// Flows must be sorted by slot and name continuous variables; every discrete variable must
  /// get a value; the mode name must be new.
  ModeId AddMode(Mode mode);
  /// Source and target must exist; resets must assign continuous variables; the name must be new.
  TransitionId AddTransition(Transition transition);
  /// Adds `label` to the automaton's alphabet without a transition: a label it synchronises on
  /// but never takes, so that, composed, it blocks the transitions of other components on that
  /// label (SpaceEx's reading of a declared, unused label). Labels of transitions are in the
  /// alphabet anyway; declaring one of them again, or twice, changes nothing. Throws
  /// std::invalid_argument ("empty label") for an empty label.
  void DeclareLabel(std::string label);
  /// The labels declared with DeclareLabel, sorted, without those of transitions added later.
  const std::set<std::string>& declared_labels() const { return declared_labels_; }
  /// Replaces the guard of transition `id` (a model transformation, e.g. contact guards computed
  /// from geometry). Throws std::invalid_argument for an unknown transition or a guard reading
  /// undeclared slots.
  void SetGuard(TransitionId id, Constraint guard);
  /// Sets the initial value of continuous variable `slot` in every initial state (replacing it
  /// where given): for a variable added after the initial states. Throws std::invalid_argument
  /// if `slot` is not a continuous variable or `value` is empty or reads anything but
  /// parameters.
  void SetInitialValue(int slot, const InitialValue& value);
  /// Every continuous variable must get exactly one value; bounds read parameters only.
  void AddInitialState(InitialState state);
  /// Keeps initial state `index` (declaration order) as the only one: the start a replayed
  /// trace names. Throws std::invalid_argument if there is no such initial state.
  void KeepInitialState(int index);
  /// Comparisons may read variables, discrete variables and parameters, not inputs; `in` atoms
  /// must name modes of this automaton; the property name must be new.
  void AddProperty(Property property);
  /// Inputs must exist, each at most once; points strictly increasing in time; until > 0.
  void SetScenario(Scenario scenario);

  int num_modes() const { return static_cast<int>(modes_.size()); }
  int num_transitions() const { return static_cast<int>(transitions_.size()); }
  const Mode& mode(ModeId id) const { return modes_.at(id.value()); }
  const Transition& transition(TransitionId id) const { return transitions_.at(id.value()); }
  std::span<const Mode> modes() const { return modes_; }
  std::span<const Transition> transitions() const { return transitions_; }
  std::optional<ModeId> FindMode(std::string_view name) const;
  std::span<const VariableInfo> variables() const { return variables_; }
  std::span<const InputInfo> inputs() const { return inputs_; }
  /// Slots of the parameters in declaration order, with their defining expressions.
  std::span<const std::pair<int, Expression>> parameters() const { return parameters_; }
  /// The declared range of the parameter at `slot` (expressions over earlier parameters, to be
  /// evaluated in ParameterEnvironment()), or nullopt if it has none or `slot` is not a
  /// parameter. Never throws.
  std::optional<Range> ParameterRange(int slot) const;
  std::span<const int> discrete_variables() const { return discrete_; }
  std::span<const InitialState> initial_states() const { return initial_states_; }
  std::span<const Property> properties() const { return properties_; }
  const std::optional<Scenario>& scenario() const { return scenario_; }

  /// An environment (one entry per slot) with every parameter evaluated in declaration order and
  /// every other slot 0.
  std::vector<double> ParameterEnvironment() const;
  /// ParameterEnvironment() with the parameters at the slots of `values` taking those values in
  /// place of their definitions (parameters defined from them follow), checked as SetParameter
  /// checks one value: throws std::invalid_argument, the message beginning with `setting`
  /// ("setting 'k' to 2"), if a parameter or a range bound becomes non-finite, a range empty or a
  /// parameter leaves its range. Preconditions: every slot of `values` is a parameter's.
  std::vector<double> ParameterEnvironment(std::span<const std::pair<int, double>> values,
                                           const std::string& setting) const;
  /// The value of a constant expression over parameters (throws std::invalid_argument, naming
  /// `context`, if it reads a non-parameter or is not finite).
  double EvaluateConstant(const Expression& e, std::string_view context) const;

  friend bool operator==(const Automaton&, const Automaton&) = default;

 private:
  void CheckSlots(const Expression& e, std::string_view context, bool allow_inputs,
                  bool allow_state) const;

  std::string name_;
  SymbolTable symbols_;
  std::vector<VariableInfo> variables_;
  std::vector<int> discrete_;
  std::vector<InputInfo> inputs_;
  std::vector<std::pair<int, Expression>> parameters_;
  // The declared range of each parameter, parallel to parameters_.
  std::vector<std::optional<Range>> parameter_ranges_;
  std::vector<Mode> modes_;
  std::vector<Transition> transitions_;
  std::set<std::string> declared_labels_;
  // Name -> index look-ups (derived from modes_ and transitions_).
  std::unordered_map<std::string, int> mode_index_;
  std::unordered_map<std::string, int> transition_index_;
  std::vector<InitialState> initial_states_;
  std::vector<Property> properties_;
  std::optional<Scenario> scenario_;
};

/// A new automaton named as `a` that declares `a`'s symbols in slot order (continuous variables
/// with their units and domains, discrete variables, inputs with their bounds, parameters with
/// their defining expressions and ranges) and nothing else: every expression of `a` reads the
/// same slots in it. The start of a model transformation that rebuilds modes or transitions;
/// symbols added to it afterwards take the slots after `a`'s.
Automaton CopySymbols(const Automaton& a);

}  // namespace hybrid
