#pragma once

// What a Simulator builds once from a System and every run reads: the continuous variables (the
// state vector x), every component compiled (CompileComponent), the parameter values of the model
// and which parameters a run may set.

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/system.h"
#include "solvers/simulation/compiled_component.h"

namespace hybrid {

/// The compiled form of a System: x holds the System's continuous variables in slot order;
/// components are compiled in the System's order, each with its synchronisation alphabet
/// (System::Alphabet). Immutable after construction: runs only read it.
class CompiledModel {
 public:
  /// Compiles every component of `system`. Keeps a reference to `system`, which must outlive the
  /// model. Throws std::invalid_argument if some component has no initial state.
  explicit CompiledModel(const System& system);
  CompiledModel(const CompiledModel&) = delete;
  CompiledModel& operator=(const CompiledModel&) = delete;

  const System& system() const { return system_; }
  /// Names of the continuous variables, the order of x.
  const std::vector<std::string>& variable_names() const { return variable_names_; }
  /// Index in x -> System slot.
  const std::vector<int>& variable_slots() const { return variable_slots_; }
  const std::vector<CompiledComponent>& components() const { return components_; }

  /// The values of every System slot's parameter with `parameters` (System names) set in place
  /// of the model's values, the parameters defined from them following (as
  /// Automaton::ParameterEnvironment evaluates them), other slots 0. Throws
  /// std::invalid_argument, naming the parameter, for a name that is not a parameter, a value
  /// that is not finite, a parameter the compiled model holds as a constant (one an initial value
  /// reads, or one scaling a variable in a guard or invariant, or one such a parameter is defined
  /// from), or a setting the automaton refuses (a parameter taken outside its declared range or
  /// made non-finite).
  std::vector<double> ParameterEnvironment(
      std::span<const std::pair<std::string, double>> parameters) const;

  /// Name of mode `mode` of component `component`, qualified by the instance ("A.on"). Throws
  /// std::out_of_range for an index out of range.
  std::string ModeName(int component, int mode) const;
  /// ModeName of each component's mode in `modes` (one per component, from the first), joined
  /// with "|".
  std::string ModeLabel(std::span<const int> modes) const;

 private:
  const System& system_;
  std::vector<std::string> variable_names_;
  std::vector<int> variable_slots_;
  std::vector<CompiledComponent> components_;
  // System slots, parameters filled with the model's values.
  std::vector<double> parameter_env_;
  // System slot -> the parameter there cannot be set per run (SimulationOptions::parameters).
  std::vector<char> fixed_;
};

}  // namespace hybrid
