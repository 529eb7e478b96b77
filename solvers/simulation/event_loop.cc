#include "solvers/simulation/event_loop.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "automaton/internal_assert.h"
#include "solvers/simulation/invariant_guard.h"
#include "solvers/simulation/zeno_detection.h"

namespace hybrid {

namespace {

// Consecutive passes of the loop that neither advanced time nor jumped. A few are normal (a root
// at the segment start, then a stop time there); more mean that the loop is stuck.
constexpr int kMaxStalledPasses = 100;
// A segment after a restart shorter than this times |t| is not given to CVODE (see ShortGap).
constexpr double kShortGap = 100 * std::numeric_limits<double>::epsilon();

}  // namespace

EventLoop::EventLoop(const CompiledModel& model, RunState& run, const SimulationOptions& options,
                     double until, std::vector<double> breakpoints, Eigen::VectorXd x)
    : model_(model),
      components_(model.components()),
      run_(run),
      options_(options),
      until_(until),
      breakpoints_(std::move(breakpoints)),
      n_(static_cast<int>(run.x_size())),
      x_(std::move(x)),
      jumps_(model.components(), run),
      samples_(options, until),
      rate_(Eigen::VectorXd::Zero(std::max(n_, 1))) {
  HYBRID_ASSERT(x_.size() == std::max(n_, 1), "the state has max(1, number of variables) entries");
  HYBRID_ASSERT(run.modes().size() == components_.size(), "the run's modes are set");
}

SimulationResult EventLoop::Simulate() {
  // The listed samples, the start and a few events (the vector grows past that as needed).
  result_.samples.reserve(options_.sample_times.size() + 16);
  Record(StateSample::Kind::kStart);
  bool running = JumpAndIterate(jumps_.Candidates(), EventRecord::Cause::kEnabled);
  if (running) running = FireScheduled();
  if (running && ZenoCheck()) running = false;
  // Listed times already reached (0, or before the first step): recorded now, after the start.
  RecordListed();
  if (running && StopAsked()) running = false;
  EvaluateRoots(t_, x_, &g_prev_);
  while (running && t_ < until_) running = RunPass();
  return Finish();
}

bool EventLoop::RunPass() {
  if (StepLimitExceeded()) return false;
  Pass p = BeginPass();
  IntegrateToStop(p);
  if (p.status == CvodeIntegrator::Status::kFailure) {
    result_.status = SimulationStatus::kSolverFailure;
    result_.message =
        integrator_->message() + " at t = " + FormatNumber(p.t_new) + " in mode " + ModesLabel();
    return false;
  }
  CollectSolverRoots(p);
  FindInteriorCrossing(p);
  if (!RecordInsideStep(p)) return false;
  t_ = p.t_new;
  x_ = x_new_;
  run_.Load(t_, x_.data());
  bool restart = p.interior;

  jumps_.ForgetAll();  // a new instant
  if (p.status == CvodeIntegrator::Status::kRoot || p.interior) {
    if (!HandleCrossings(p, &restart)) return false;
  }
  if (!ReachStopTimes(&restart)) return false;
  if (!EndPass(p, restart)) return false;
  // An exact segment that ended at a sample with nothing crossed goes on along its line.
  const bool on_line = p.exact && p.status == CvodeIntegrator::Status::kReachedTime && !restart &&
                       !p.at_breakpoint && result_.events.size() == p.events_before && anchor_.set;
  return on_line ? SamplesOnTheLine() : true;
}

bool EventLoop::SamplesOnTheLine() {
  // The earliest time a root function crosses on the anchor's line (ExactCrossing's `toward`).
  double first = until_;
  slopes_.resize(g_prev_.size());
  for (size_t i = 0; i < g_prev_.size(); ++i) {
    slopes_[i] = run_.Slope(static_cast<int>(i), rate_);
    const int dir = run_.roots()[i].direction;
    const double g0 = anchor_.g[i], slope = slopes_[i];
    const bool toward =
        (dir <= 0 && g0 > 0.0 && slope < 0.0) || (dir >= 0 && g0 < 0.0 && slope > 0.0);
    if (toward) first = std::min(first, anchor_.t - g0 / slope);
  }
  for (;;) {
    while (next_break_ < breakpoints_.size() && breakpoints_[next_break_] <= t_) ++next_break_;
    const double hard =
        next_break_ < breakpoints_.size() ? std::min(until_, breakpoints_[next_break_]) : until_;
    const double stop = samples_.Next();
    const double tie = 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(stop));
    // The next pass is one of these only if it is exact (ExactSegmentApplies), ends at a sample
    // (not at an input breakpoint or the horizon) and nothing crosses up to a tie after it.
    if (!(stop < hard) || !(stop + tie < first) || !StaysOnTheLine()) return true;
    if (StepLimitExceeded()) return false;
    t_ = stop;
    x_ = anchor_.x + rate_.head(x_.size()) * (t_ - anchor_.t);
    run_.Load(t_, x_.data());
    jumps_.ForgetAll();
    if (samples_.TakeUniform(t_)) Record(StateSample::Kind::kSample);
    RecordListed();
    if (StopAsked()) return false;
    EvaluateRoots(t_, x_, &g_prev_);
    stalled_ = 0;
  }
}

bool EventLoop::StaysOnTheLine() const {
  for (size_t i = 0; i < g_prev_.size(); ++i) {
    if (!(run_.roots()[i].direction * slopes_[i] > 0.0)) continue;  // moving away or along
    const bool boundary =
        g_prev_[i] == 0.0 ? anchor_.t - anchor_.g[i] / slopes_[i] == t_ : OnBoundary(i);
    if (boundary) return false;
  }
  return true;
}

bool EventLoop::StepLimitExceeded() {
  if (++passes_ <= options_.max_steps) return false;
  result_.status = SimulationStatus::kStepLimit;
  result_.message =
      "more than " + std::to_string(options_.max_steps) +
      " integration steps (solver steps and exact segments) before t = " + FormatNumber(t_);
  return true;
}

EventLoop::Pass EventLoop::BeginPass() {
  while (next_break_ < breakpoints_.size() && breakpoints_[next_break_] <= t_) ++next_break_;
  Pass p;
  p.t_stop = std::min({until_, samples_.Next(),
                       next_break_ < breakpoints_.size() ? breakpoints_[next_break_] : until_});
  p.t_prev = t_;
  x_start_ = x_;
  p.events_before = result_.events.size();
  p.t_new = t_;
  crossed_.clear();
  p.at_breakpoint = next_break_ < breakpoints_.size() && p.t_stop == breakpoints_[next_break_];
  return p;
}

void EventLoop::IntegrateToStop(Pass& p) {
  // Exact segment: constant rates and affine root functions. Each root function is
  // g_i(t) = g_i(t_prev) + s_i (t - t_prev); the first crossing in its direction is a division.
  // A root function starting on its boundary is left to the solver path (its conventions for
  // that case apply), so both paths fire the same events.
  p.exact = ExactSegmentApplies(p);
  if (!p.exact && options_.interpolate_samples && !p.at_breakpoint && p.t_stop < until_) {
    // A solver step goes on past the samples (RecordInsideStep records them).
    const bool breakpoint = next_break_ < breakpoints_.size() && breakpoints_[next_break_] < until_;
    p.t_stop = breakpoint ? breakpoints_[next_break_] : until_;
    p.at_breakpoint = breakpoint;
  }
  if (p.exact) {
    ExactSegment(p);
  } else if (stale_ && p.t_stop - t_ <= kShortGap * std::max(std::abs(t_), std::abs(p.t_stop))) {
    ShortGap(p);
  } else {
    SolverStep(p);
  }
}

bool EventLoop::ExactSegmentApplies(const Pass& p) {
  bool exact = run_.exact();
  if (exact) {
    run_.Derivatives(t_, x_.data(), rate_.data());
    // On the anchor's line, a root function is exactly on its boundary where its line says
    // so, not where a stop's rounded state happens to give 0.
    const bool on_line = anchor_.set && rate_ == anchor_.rate;
    for (size_t i = 0; i < g_prev_.size() && exact; ++i) {
      const double slope = run_.Slope(static_cast<int>(i), rate_);
      const bool boundary = on_line && g_prev_[i] == 0.0
                                ? anchor_.t - anchor_.g[i] / slope == p.t_prev
                                : OnBoundary(i);
      exact = !(boundary && run_.roots()[i].direction * slope > 0.0);
    }
  }
  return exact;
}

void EventLoop::ExactSegment(Pass& p) {
  if (!anchor_.set || rate_ != anchor_.rate) {
    anchor_.set = true;
    anchor_.t = p.t_prev;
    anchor_.x = x_;
    anchor_.rate = rate_;
    anchor_.g = g_prev_;
  }
  HYBRID_ASSERT(anchor_.g.size() == g_prev_.size(),
                "the anchor has the current root functions (a jump drops the anchor)");
  const double tie = 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(p.t_stop));
  // A crossing up to a tie after a recorded sample's time still ends this pass, at its own
  // time: the sample must not split crossings that the run without it fires together (and
  // chooses between by priority), nor move one onto its time; the sample is then recorded
  // at the event's time. Input breakpoints and the horizon are hard stops.
  const double limit = p.at_breakpoint || p.t_stop >= until_ ? p.t_stop : p.t_stop + tie;
  p.t_new = limit;  // the earliest crossing so far
  for (size_t i = 0; i < g_prev_.size(); ++i) {
    const std::optional<double> crossing = ExactCrossing(i, p, limit, tie);
    if (!crossing) continue;
    if (*crossing < p.t_new - tie) crossed_.clear();
    p.t_new = std::min(p.t_new, *crossing);
    crossed_.push_back(static_cast<int>(i));
  }
  if (crossed_.empty()) p.t_new = p.t_stop;
  p.status =
      crossed_.empty() ? CvodeIntegrator::Status::kReachedTime : CvodeIntegrator::Status::kRoot;
  x_new_ = anchor_.x + rate_.head(x_.size()) * (p.t_new - anchor_.t);
  stale_ = true;
}

std::optional<double> EventLoop::ExactCrossing(size_t i, const Pass& p, double limit,
                                               double tie) const {
  const double slope = run_.Slope(static_cast<int>(i), rate_);
  const int dir = run_.roots()[i].direction;
  // Where the root function crosses is decided on its line from the anchor, never from
  // the rounded state of a stop in between (which may already lie a hair past the
  // boundary, so that the crossing would be missed).
  const double g0 = anchor_.g[i];
  const bool toward =
      (dir <= 0 && g0 > 0.0 && slope < 0.0) || (dir >= 0 && g0 < 0.0 && slope > 0.0);
  if (!toward) return std::nullopt;
  const double on_line = anchor_.t - g0 / slope;
  // Crossed before this pass: reported by the pass that reached it.
  if (on_line < p.t_prev - tie) return std::nullopt;
  const double crossing = std::max(on_line, p.t_prev);
  if (crossing > p.t_new + tie || crossing > limit) return std::nullopt;
  // Already reported at this instant, and nothing fired: no progress to make here.
  if (crossing <= p.t_prev + tie && settled_.IsSettled(i, p.t_prev, result_.events.size())) {
    return std::nullopt;
  }
  // An invariant boundary reached exactly at an input breakpoint is not left yet: the
  // input changes there. The next segment starts on the boundary and decides.
  if (run_.roots()[i].invariant && p.at_breakpoint && crossing >= p.t_stop - tie) {
    return std::nullopt;
  }
  return crossing;
}

void EventLoop::ShortGap(Pass& p) {
  // A stop time a few ulps after a restart (a jump one ulp before a sample time or an input
  // breakpoint): CVODE cannot start a step that short (CV_TOO_CLOSE), and CVODE itself
  // locates roots only to about this precision. Move there on the tangent instead; a root
  // function that changes sign, or leaves its boundary, crosses at the stop time.
  p.short_gap = true;
  run_.Derivatives(t_, x_.data(), rate_.data());
  p.t_new = p.t_stop;
  x_new_ = x_ + rate_.head(x_.size()) * (p.t_new - p.t_prev);
  EvaluateRoots(p.t_new, x_new_, &g_mid_);
  for (size_t i = 0; i < g_mid_.size(); ++i) {
    const int dir = run_.roots()[i].direction;
    const double g0 = g_prev_[i], g1 = g_mid_[i];
    const bool moved =
        OnBoundary(i) ? dir * g1 > dir * g0
                      : (dir <= 0 && g0 > 0.0 && g1 <= 0.0) || (dir >= 0 && g0 < 0.0 && g1 >= 0.0);
    if (moved) crossed_.push_back(static_cast<int>(i));
  }
  p.status =
      crossed_.empty() ? CvodeIntegrator::Status::kReachedTime : CvodeIntegrator::Status::kRoot;
}

void EventLoop::SolverStep(Pass& p) {
  if (!integrator_) {
    CvodeIntegrator::Options integrator_options;
    integrator_options.relative_tolerance = options_.relative_tolerance;
    integrator_options.absolute_tolerance = options_.absolute_tolerance;
    integrator_options.max_step = options_.max_step;
    integrator_options.fixed_point_iteration = options_.fixed_point_iteration;
    integrator_.emplace(&run_, std::max(n_, 1), integrator_options);
  }
  if (stale_) {
    integrator_->Restart(t_, x_, run_.directions());
    stale_ = false;
    p.restarted = true;
  }
  p.status = integrator_->Advance(p.t_stop, &p.t_new, &x_new_);
  ++result_.steps;
}

void EventLoop::CollectSolverRoots(const Pass& p) {
  // Roots CVODE reports, or a double crossing inside the step found on the interpolant.
  if (!p.exact && !p.short_gap && p.status == CvodeIntegrator::Status::kRoot) {
    HYBRID_ASSERT(integrator_ && integrator_->root_info().size() == run_.roots().size(),
                  "CVODE reports on the current root functions");
    for (size_t i = 0; i < integrator_->root_info().size(); ++i) {
      if (integrator_->root_info()[i] != 0) crossed_.push_back(static_cast<int>(i));
    }
  }
}

void EventLoop::FindInteriorCrossing(Pass& p) {
  // Crossings CVODE cannot see, found on the step's interpolating polynomial:
  // - a guard that crosses and crosses back inside one step leaves the step ends with the same
  //   sign: look at `dense_checks` interior points;
  // - CVODE ignores a root function that is exactly 0 where it was (re)started (it takes its
  //   sign from just after the start), and one already past its boundary (within
  //   event_tolerance) has no crossing left to report. So a root function that starts on its
  //   boundary and moves on in its direction would never be reported: a strict guard `x > 0`
  //   entered at x = 0, or an invariant left right after a jump onto its boundary. Look at the
  //   step end too for those (root functions exactly 0, and invariants past their boundary
  //   within event_tolerance).
  bool any_on_boundary = false;
  for (size_t i = 0; i < g_prev_.size() && !any_on_boundary; ++i) {
    any_on_boundary = OnBoundary(i);
  }
  if (!p.exact && !p.short_gap && (options_.dense_checks > 0 || any_on_boundary) &&
      !run_.roots().empty() && p.t_new > p.t_prev) {
    HYBRID_ASSERT(integrator_.has_value(), "a solver step has an integrator to interpolate");
    ga_ = g_prev_;
    double a = p.t_prev;
    const int points = options_.dense_checks + 1;  // the last one is the step end
    for (int j = 1; j <= points && !p.interior; ++j) {
      const bool end = j == points;
      if (end && !any_on_boundary) break;  // CVODE watches the step ends
      const double b = end ? p.t_new : p.t_prev + (p.t_new - p.t_prev) * j / points;
      if (end) {
        EvaluateRoots(b, x_new_, &g_mid_);
      } else {
        if (!integrator_->Interpolate(b, &x_mid_)) break;
        EvaluateRoots(b, x_mid_, &g_mid_);
      }
      for (size_t i = 0; i < g_mid_.size() && !p.interior; ++i) {
        p.interior = InteriorCrossing(i, a, b, end, p);
      }
      a = b;
      ga_ = g_mid_;
    }
  }
}

bool EventLoop::InteriorCrossing(size_t i, double a, double b, bool end, Pass& p) {
  const int dir = run_.roots()[i].direction;
  const bool boundary = OnBoundary(i);
  if (end && !boundary) return false;
  // Whether root i has crossed at g since `a` or, starting on its boundary, moved on in
  // its direction since the step start.
  const double g0 = boundary ? g_prev_[i] : ga_[i];
  auto reached = [&](double g) {
    return boundary ? dir * g > dir * g0 : g == 0.0 || (g > 0.0) != (g0 > 0.0);
  };
  const bool change = boundary ? reached(g_mid_[i])
                               : (g0 > 0.0 && g_mid_[i] <= 0.0 && dir <= 0) ||
                                     (g0 < 0.0 && g_mid_[i] >= 0.0 && dir >= 0);
  if (!change) return false;
  // Bisection on the interpolant: not reached at lo, reached at hi.
  double lo = a, hi = b;
  while (hi - lo > 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(hi))) {
    const double mid = 0.5 * (lo + hi);
    if (!integrator_->Interpolate(mid, &x_mid_)) break;
    EvaluateRoots(mid, x_mid_, &gm_);
    if (reached(gm_[i]))
      hi = mid;
    else
      lo = mid;
  }
  p.t_new = hi;
  integrator_->Interpolate(p.t_new, &x_new_);
  crossed_ = {static_cast<int>(i)};
  return true;
}

bool EventLoop::HandleCrossings(const Pass& p, bool* restart) {
  if (auto off = UnresolvedCrossing(crossed_)) {
    // The state reached is not trustworthy: the run ends at the start of this pass.
    result_.status = SimulationStatus::kUnresolved;
    result_.message = *off;
    t_ = p.t_prev;
    x_ = x_start_;
    run_.Load(t_, x_.data());
    return false;
  }
  jumps_.Note(crossed_);
  std::vector<Jump> jumps = jumps_.Candidates();
  const bool jumped = !jumps.empty();
  bool running = true;
  if (jumped) {
    const EventRecord::Cause cause =
        LazyLeader(jumps) ? EventRecord::Cause::kInvariant : EventRecord::Cause::kCrossing;
    running = JumpAndIterate(std::move(jumps), cause);
    *restart = true;
  }
  // A component that reached its invariant boundary and has not left its mode (nothing was
  // enabled, or only other components jumped at this instant) violates its invariant.
  if (running) {
    if (const std::optional<std::string> reached = jumps_.FirstReachedInvariant()) {
      result_.status = SimulationStatus::kInvariantViolated;
      result_.message = "at t = " + FormatNumber(t_) + " the state leaves the invariant '" +
                        *reached + "' of mode " + ModesLabel() + " and no transition is enabled";
      running = false;
    }
  }
  if (running && jumped && ZenoCheck()) running = false;
  // Exact segments: a root function reported here that fired nothing is not reported again at
  // this instant.
  if (running && p.exact && !jumped) {
    settled_.Settle(t_, result_.events.size(), run_.roots().size(), crossed_);
  }
  return running;
}

bool EventLoop::ReachStopTimes(bool* restart) {
  // Stop times reached by this step (also when a root lies exactly on one: otherwise the sample
  // or the input jump there would be skipped, and the next Advance would be asked to stop at
  // the current time).
  if (samples_.TakeUniform(t_)) Record(StateSample::Kind::kSample);
  RecordListed();
  if (StopAsked()) return false;
  if (next_break_ < breakpoints_.size() && t_ >= breakpoints_[next_break_]) {
    run_.SetStepInputs(t_);
    run_.Load(t_, x_.data());
    settled_.Unsettle();  // the inputs changed
    bool running = InputJump();
    if (running) running = FireScheduled();
    *restart = true;
    return running;
  }
  return true;
}

bool EventLoop::FireScheduled() {
  const std::vector<ScheduledJump>& schedule = options_.lazy_schedule;
  bool running = true;
  while (running && next_scheduled_ < schedule.size() && schedule[next_scheduled_].time <= t_) {
    const ScheduledJump& entry = schedule[next_scheduled_++];
    Jump jump;
    bool enabled = !entry.transitions.empty();
    for (const auto& [c, ti] : entry.transitions) {
      enabled = enabled && c >= 0 && c < static_cast<int>(components_.size()) && ti >= 0 &&
                ti < static_cast<int>(components_[c].transitions.size()) &&
                components_[c].transitions[ti].source == run_.modes()[c] &&
                run_.GuardHolds(c, ti, true);
      jump.emplace_back(c, ti);
    }
    if (!enabled) continue;
    running = JumpAndIterate({jump}, EventRecord::Cause::kScheduled);
    settled_.Unsettle();
  }
  return running;
}

bool EventLoop::EndPass(const Pass& p, bool restart) {
  EvaluateRoots(t_, x_, &g_prev_);
  // Also restart after a root that fired nothing when some root function is exactly 0 there:
  // CVODE would fail on the next step (CV_ILL_INPUT, "root found at and very near t") if it is
  // still 0 just after the root, as when the state lands exactly on a boundary value.
  if (p.status == CvodeIntegrator::Status::kRoot && !restart) {
    restart = std::find(g_prev_.begin(), g_prev_.end(), 0.0) != g_prev_.end();
  }
  if (restart) stale_ = true;
  if (restart || !p.exact) anchor_.set = false;
  // Never spin: every pass must advance time or jump, but for a bounded number of passes.
  // CVODE steps that continue without a restart are not counted: steps shorter than the
  // resolution of t (t + h = t, as a solution blows up) are bounded by its max_steps, which
  // reports CV_TOO_MUCH_WORK.
  const bool continued = !p.exact && !p.short_gap && !p.restarted;
  if (t_ > p.t_prev || result_.events.size() != p.events_before) {
    stalled_ = 0;
  } else if (!continued && ++stalled_ > kMaxStalledPasses) {
    result_.status = SimulationStatus::kSolverFailure;
    result_.message = "no progress at t = " + FormatNumber(t_) + " in mode " + ModesLabel() + ": " +
                      std::to_string(kMaxStalledPasses) +
                      " passes neither advanced time nor took a jump";
    return false;
  }
  return true;
}

SimulationResult EventLoop::Finish() {
  if (result_.status == SimulationStatus::kCompleted && t_ < until_) {
    result_.status = SimulationStatus::kSolverFailure;
    result_.message = "stopped before the horizon";
  }
  Record(StateSample::Kind::kEnd);
  // The general guard: no recorded state outside its modes' invariants (the final instant of an
  // invariant violation aside), whatever the status; the first one ends the run there.
  const double exempt_from = result_.status == SimulationStatus::kInvariantViolated
                                 ? t_
                                 : std::numeric_limits<double>::infinity();
  if (auto outside = StateOutsideInvariant(run_, result_.samples, model_, exempt_from)) {
    TruncateUnresolved(result_, outside->first, std::move(outside->second));
  }
  return std::move(result_);
}

void EventLoop::Fire(const Jump& jump, EventRecord::Cause cause) {
  EventRecord e;
  e.time = t_;
  e.cause = cause;
  e.modes_before = run_.modes();
  e.before = x_.head(n_);
  Record(StateSample::Kind::kBeforeEvent);
  std::vector<int> modes_after = run_.modes();
  Eigen::VectorXd x_after = x_;
  for (const auto& [c, ti] : jump) {
    HYBRID_ASSERT(c >= 0 && c < static_cast<int>(components_.size()) && ti >= 0 &&
                      ti < static_cast<int>(components_[c].transitions.size()) &&
                      components_[c].transitions[ti].source == run_.modes()[c],
                  "a jump's transitions leave their components' current modes");
    const CompiledTransition& tr = components_[c].transitions[ti];
    e.transitions.push_back(tr.name);
    if (e.label.empty()) e.label = tr.label;
    for (const auto& [index, value] : tr.resets) {
      x_after[index] = value.Evaluate(run_.env().data());
    }
    modes_after[c] = tr.target;
  }
  x_ = x_after;
  run_.SetModes(modes_after);
  run_.Load(t_, x_.data());
  e.modes_after = run_.modes();
  e.after = x_.head(n_);
  Record(StateSample::Kind::kAfterEvent);
  result_.events.push_back(std::move(e));
}

bool EventLoop::JumpAndIterate(std::vector<Jump> jumps, EventRecord::Cause cause) {
  for (int iteration = 0; !jumps.empty(); ++iteration) {
    if (iteration >= options_.max_event_iterations) {
      StopIterationZeno();
      return false;
    }
    if (static_cast<long>(result_.events.size()) >= options_.max_events) {
      result_.status = SimulationStatus::kEventLimit;
      result_.message = "more than " + std::to_string(options_.max_events) + " events";
      return false;
    }
    Fire(jumps.front(), cause);
    jumps_.Forget(jumps.front());  // these components are in new modes now
    if (auto violated = run_.ViolatedInvariant()) {
      // Still allowed if an urgent transition leaves at once.
      jumps = jumps_.Candidates();
      if (jumps.empty()) {
        result_.status = SimulationStatus::kInvariantViolated;
        result_.message = "after the jump at t = " + FormatNumber(t_) + " the state violates '" +
                          *violated + "' of mode " + ModesLabel();
        return false;
      }
    } else {
      jumps = jumps_.Candidates();
    }
    cause = jumps_.CauseInIteration(jumps);
  }
  return true;
}

bool EventLoop::LazyLeader(const std::vector<Jump>& jumps) const {
  HYBRID_ASSERT(!jumps.empty() && !jumps.front().empty(), "a jump has a leader");
  const auto [c0, t0] = jumps.front().front();
  return components_[c0].transitions[t0].urgency == Urgency::kLazy;
}

void EventLoop::StopIterationZeno() {
  result_.status = SimulationStatus::kZeno;
  result_.message = "more than " + std::to_string(options_.max_event_iterations) +
                    " jumps at t = " + FormatNumber(t_) + " (event iteration does not settle)";
  result_.zeno = IterationZenoReport(result_.events, t_);
}

bool EventLoop::ZenoCheck() {
  std::optional<ZenoFinding> zeno = DetectZeno(result_.events, options_);
  if (!zeno) return false;
  result_.status = SimulationStatus::kZeno;
  result_.message = std::move(zeno->message);
  result_.zeno = std::move(zeno->report);
  return true;
}

std::optional<std::string> EventLoop::UnresolvedCrossing(const std::vector<int>& crossed) const {
  // A located event must sit on its boundary: the root functions that crossed are within their
  // resolution tolerance of zero at the state reached. Otherwise time, rounded to doubles, no
  // longer resolves the dynamics there (or the solver's root location failed).
  for (int i : crossed) {
    const auto off = run_.OffBoundary(i);
    if (!off) continue;
    const RootRef& ref = run_.roots()[i];
    const double resolution = std::nextafter(t_, std::numeric_limits<double>::infinity()) - t_;
    return "at t = " + FormatNumber(t_) + " the event on '" + run_.ComparisonOf(ref).text +
           "' in mode " + ModesLabel() + " cannot be located: the state reached is " +
           FormatNumber(std::abs(off->first)) + " from its boundary, beyond the tolerance " +
           FormatNumber(off->second) + "; time is resolved only to " + FormatNumber(resolution) +
           " there (a shorter horizon, or larger tolerances)";
  }
  return std::nullopt;
}

bool EventLoop::InputJump() {
  // An urgent guard may hold now, and a component the jump leaves outside its invariant has
  // reached its boundary at this instant (its lazy transitions may fire; if none does, the
  // invariant is violated).
  for (size_t c = 0; c < components_.size(); ++c) {
    if (auto violated = run_.ViolatedInvariantOf(c)) jumps_.ReachInvariant(c, *violated);
  }
  std::vector<Jump> jumps = jumps_.Candidates();
  const EventRecord::Cause cause = !jumps.empty() && LazyLeader(jumps)
                                       ? EventRecord::Cause::kInvariant
                                       : EventRecord::Cause::kEnabled;
  if (!JumpAndIterate(std::move(jumps), cause)) return false;
  if (const std::optional<std::string> reached = jumps_.FirstReachedInvariant()) {
    result_.status = SimulationStatus::kInvariantViolated;
    result_.message = "at t = " + FormatNumber(t_) + " the input jump leaves the state outside " +
                      "the invariant '" + *reached + "' of mode " + ModesLabel() +
                      " and no transition is enabled";
    return false;
  }
  return !ZenoCheck();
}

bool EventLoop::RecordInsideStep(const Pass& p) {
  if (p.exact || p.short_gap || !options_.interpolate_samples) return true;
  for (double t = samples_.Next(); t < p.t_new; t = samples_.Next()) {
    HYBRID_ASSERT(t > p.t_prev, "the samples up to the pass's start are taken");
    const bool inside = integrator_->Interpolate(t, &x_mid_);
    HYBRID_ASSERT(inside, "a sample inside a solver step lies on its interpolant");
    if (samples_.TakeUniform(t)) RecordAt(StateSample::Kind::kSample, t, x_mid_);
    while (samples_.TakeListed(t)) RecordAt(StateSample::Kind::kSample, t, x_mid_);
    if (stop_asked_) {
      t_ = t;
      x_ = x_mid_;
      return !StopAsked();
    }
  }
  return true;
}

void EventLoop::Record(StateSample::Kind kind) { RecordAt(kind, t_, x_); }

void EventLoop::RecordAt(StateSample::Kind kind, double t, const Eigen::VectorXd& x) {
  result_.samples.push_back({t, kind, run_.modes(), x.head(n_)});
  if (kind == StateSample::Kind::kSample && options_.monitor && !stop_asked_) {
    stop_asked_ = !options_.monitor(monitored_++, result_.samples.back());
  }
}

bool EventLoop::StopAsked() {
  if (!stop_asked_) return false;
  result_.status = SimulationStatus::kStopped;
  result_.message = "stopped by the monitor at t = " + FormatNumber(t_);
  return true;
}

void EventLoop::RecordListed() {
  while (samples_.TakeListed(t_)) Record(StateSample::Kind::kSample);
}

void EventLoop::EvaluateRoots(double time, const Eigen::VectorXd& state, std::vector<double>* g) {
  g->resize(run_.roots().size());
  if (!g->empty()) run_.Roots(time, state.data(), g->data());
}

bool EventLoop::OnBoundary(size_t i) const {
  const RootRef& ref = run_.roots()[i];
  return ref.direction != 0 &&
         (g_prev_[i] == 0.0 || (ref.invariant && ref.direction * g_prev_[i] > 0.0 &&
                                std::abs(g_prev_[i]) <= options_.event_tolerance));
}

}  // namespace hybrid
