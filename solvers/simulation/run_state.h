#pragma once

// The state of one simulation run that the compiled expressions read, and the OdeSystem that
// CVODE calls back: the environment (one value per System slot: variables, inputs, parameters,
// discrete values), the current modes and their root functions.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/scenario.h"
#include "hybrid/simulation/simulator.h"
#include "solvers/simulation/compiled_model.h"
#include "solvers/simulation/cvode_integrator.h"

namespace hybrid {

/// One root function of the current modes: comparison `comparison` of the guard of transition
/// `index` of component `component`, or (`invariant`) of the invariant of that component's
/// current mode, watched in `direction` (+1 rising, -1 falling, 0 both; Simulator's header).
struct RootRef {
  bool invariant = false;
  int component = 0;
  /// Transition index (guard) or unused (invariant).
  int index = 0;
  /// Comparison index within the guard or invariant.
  int comparison = 0;
  int direction = 0;
};

/// The state of one run. The environment holds a value for every System slot: the parameters as
/// given, the continuous variables and linear inputs as last loaded (Load), step inputs at their
/// segment value (SetStepInputs) and the discrete values of the current modes (SetModes). The
/// root functions of the current modes (roots()) are, per component in System order: every
/// comparison of every outgoing guard (transitions in declaration order), crossing towards the
/// guard (`<`, `<=`: falling; `>`, `>=`: rising; `==`: both), then every invariant comparison but
/// `==`, crossing out of the invariant.
///
/// As an OdeSystem, Derivatives and Roots load (t, x) and evaluate the current modes' flows and
/// root functions. A model without continuous variables is integrated as one constant dummy
/// variable (CVODE needs at least one), so x and dx/dt have max(1, x_size()) entries.
class RunState final : public OdeSystem {
 public:
  /// `env`: one value per System slot with the run's parameters (CompiledModel::
  /// ParameterEnvironment); `signals`: the run's inputs (validated, one per driven input). Keeps
  /// references to `model` and `options`, which must outlive the state. SetModes must be called
  /// before anything that reads the modes.
  RunState(const CompiledModel& model, std::vector<double> env, std::vector<InputSignal> signals,
           const SimulationOptions& options);

  void Derivatives(double t, const double* x, double* dxdt) override;
  void Roots(double t, const double* x, double* g) override;

  /// Number of continuous variables.
  size_t x_size() const { return model_.variable_slots().size(); }

  /// Puts (t, x) into the environment; linear inputs follow t, step inputs stay at their segment
  /// value (set by SetStepInputs) so that a step at a stop time does not leak into the segment.
  void Load(double t, const double* x);
  /// Sets every step input to its value at `t` (the segment that starts there).
  void SetStepInputs(double t);
  /// Enters `modes` (one per component, each in range): their discrete values, flows and root
  /// functions, and whether their segments are exact.
  void SetModes(const std::vector<int>& modes);

  /// True when the current modes move the state on a straight line and every root function is
  /// affine along it, so that crossings are found exactly without a solver: every flow reads no
  /// continuous variable, and neither a flow nor a root function reads a linear input.
  bool exact() const { return exact_; }
  /// d g_i / dt along the straight line with constant rate `dxdt` (exact() must hold).
  double Slope(int i, const Eigen::VectorXd& dxdt) const;

  /// The comparison root function `r` watches (r one of roots()).
  const CompiledComparison& ComparisonOf(const RootRef& r) const;

  /// Whether the guard of transition `t` of component `component` holds at the environment, each
  /// comparison within event_tolerance; `closure`: strict comparisons taken as non-strict
  /// (ResidualHolds).
  bool GuardHolds(int component, int t, bool closure) const;
  /// The first comparison of component c's current invariant violated beyond event_tolerance, as
  /// text.
  std::optional<std::string> ViolatedInvariantOf(size_t c) const;
  /// The first comparison of the current modes' invariants violated beyond event_tolerance, as
  /// text.
  std::optional<std::string> ViolatedInvariant() const;

  /// How far from its boundary a located event may leave comparison `c` at the environment:
  /// event_tolerance + resolution_tolerance * (|lhs| + |rhs|).
  double ResolutionTolerance(const CompiledComparison& c) const;
  /// Root function i at the environment, if it is off its boundary by more than its resolution
  /// tolerance: (residual, tolerance). nullopt for a comparison that may jump.
  std::optional<std::pair<double, double>> OffBoundary(int i) const;

  /// Loads a recorded state (its modes' discrete values, its variables and the inputs at
  /// `input_time`, normally its own time) and returns the first invariant comparison it violates
  /// beyond the resolution tolerance (comparisons that may jump exempt), with its residual, or
  /// nullopt. `s` must fit the model (a mode in range per component, x_size() variables). Leaves
  /// the environment at that state and the current modes unchanged: for after the run.
  std::optional<std::pair<std::string, double>> OutsideInvariant(const StateSample& s,
                                                                 double input_time);

  const std::vector<int>& modes() const { return modes_; }
  const std::vector<RootRef>& roots() const { return roots_; }
  /// roots()[i].direction, for CvodeIntegrator::Restart.
  const std::vector<int>& directions() const { return directions_; }
  /// One value per System slot.
  std::vector<double>& env() { return env_; }
  const std::vector<CompiledComponent>& components() const { return model_.components(); }

 private:
  // Whether every slot of `slots` is steady within a segment (no linear input drives it).
  bool Steady(const std::vector<int>& slots) const;

  const CompiledModel& model_;
  std::vector<double> env_;
  std::vector<InputSignal> signals_;
  const SimulationOptions& options_;
  std::vector<int> modes_;
  std::vector<std::pair<int, const CompiledExpression*>> active_flows_;
  std::vector<RootRef> roots_;
  std::vector<const CompiledExpression*> root_residuals_;  // roots_[i]'s residual
  bool exact_ = false;
  std::vector<int> directions_;
};

}  // namespace hybrid
