#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/scenario.h"
#include "hybrid/automaton/system.h"

namespace hybrid {

class CompiledModel;

/// A jump taken at a given time: one transition per participating component, (component index
/// in the System, transition index in its automaton), and a name for messages.
struct ScheduledJump {
  double time = 0.0;
  std::string name;
  std::vector<std::pair<int, int>> transitions;
  friend bool operator==(const ScheduledJump&, const ScheduledJump&) = default;
};

struct StateSample;

/// Settings of one simulation run. Defaults suit models whose time scale is between 1e-3 and
/// 1e4 (seconds, or any unit). Run throws std::invalid_argument for a setting out of its range.
///
/// Bounds. Every run ends after a bounded amount of work and memory, each bound a count (never a
/// time, so that outcomes do not depend on the machine's load): at most `max_steps` passes of the
/// integration loop (kStepLimit), `max_events` events in all (kEventLimit) and
/// `max_event_iterations` at one instant (kZeno), at most CvodeIntegrator::Options::max_steps
/// solver steps towards one stop time (kSolverFailure), and at most `max_samples` samples
/// recorded at sample times (refused before the run). So a run records at most
/// max_samples + 2 max_events + 2 states; with the defaults its result stays below about 250 MB
/// for a model of a few variables (docs/simulation.md, "Bounds").
struct SimulationOptions {
  /// Horizon; nullopt uses the model's scenario (Run throws if there is none).
  std::optional<double> until;
  /// > 0: also record the state every `sample_step` (from the start); 0: only the start, the end
  /// and both sides of every event. Finite and >= 0.
  double sample_step = 0.0;
  /// Further times at which to record the state (StateSample::Kind::kSample), e.g. the instants
  /// of measured samples. Non-decreasing, finite, within [0, until]; a repeated time is recorded
  /// once per occurrence, so the result has one sample per entry (a time at which an event
  /// happens records the state after the jump; a time 0 records the start). Run throws
  /// std::invalid_argument otherwise.
  std::vector<double> sample_times;
  double relative_tolerance = 1e-10;
  double absolute_tolerance = 1e-12;
  /// A residual within this of 0 counts as on the boundary (non-strict guards hold, invariants
  /// are not violated).
  double event_tolerance = 1e-9;
  /// Resolution check. A located event (a root function that crossed) must leave its comparison
  /// within event_tolerance + resolution_tolerance * (|lhs| + |rhs|) of its boundary, and every
  /// state a completed run records must satisfy its modes' invariants within the same tolerance;
  /// otherwise the run ends as kUnresolved (time, rounded to doubles, no longer resolves the
  /// dynamics: a horizon so far that one unit of time resolution moves the state past the
  /// tolerance). Comparisons that may jump (sign, tan, atan2, a division by a non-constant) are
  /// exempt.
  double resolution_tolerance = 1e-6;
  /// Interior points of every integration step at which the root functions are also evaluated on
  /// the step's interpolating polynomial, to find a guard that crosses twice inside one step (the
  /// integrator looks only at step ends). 0 disables the check. At most 1000.
  int dense_checks = 4;
  /// Samples inside a solver step (listed and uniform ones that fall strictly inside it) are
  /// recorded on the step's interpolating polynomial (the integrator's dense output, accurate to
  /// about the tolerances) instead of ending a step at each one: far fewer steps when the samples
  /// are denser than the dynamics need, states within the tolerances of those the default records.
  /// Samples on exact (constant-rate) segments, at events and at input breakpoints are recorded
  /// as without it.
  bool interpolate_samples = false;
  /// Solve the integrator's implicit (Adams-Moulton) steps by fixed-point iteration instead of
  /// Newton's method with a finite-difference Jacobian: cheaper steps for a non-stiff flow (no
  /// Jacobian, no linear solves); on a stiff one the steps shrink until the iteration converges,
  /// and the run may end as kSolverFailure where Newton's would not. The same solution within the
  /// tolerances.
  bool fixed_point_iteration = false;
  /// Largest internal step (0: unlimited).
  double max_step = 0.0;
  /// Jumps allowed at one instant before the run stops as Zeno (event iteration bound).
  int max_event_iterations = 100;
  /// Zeno detection over the last `zeno_events` events (time scale s = max(1, |t|)):
  /// (a) chattering: they all fall inside a window shorter than `zeno_window` * s;
  /// (b) accumulation: their transitions repeat a cycle (the sequence of names is periodic with
  ///     a period of at most zeno_events / 2), their intervals shrink geometrically (every ratio
  ///     of consecutive intervals within 1% of their mean r < 1) and the predicted remaining
  ///     time to the accumulation point, d_last * r / (1 - r), is below `zeno_horizon` * s.
  int zeno_events = 10;
  double zeno_window = 1e-6;
  double zeno_horizon = 1e-4;
  /// Total number of events allowed (kEventLimit beyond). Each event records two states.
  long max_events = 200000;
  /// Most states recorded at sample times: the uniform samples (about until / sample_step) plus
  /// `sample_times`. A run that would record more is refused before it starts.
  long max_samples = 1000000;
  /// Most passes of the integration loop in one run: integrator steps, exact (constant-rate)
  /// segments and steps over short gaps, each a pass (kStepLimit beyond).
  long max_steps = 10000000;
  /// Parameter values for this run in place of the model's, by System name ("gob1", "A.gob1"),
  /// without compiling the model again: parameters defined from one follow it (`m1 =
  /// theta1_max / 140`), as with Automaton::SetParameter, and the run equals one of the model
  /// with those values set. Run throws std::invalid_argument, naming the parameter, for a name
  /// that is not a parameter, a value that is not finite, a parameter (or one defined from it)
  /// made non-finite or taken outside its declared range, and a parameter the compiled model
  /// holds as a constant: one that an initial value reads, or that scales a continuous variable
  /// in a guard or invariant (set those in the model).
  std::vector<std::pair<std::string, double>> parameters;
  /// Lazy jumps to take at given times (a replayed trace's schedule), in time order: at each
  /// entry's time (a hard stop of the integration, like an input breakpoint) its transitions are
  /// taken together if every one leaves its component's current mode and its guard holds (in
  /// its closure, within event_tolerance); otherwise the entry is skipped. Urgent transitions and
  /// lazy ones at invariant boundaries fire as usual. Times must be finite, non-decreasing and
  /// in [0, until].
  std::vector<ScheduledJump> lazy_schedule;
  /// A start state in place of the model's initial one: the mode of each component and the
  /// continuous variables in the order of Simulator::variable_names() (a recorded
  /// StateSample's `modes` and `x`); empty `modes`: the model's. The run starts from it at time 0,
  /// so a model whose flows, guards and resets do not read the time continues a run that reached
  /// this state (with the inputs shifted by that run's time): a stateful emulator steps a run
  /// this way. Run throws std::invalid_argument for modes or variables that do not fit the model,
  /// a value that is not finite, or a state outside its modes' invariants.
  std::vector<int> start_modes;
  Eigen::VectorXd start_x;
  /// Called with each state recorded at a sample time (StateSample::Kind::kSample), in time
  /// order, with its index among them (0, 1, ...; a listed time 0 included). Returning false ends
  /// the run at that instant with status kStopped: the states recorded up to there are those a
  /// run to the horizon records (other samples due at the same instant are recorded too, without
  /// a further call), then the end state. For a caller that looks for a condition on the samples
  /// and needs nothing after it (as a Drake simulator's monitor ends a simulation). Empty: none.
  std::function<bool(size_t index, const StateSample& sample)> monitor;
};

/// Throws std::invalid_argument, with a message for the user, if the horizon `until` (the one the
/// run will use) is not positive and finite, if a setting of `options` is out of its range, or if
/// the run would record more than options.max_samples samples at sample times; the messages speak
/// of the settings in the words of this API (the horizon `until`, the sample step `sample_step`),
/// never of a command line's options. Simulator::Run calls it; a command line may call it first to
/// tell a bad option from a bad model.
void ValidateSimulationOptions(const SimulationOptions& options, double until);

/// How a run ended. Only kCompleted reaches the horizon, and a kCompleted run has every recorded
/// state inside its modes' invariants (within the resolution tolerance) and every event located.
enum class SimulationStatus {
  kCompleted,
  /// Events accumulate (or iterate at one instant): see SimulationResult::zeno.
  kZeno,
  /// The state reached a mode invariant's boundary, moving out, with no transition to take.
  kInvariantViolated,
  /// The integrator failed (message quotes what it said), or its steps collapsed (more than
  /// CvodeIntegrator::Options::max_steps steps towards one stop time), or the run stopped making
  /// progress (many passes at one instant without a jump: "no progress at t = ..."); see message.
  kSolverFailure,
  /// More than SimulationOptions::max_events events.
  kEventLimit,
  /// More than SimulationOptions::max_steps passes of the integration loop.
  kStepLimit,
  /// Time, rounded to doubles, no longer resolves the run: a located event is off its boundary,
  /// or a recorded state lies outside its mode's invariant, by more than the resolution tolerance
  /// (SimulationOptions::resolution_tolerance). No recorded state after the message's time is
  /// trustworthy.
  kUnresolved,
  /// SimulationOptions::monitor ended the run at a sample it was given.
  kStopped,
};

/// "completed", "zeno", "invariant_violated", "solver_failure", "event_limit", "step_limit",
/// "unresolved", "stopped".
std::string_view StatusName(SimulationStatus status);

/// One recorded state.
struct StateSample {
  enum class Kind { kStart, kSample, kBeforeEvent, kAfterEvent, kEnd };
  double time = 0.0;
  Kind kind = Kind::kSample;
  /// Mode index of each component.
  std::vector<int> modes;
  /// Continuous variables, in the order of Simulator::variable_names().
  Eigen::VectorXd x;
};

/// One discrete jump (several transitions when synchronised).
struct EventRecord {
  enum class Cause {
    kCrossing,   ///< a guard comparison crossed zero (an urgent transition)
    kInvariant,  ///< an invariant was about to be violated (a lazy transition)
    kEnabled,    ///< the guard already held on entering the mode or when an input jumped
    kScheduled,  ///< a lazy jump at a time SimulationOptions::lazy_schedule gives
  };
  double time = 0.0;
  Cause cause = Cause::kCrossing;
  /// Qualified transition names ("A.t1" for instance A), one per participating component.
  std::vector<std::string> transitions;
  std::string label;
  std::vector<int> modes_before;
  std::vector<int> modes_after;
  Eigen::VectorXd before;
  Eigen::VectorXd after;
};

/// Why and where a run stopped as Zeno.
struct ZenoReport {
  /// Estimated accumulation time: for geometrically shrinking intervals with ratio
  /// r = (d_last / d_first)^(1 / (k - 2)) over the last k events, t_last + d_last * r / (1 - r);
  /// otherwise the last event time.
  double accumulation_time = 0.0;
  /// The repeating cycle of transitions among the last events (qualified names, in order).
  std::vector<std::string> cycle;
};

struct SimulationResult {
  SimulationStatus status = SimulationStatus::kCompleted;
  /// Human-readable detail for every status but kCompleted.
  std::string message;
  std::vector<StateSample> samples;
  std::vector<EventRecord> events;
  std::optional<ZenoReport> zeno;
  /// The integrator's internal steps (none for exact constant-rate segments).
  long steps = 0;
};

/// Simulates a System with exact event location on a variable-step integrator with root finding
/// (the library's private wrapper of a BDF/Adams solver; called "the integrator" below).
///
/// The state is one mode per component plus the System's continuous variables. Between events the
/// flows of the current modes are integrated (a variable without a flow is constant). Every
/// comparison of every outgoing guard is a root function of the integrator with its crossing
/// direction
/// (`<`, `<=`: falling; `>`, `>=`: rising; `==`: both), and so is every invariant comparison
/// (in the direction that leaves the invariant). At a root:
/// - an urgent transition fires when its guard holds in its closure (strict comparisons taken as
///   non-strict, each within event_tolerance) and one of its comparisons crossed or it holds
///   strictly;
/// - at an invariant boundary, lazy transitions whose guards hold may fire too; if none can, the
///   run stops with kInvariantViolated.
/// A root function that starts exactly on its boundary (the integrator does not report roots at its
/// initial point), or an invariant comparison already past its boundary by at most event_tolerance,
/// is watched at the end of each step: once it moves on in its direction, that is a crossing there
/// (so a strict guard `x > 0` entered at x = 0 fires as soon as x becomes positive, and an
/// invariant left right after a jump onto its boundary is reported).
/// Priority among enabled transitions: urgent before lazy, then component order, then declaration
/// order. A labelled transition of a composed system fires only together with one enabled
/// transition of the same label in every other component that uses the label (lowest declaration
/// order first); resets of all participants are evaluated in the state before the jump.
/// After a jump the new modes' urgent guards are checked (strictly): if one holds it fires at the
/// same instant (event iteration, at most max_event_iterations times). What the other components
/// reached at that instant stays in force during the iteration: an urgent transition whose guard
/// crossed there is still taken (in its closure), a lazy one at its component's invariant boundary
/// too; a component left at its invariant boundary with no transition taken is an invariant
/// violation. The same check runs when a step input jumps. Input breakpoints and sample times are
/// integration stop times (also when an event falls exactly on one), and the integrator is
/// restarted (reinitialised) after every jump and input jump, and after a root at which some root
/// function is exactly 0.
///
/// Exact segments: while every flow of the current modes reads no continuous variable and no
/// linearly interpolated input (a constant rate f between input breakpoints), and every root
/// function is affine in the state (parameters folded), the state moves on the line
/// x(t) = x0 + f (t - t0) and each root function is g0 + s (t - t0) with s = grad g . f: the
/// first crossing in its direction is t0 - g0 / s, computed without the integrator (no solver
/// steps, no integration error). The event rules above apply unchanged; a root function that starts
/// on its boundary and moves on sends that segment to the solver path, and an invariant boundary
/// reached exactly at an input breakpoint is decided by the next segment (the input changes there).
/// The state at a crossing is rounded, so a root function may be left a hair before its boundary
/// and its next crossing time round to the current time: a root function reported at an instant
/// at which nothing fired is not reported again at that instant (until a jump or an input jump
/// there).
///
/// Rounding guards. A stop time within about 100 ulps of the time at which the integrator would be
/// restarted (a jump one ulp before a sample time) is reached on the tangent instead: the
/// integrator cannot start a step that short, and locates roots only to about that precision
/// itself; root functions that cross on it cross at the stop time. The main loop never spins: more
/// than a hundred passes at one instant without a jump (integrator steps that continue without a
/// restart aside, which its max_steps bounds) end the run with kSolverFailure. The integrator never
/// prints.
///
/// Resolution. The integrator sizes its first step after every restart near the current time
/// (InitialStepTarget), never by the horizon. At every event, each root function that crossed
/// must lie within the resolution tolerance of its boundary at the state reached (see
/// SimulationOptions::resolution_tolerance); otherwise the run ends as kUnresolved at the start of
/// that pass. After the run, every recorded state is checked against its modes' invariants
/// (FirstStateOutsideInvariant, with the exemptions stated there, and the final instant of a
/// kInvariantViolated run); the first state outside ends the run as kUnresolved at that state:
/// the states and events from its time on are dropped and the last state kept is repeated as the
/// end. So whatever the status, the recorded states can be trusted.
///
/// Input jumps. A step input that jumps so that the state lies outside an invariant (beyond
/// event_tolerance) has reached that invariant's boundary at that instant: lazy transitions whose
/// guards hold may fire; if none does, the run stops with kInvariantViolated.
class Simulator {
 public:
  /// Compiles every flow, guard, reset and invariant of `system`. Keeps a reference to `system`,
  /// which must outlive the Simulator (and any Simulator it is moved into). Throws
  /// std::invalid_argument if some component has no initial state.
  explicit Simulator(const System& system);
  ~Simulator();
  Simulator(Simulator&&) noexcept;

  /// Runs from the first initial state of each component (interval initial values start at
  /// their midpoint). Inputs: `signals` (System input slots) override the scenario's signals;
  /// inputs with neither are 0. Throws std::invalid_argument, with a message for the user, for
  /// misuse: a non-positive or non-finite horizon, no horizon and no scenario, an option out of
  /// its range, more samples than SimulationOptions::max_samples, a signal for a non-input, a
  /// signal value outside the input's bounds, non-finite signal points, an initial state that
  /// violates its mode's invariant or is not finite. Run-time outcomes (Zeno, invariant
  /// violation, solver failure, limits, lost resolution) are statuses in the result.
  SimulationResult Run(const SimulationOptions& options,
                       std::span<const InputSignal> signals = {}) const;

  /// The general guard of every run: the first state of `result.samples` that lies outside its
  /// modes' invariants by more than the resolution tolerance (SimulationOptions), as a message
  /// naming its time, the invariant and the mode; nullopt if none. The inputs are those of a run
  /// with `signals`. A state that a jump leaves at its own instant (a kBeforeEvent sample in the
  /// same modes at the same time, itself or later) is exempt if it was entered at that instant (a
  /// kAfterEvent sample in the same modes at the same time, itself or earlier) or lay inside with
  /// the inputs just before that instant (an input jump put it outside). Run applies it to every
  /// result; callers that replay or doctor a result may apply it too. Throws std::invalid_argument
  /// if a state does not fit the model (mode indices, number of variables) or a signal drives a
  /// non-input.
  std::optional<std::string> FirstStateOutsideInvariant(
      const SimulationResult& result, const SimulationOptions& options,
      std::span<const InputSignal> signals = {}) const;

  /// Names of the continuous variables, the order of StateSample::x.
  const std::vector<std::string>& variable_names() const;
  /// Name of mode `mode` of component `component`, qualified by the instance.
  std::string ModeName(int component, int mode) const;
  /// Names of the current modes of `modes`, joined with "|" for several components.
  std::string ModeLabel(std::span<const int> modes) const;
  const System& system() const;
  /// The values of every System slot's parameter for a run with `parameters` set
  /// (SimulationOptions::parameters; throws as Run does), other slots 0.
  std::vector<double> ParameterEnvironment(
      std::span<const std::pair<std::string, double>> parameters) const;

 private:
  std::unique_ptr<const CompiledModel> model_;
};

}  // namespace hybrid
