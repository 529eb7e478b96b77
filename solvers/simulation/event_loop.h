#pragma once

// The event loop of one simulation run (the semantics are those stated in
// include/hybrid/simulation/simulator.h): integrate to the next stop, locate crossings, choose and
// fire jumps, iterate at an instant, detect Zeno, record.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/simulation/simulator.h"
#include "solvers/simulation/compiled_model.h"
#include "solvers/simulation/cvode_integrator.h"
#include "solvers/simulation/jump_selector.h"
#include "solvers/simulation/run_state.h"
#include "solvers/simulation/sample_schedule.h"
#include "solvers/simulation/settled_roots.h"

namespace hybrid {

/// The event loop of one run, in the manner of Drake's Simulator::AdvanceTo: each pass integrates
/// towards the next stop time (horizon, sample time, input breakpoint) on an exact segment, a
/// tangent over a short gap or CVODE (IntegrateToStop); locates the crossings inside the step
/// (FindInteriorCrossing); at a crossing chooses and fires the jumps and iterates at that instant,
/// watching for Zeno (HandleCrossings); records the samples due and applies input jumps
/// (ReachStopTimes); and guards against a loop that makes no progress (EndPass). The members hold
/// what the steps share: time and state, the result so far, what the current instant reached (a
/// JumpSelector), the integrator and the anchor of exact segments.
class EventLoop {
 public:
  /// `run` must be at the start state (step inputs at 0, modes set, (0, x) loaded) and `x` be
  /// that state (max(1, number of variables) entries); the start state lies inside its
  /// invariants. `options` must be valid for the horizon `until` (ValidateSimulationOptions,
  /// ValidateSampleTimes); `breakpoints` are those of the inputs and scheduled jumps
  /// (Breakpoints). Keeps references to `model`, `run` and `options`, which must outlive the
  /// loop.
  EventLoop(const CompiledModel& model, RunState& run, const SimulationOptions& options,
            double until, std::vector<double> breakpoints, Eigen::VectorXd x);
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  /// Records the start, fires what is enabled there, runs passes until the horizon or a stop, and
  /// returns the result (Finish). Call once.
  SimulationResult Simulate();

 private:
  // One pass of the loop: where it started, what it aimed at, how it moved and what it reached.
  struct Pass {
    double t_stop = 0.0;         // the stop time: horizon, next sample time or input breakpoint
    double t_prev = 0.0;         // the time at the start of the pass
    size_t events_before = 0;    // events recorded before the pass
    bool at_breakpoint = false;  // t_stop is an input breakpoint
    bool exact = false;          // an exact segment (constant rates, affine root functions)
    bool short_gap = false;      // stepped over a gap too short for CVODE
    bool restarted = false;      // CVODE was restarted for this pass
    bool interior = false;       // a crossing found inside the step on the interpolant
    double t_new = 0.0;          // the time reached (x_new_ the state)
    CvodeIntegrator::Status status = CvodeIntegrator::Status::kReachedTime;
  };
  // Exact segments are computed from an anchor, the state where the current constant rates took
  // over (after a jump, an input breakpoint, a restart or a solver pass), not from the last stop:
  // a recorded sample stops the loop, and computing on from its rounded state made the state at
  // a later event (a guard reached exactly at an input breakpoint) depend on `sample_step`.
  struct Anchor {
    bool set = false;
    double t = 0.0;
    Eigen::VectorXd x, rate;
    std::vector<double> g;  // the root functions at (t, x)
  };

  // One pass: integrate to the next stop, locate crossings, act on them, reach the stop times.
  // Returns false when the run must stop (status set, or an early stop such as kUnresolved).
  bool RunPass();
  // After an exact pass that ended at a sample with nothing crossed: the passes to the next
  // samples on the same line (constant rates, the anchor unchanged), each taken here as RunPass
  // takes it (the state on the anchor's line, recorded, the root functions evaluated there) but
  // without locating crossings, while no root function can cross up to a tie after the sample
  // and the next pass stays exact. Leaves the first pass that may differ from such a pass (a
  // crossing near, a boundary, an input breakpoint, the horizon) to RunPass. Returns false when
  // the run must stop (step limit, monitor).
  bool SamplesOnTheLine();
  // Whether a pass starting at t_ is exact on the anchor's line: ExactSegmentApplies with the
  // rates unchanged (slopes_ of the line, g_prev_ at t_).
  bool StaysOnTheLine() const;
  // Counts the pass; beyond options.max_steps sets kStepLimit and returns true.
  bool StepLimitExceeded();
  // Starts a pass at (t_, x_): skips breakpoints already reached, chooses the stop time, saves
  // the start state (x_start_) and clears crossed_.
  Pass BeginPass();
  // Moves from (t_, x_) towards p.t_stop by one of the three paths; sets p.exact and the path's
  // flags, p.status, p.t_new, x_new_ and, on the exact and short-gap paths, crossed_.
  void IntegrateToStop(Pass& p);
  // Whether this pass can be an exact segment: the modes are exact and no root function starts
  // on its boundary moving in its direction (that case goes to the solver path). Sets rate_ to
  // the constant rate when the modes are exact.
  bool ExactSegmentApplies(const Pass& p);
  // Exact segment: (re)anchors the line if the rate changed, then moves on it to the earliest
  // crossing (ties within a few ulps together in crossed_) or to the stop time. Marks the
  // integrator stale.
  void ExactSegment(Pass& p);
  // The crossing time of root function i on the anchor's line if it counts for this pass (moving
  // towards its boundary in its direction, not before the pass, not after the earliest so far or
  // `limit`, not settled at the pass start, not an invariant at a breakpoint); nullopt otherwise.
  std::optional<double> ExactCrossing(size_t i, const Pass& p, double limit, double tie) const;
  // Short gap: moves to p.t_stop on the tangent; a root function that changes sign there, or
  // leaves its boundary in its direction, crosses at the stop time.
  void ShortGap(Pass& p);
  // Solver path: one CVODE step towards p.t_stop (created on first use, restarted if stale).
  void SolverStep(Pass& p);
  // After a CVODE root: the root functions it reports, into crossed_.
  void CollectSolverRoots(const Pass& p);
  // After a CVODE step: looks for a crossing CVODE cannot see on the step's interpolant (dense
  // checks, and root functions that start on their boundary at the step end); if found, bisects
  // it, sets p.interior, p.t_new, x_new_ and crossed_ to that root function alone.
  void FindInteriorCrossing(Pass& p);
  // Root function i between the dense points a and b (ga_ at a, g_mid_ at b; only on its boundary
  // at the step end): if it crossed, or moved on from its boundary, there, bisects for the time and
  // returns true (p.t_new, x_new_, crossed_ set).
  bool InteriorCrossing(size_t i, double a, double b, bool end, Pass& p);
  // At a located crossing (t_ reached): checks its resolution, notes what it reached, fires and
  // iterates, reports an invariant left with nothing enabled, checks Zeno, settles the crossing
  // root functions of an exact segment that fired nothing. Sets *restart after a jump. Returns
  // false when the run must stop (on kUnresolved the run is back at the pass start).
  bool HandleCrossings(const Pass& p, bool* restart);
  // Records the samples due at t_, then applies an input breakpoint reached (InputJump, *restart
  // set). Returns false when the run must stop.
  bool ReachStopTimes(bool* restart);
  // Takes the entries of options_.lazy_schedule due at t_ whose transitions are enabled
  // (JumpAndIterate). Returns false when the run must stop.
  bool FireScheduled();
  // Ends a pass: root functions at the new state, restart and anchor decisions, and the stall
  // guard (kSolverFailure after kMaxStalledPasses passes without progress: returns false).
  bool EndPass(const Pass& p, bool restart);
  // The final checks: kSolverFailure if a run that did not stop otherwise fell short of the
  // horizon, the end state, and the general invariant guard (StateOutsideInvariant).
  SimulationResult Finish();

  // Discrete steps at one instant (the candidates come from jumps_).
  // Fires `jump` at t_: records the states before and after and the event; resets are evaluated
  // in the state before the jump.
  void Fire(const Jump& jump, EventRecord::Cause cause);
  // Fires the first of `jumps` and then whatever becomes enabled at the same instant, at most
  // max_event_iterations times and within max_events. Returns false when the run must stop
  // (kZeno, kEventLimit or kInvariantViolated set).
  bool JumpAndIterate(std::vector<Jump> jumps, EventRecord::Cause cause);
  // Whether the leader of the first of `jumps` (which must not be empty) is a lazy transition.
  bool LazyLeader(const std::vector<Jump>& jumps) const;
  // Event iteration that does not settle: sets kZeno with the last events' transitions.
  void StopIterationZeno();
  // Zeno across time (DetectZeno): if so sets kZeno with its report and returns true.
  bool ZenoCheck();
  // The message if a root function of `crossed` lies off its boundary beyond its resolution
  // tolerance at the state reached; nullopt otherwise.
  std::optional<std::string> UnresolvedCrossing(const std::vector<int>& crossed) const;
  // A step input jumped at t_: a component left outside its invariant has reached its boundary;
  // fires what is enabled. Returns false when the run must stop.
  bool InputJump();

  // Helpers.
  // Records (t_, modes, x_) as a sample of `kind`; gives a kSample to options_.monitor.
  void Record(StateSample::Kind kind);
  void RecordAt(StateSample::Kind kind, double t, const Eigen::VectorXd& x);
  // With options_.interpolate_samples, after a solver step: records the samples due strictly
  // before the pass's end on the step's interpolant. Returns false when the monitor stops the
  // run at one of them ((t_, x_) then that sample's).
  bool RecordInsideStep(const Pass& p);
  // Whether the monitor asked the run to stop; if so, sets the status kStopped.
  bool StopAsked();
  // Records the listed sample times already reached.
  void RecordListed();
  // The root functions at (time, state), into *g (resized to their number).
  void EvaluateRoots(double time, const Eigen::VectorXd& state, std::vector<double>* g);
  // Root function i starts this pass on its boundary (g_prev_ exactly 0, or an invariant past it
  // within event_tolerance) with a crossing direction.
  bool OnBoundary(size_t i) const;
  // The current modes, as a label for messages.
  std::string ModesLabel() const { return model_.ModeLabel(run_.modes()); }

  const CompiledModel& model_;
  const std::vector<CompiledComponent>& components_;
  RunState& run_;
  const SimulationOptions& options_;
  const double until_;
  const std::vector<double> breakpoints_;
  const int n_;  // number of continuous variables (x_ has at least one entry)
  double t_ = 0.0;
  Eigen::VectorXd x_;
  SimulationResult result_;
  // What the current instant reached, and the jumps that can fire there.
  JumpSelector jumps_;
  SampleSchedule samples_;
  // Created on first use: a run that stays in constant-rate modes never needs it.
  std::optional<CvodeIntegrator> integrator_;
  bool stale_ = true;  // the integrator must be restarted at (t, x) before its next step
  Eigen::VectorXd rate_;
  Anchor anchor_;
  size_t next_break_ = 0;
  size_t next_scheduled_ = 0;  // the first entry of options_.lazy_schedule not yet due
  std::vector<double> g_prev_, g_mid_;
  std::vector<double> slopes_;  // of the root functions on the anchor's line (SamplesOnTheLine)
  Eigen::VectorXd x_new_, x_mid_, x_start_;
  // Per-step buffers, reused so that a step allocates nothing.
  std::vector<double> ga_, gm_;
  std::vector<int> crossed_;
  SettledRoots settled_;
  int stalled_ = 0;
  size_t monitored_ = 0;     // samples given to options_.monitor
  bool stop_asked_ = false;  // the monitor returned false
  long passes_ = 0;          // SimulationOptions::max_steps
};

}  // namespace hybrid
