#pragma once

#include <Eigen/Core>
#include <memory>
#include <span>
#include <vector>

namespace hybrid {

/// The continuous dynamics and root functions integrated by CvodeIntegrator.
class OdeSystem {
 public:
  virtual ~OdeSystem() = default;
  /// dx/dt at (t, x); `x` and `dxdt` have the integrator's dimension.
  virtual void Derivatives(double t, const double* x, double* dxdt) = 0;
  /// The root functions g_i(t, x), i < the count given to CvodeIntegrator::Restart.
  virtual void Roots(double t, const double* x, double* g) = 0;
};

/// The time towards which CVODE sizes its first step after a restart at `t` with stop time
/// `t_stop`: min(t_stop, t + 1000 max(|t|, 1)). CVODE bounds that first step from below by
/// 100 * unit roundoff * max(|t|, |target|); aimed at a far stop time (a horizon of 1e50) the bound
/// alone would exceed the dynamics' time scale by far, and the first step with it. The stop time
/// itself is unchanged: steps never pass `t_stop`.
double InitialStepTarget(double t, double t_stop);

/// The one owner of raw SUNDIALS handles: an RAII wrapper over CVODE (SUNDIALS 6.4) with root
/// finding. Not copyable; movable.
///
/// Method: Adams-Moulton with Newton iteration and a dense linear solver (finite-difference
/// Jacobian), suited to the small, mostly non-stiff flows of hybrid models; or, with
/// Options::fixed_point_iteration, with fixed-point iteration (no Jacobian, no linear solves). Root
/// functions are located by CVODE's Illinois method to about 100 * unit roundoff * (|t| + |h|).
///
/// The integrator never prints: CVODE's error handler is replaced by one that keeps the last
/// message (errors and warnings), which failures report in message() (and setup errors in the
/// exception text). The first step after every restart is sized towards InitialStepTarget, not
/// towards the stop time, so that the run does not depend on how far away the stop time is. CVODE
/// cannot start a step towards a stop time within about 2 * unit roundoff
/// * |t| of the restart time: Advance then reports kFailure (CV_TOO_CLOSE, "tout too close to t0
/// to start integration"); the Simulator steps over such short gaps without CVODE.
class CvodeIntegrator {
 public:
  struct Options {
    double relative_tolerance = 1e-10;
    double absolute_tolerance = 1e-12;
    /// Largest internal step; infinity for none.
    double max_step = 0.0;
    /// Most internal steps towards one stop time (counted from the last Restart or the last
    /// change of `t_stop`), as CVODE's mxstep in normal mode; more make Advance report kFailure
    /// ("CV_TOO_MUCH_WORK"), so that a run whose steps collapse (a sliding mode such as
    /// x' = -sign(x), or a flow that turns NaN) ends instead of crawling on for ever.
    int max_steps = 100000;
    /// Solve each implicit Adams step by fixed-point (functional) iteration instead of Newton's
    /// method (SimulationOptions::fixed_point_iteration).
    bool fixed_point_iteration = false;
  };
  /// Outcome of Advance.
  enum class Status { kStep, kReachedTime, kRoot, kFailure };

  /// `system` must outlive the integrator; `dimension` >= 1 (pass 1 with a dummy state for a model
  /// without continuous variables).
  CvodeIntegrator(OdeSystem* system, int dimension, const Options& options);
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;
  CvodeIntegrator(CvodeIntegrator&&) noexcept;
  CvodeIntegrator& operator=(CvodeIntegrator&&) noexcept;

  /// Restarts integration at (t0, x0) (CVodeReInit: after a jump the history is discarded) with
  /// `directions.size()` root functions; directions[i] is +1 (report only rising crossings of
  /// g_i), -1 (only falling) or 0 (both).
  void Restart(double t0, const Eigen::VectorXd& x0, std::span<const int> directions);

  /// Takes one internal step towards `t_stop` (never past it, CV_ONE_STEP mode), truncated at the
  /// first root of any root function. On return `*t` and `*x` hold the time and state reached:
  /// kStep (an internal step ended before t_stop), kReachedTime (t == t_stop), kRoot, or
  /// kFailure (with `message()` set; also after more than Options::max_steps steps towards the
  /// same `t_stop`). Never throws for run-time failures.
  Status Advance(double t_stop, double* t, Eigen::VectorXd* x);
  /// The state at `t` from the interpolating polynomial of the last step (CVodeGetDky); `t` must
  /// lie in the last step [t_n - h_last, t_n]. Returns false otherwise.
  bool Interpolate(double t, Eigen::VectorXd* x);
  /// After kRoot: which root functions crossed (+1 rising, -1 falling, 0 not), per
  /// CVodeGetRootInfo.
  const std::vector<int>& root_info() const { return root_info_; }
  /// The last failure: the return flag and, in parentheses, what CVODE said, e.g.
  /// "CVODE failed: CV_TOO_CLOSE (tout too close to t0 to start integration.)".
  const std::string& message() const { return message_; }
  /// Number of internal steps taken since construction.
  long steps() const;

 private:
  struct Handles;
  std::unique_ptr<Handles> h_;
  std::vector<int> root_info_;
  std::string message_;
};

}  // namespace hybrid
