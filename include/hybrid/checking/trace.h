#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/scenario.h"
#include "hybrid/automaton/system.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// A parameter declared with a range (`param p = v in [lo, hi];`): a verifier covers every
/// value in [lo, hi]; simulation uses the nominal value.
struct UncertainParameter {
  /// System name ("gob1", or "A.gob1" inside instance A).
  std::string name;
  double nominal = 0.0;
  double lo = 0.0;
  double hi = 0.0;
};

/// The uncertain parameters of `system`, one per System name, in component and declaration
/// order.
std::vector<UncertainParameter> UncertainParameters(const System& system);

/// A concrete run of a model that a checker found: which parameter values and initial values to
/// use and which inputs to apply. The simulator replays it (ReplayTrace); `run` and `state_index`
/// hold that replay.
struct Trace {
  /// Values for uncertain parameters (System names); others keep their nominal values.
  std::vector<std::pair<std::string, double>> parameters;
  /// Which `init` declaration a component starts from: (component index in the System,
  /// initial state index in declaration order). Components not listed start from their first.
  std::vector<std::pair<int, int>> initial_states;
  /// Initial values of continuous variables (System names) where the model's initial state is a
  /// box; others keep the model's. Each must lie in its component's chosen initial state.
  std::vector<std::pair<std::string, double>> initial_values;
  /// Horizon and input signals (System input slots). Checkers produce step signals: the input
  /// is piecewise constant.
  Scenario inputs;
  /// The lazy jumps of the run in time order, when the checker chose them (polyhedral
  /// reachability does): replay takes them at these times (SimulationOptions::lazy_schedule);
  /// empty: lazy jumps as the simulator chooses (at invariant boundaries).
  std::vector<ScheduledJump> schedule;
  /// The simulator's run of this trace.
  SimulationResult run;
  /// Index into run.samples of the first state at which the property fails (`always`, `never`)
  /// or holds (`reach`).
  int state_index = -1;
};

/// Replay settings: a property counts as failing at a recorded state only when it does so with
/// margin `tolerance` (the predicate is read with Predicate::Lenient, the one definition of
/// tolerance that the SMT encoding's counterexample search shares), so a replay confirms a
/// violation only when it is clear of rounding; a `reach` target counts as met when its
/// non-strict comparisons hold within `tolerance` and its strict ones beyond it (IsTarget).
struct ReplayOptions {
  double tolerance = 1e-6;
  /// Also record the state this often (fraction of the horizon); 0 records only the start,
  /// the events and the end.
  double sample_fraction = 1e-3;
};

/// Applies `trace`'s parameters and initial values to a copy of `system`, simulates its inputs
/// up to its horizon, and fills trace.run and trace.state_index with the first recorded state
/// (start, samples, both sides of every event, end) that violates `property` (for `always` and
/// `never`) or satisfies it (for `reach`). Returns whether there is one. States from the first
/// that lies outside its modes' invariants (by more than `tolerance` times 1 + the magnitudes of
/// a comparison's sides) on are not considered: a jump into such a state is no step of a run. The
/// horizon of a bounded property (`within T`) caps the states considered. Throws
/// std::invalid_argument for a trace naming unknown parameters, variables or initial states, inputs
/// out of bounds, or an initial value outside the chosen initial state's range (beyond 1e-9
/// relative; within it, the value is moved onto the range, in trace.initial_values too): a start
/// that no `init` of the model admits is never replayed.
bool ReplayTrace(const System& system, const Property& property, Trace& trace,
                 const ReplayOptions& options = {});

/// Evaluates `property`'s predicate at recorded state `sample` of a run of `simulator` (whose
/// system has the parameter values of the run): true when the state is a counterexample
/// (`always`/`never`: the predicate fails clearly, Predicate::Lenient with `tolerance`) or a
/// witness (`reach`: Predicate::Witnessed with `tolerance`: non-strict comparisons within it,
/// strict ones beyond it, so that no rounding error makes a witness of a strict target's
/// boundary).
bool IsTarget(const Simulator& simulator, const Property& property, const StateSample& sample,
              double tolerance);

}  // namespace hybrid
