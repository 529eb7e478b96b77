// Tests of the CVODE RAII wrapper on its own (solvers/simulation/cvode_integrator.h): accuracy on
// x' = -x, root location with crossing directions, restarts with another number of root functions,
// interpolation inside the last step, run-time failures reported as a status (leaking nothing),
// CVODE messages kept for message() instead of printed, and a first step that does not depend on
// how far away the stop time is.

#include "solvers/simulation/cvode_integrator.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hybrid {
namespace {

// An OdeSystem given by two callables, with a root-function count the test can change.
class FunctionSystem final : public OdeSystem {
 public:
  using Rhs = std::function<void(double, const double*, double*)>;
  using RootFn = std::function<double(double, const double*)>;

  explicit FunctionSystem(Rhs rhs) : rhs_(std::move(rhs)) {}

  void Derivatives(double t, const double* x, double* dxdt) override {
    ++rhs_calls_;
    rhs_(t, x, dxdt);
  }
  void Roots(double t, const double* x, double* g) override {
    for (size_t i = 0; i < roots_.size(); ++i) g[i] = roots_[i](t, x);
  }
  void SetRoots(std::vector<RootFn> roots) { roots_ = std::move(roots); }
  long rhs_calls() const { return rhs_calls_; }

 private:
  Rhs rhs_;
  std::vector<RootFn> roots_;
  long rhs_calls_ = 0;
};

Eigen::VectorXd Vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double d : v) x[i++] = d;
  return x;
}

// Advances until `t_stop`, a root or a failure; returns the last status.
CvodeIntegrator::Status AdvanceUntil(CvodeIntegrator& integrator, double t_stop, double* t,
                                     Eigen::VectorXd* x, int max_calls = 1000000) {
  CvodeIntegrator::Status status = CvodeIntegrator::Status::kStep;
  for (int i = 0; i < max_calls; ++i) {
    status = integrator.Advance(t_stop, t, x);
    if (status != CvodeIntegrator::Status::kStep) return status;
  }
  ADD_FAILURE() << "no progress to t = " << t_stop << " after " << max_calls << " steps";
  return status;
}

// x = cos t, v = -sin t.
FunctionSystem Oscillator() {
  return FunctionSystem([](double, const double* x, double* dx) {
    dx[0] = x[1];
    dx[1] = -x[0];
  });
}

TEST(CvodeIntegratorTest, RejectsNullSystemAndEmptyDimension) {
  FunctionSystem s([](double, const double*, double* dx) { dx[0] = 0.0; });
  EXPECT_THROW(CvodeIntegrator(nullptr, 1, {}), std::invalid_argument);
  EXPECT_THROW(CvodeIntegrator(&s, 0, {}), std::invalid_argument);
  EXPECT_THROW(CvodeIntegrator(&s, -3, {}), std::invalid_argument);
}

TEST(CvodeIntegratorTest, IntegratesExponentialDecayAccurately) {
  FunctionSystem decay([](double, const double* x, double* dx) { dx[0] = -x[0]; });
  CvodeIntegrator integrator(&decay, 1, {});
  integrator.Restart(0.0, Vec({1.0}), {});
  double t = 0.0;
  Eigen::VectorXd x;
  for (double stop : {0.5, 1.0, 2.0, 5.0, 10.0}) {
    ASSERT_EQ(AdvanceUntil(integrator, stop, &t, &x), CvodeIntegrator::Status::kReachedTime);
    EXPECT_EQ(t, stop);  // never past the stop time
    ASSERT_EQ(x.size(), 1);
    EXPECT_NEAR(x[0], std::exp(-stop), 1e-8 * std::exp(-stop) + 1e-11) << "t = " << stop;
  }
  EXPECT_GT(integrator.steps(), 10);
  EXPECT_GT(decay.rhs_calls(), integrator.steps());
}

// Fixed-point iteration (Options::fixed_point_iteration) on a non-stiff rotation, x'' = -x:
// the same accuracy against cos t and sin t as Newton's method.
TEST(CvodeIntegratorTest, FixedPointIterationIntegratesARotationAccurately) {
  for (int fixed_point = 0; fixed_point < 2; ++fixed_point) {
    FunctionSystem rotation([](double, const double* x, double* dx) {
      dx[0] = x[1];
      dx[1] = -x[0];
    });
    CvodeIntegrator::Options options;
    options.fixed_point_iteration = fixed_point == 1;
    CvodeIntegrator integrator(&rotation, 2, options);
    integrator.Restart(0.0, Vec({1.0, 0.0}), {});
    double t = 0.0;
    Eigen::VectorXd x;
    for (double stop : {1.0, 5.0, 20.0}) {
      ASSERT_EQ(AdvanceUntil(integrator, stop, &t, &x), CvodeIntegrator::Status::kReachedTime);
      EXPECT_NEAR(x[0], std::cos(stop), 1e-8) << "fixed point " << fixed_point << " t " << stop;
      EXPECT_NEAR(x[1], -std::sin(stop), 1e-8) << "fixed point " << fixed_point << " t " << stop;
    }
    EXPECT_GT(integrator.steps(), 10);
  }
}

TEST(CvodeIntegratorTest, OneStepModeReportsIntermediateSteps) {
  FunctionSystem decay([](double, const double* x, double* dx) { dx[0] = -x[0]; });
  CvodeIntegrator integrator(&decay, 1, {});
  integrator.Restart(0.0, Vec({1.0}), {});
  double t = 0.0, t_prev = 0.0;
  Eigen::VectorXd x;
  int steps = 0;
  CvodeIntegrator::Status status;
  while ((status = integrator.Advance(3.0, &t, &x)) == CvodeIntegrator::Status::kStep) {
    EXPECT_GT(t, t_prev);
    EXPECT_LT(t, 3.0);
    EXPECT_NEAR(x[0], std::exp(-t), 1e-8);
    t_prev = t;
    ++steps;
  }
  EXPECT_EQ(status, CvodeIntegrator::Status::kReachedTime);
  EXPECT_GT(steps, 3);
  EXPECT_EQ(integrator.steps(), steps + 1);
}

TEST(CvodeIntegratorTest, LocatesRootInRequestedDirectionOnly) {
  FunctionSystem osc = Oscillator();
  // g0 = x: falls through 0 at pi/2, rises at 3 pi/2. g1 = x - 2 never crosses.
  osc.SetRoots({[](double, const double* x) { return x[0]; },
                [](double, const double* x) { return x[0] - 2.0; }});
  CvodeIntegrator integrator(&osc, 2, {});
  integrator.Restart(0.0, Vec({1.0, 0.0}), std::vector<int>{+1, 0});
  double t = 0.0;
  Eigen::VectorXd x;
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  // The falling crossing at pi/2 is ignored; the rising one at 3 pi/2 is reported.
  EXPECT_NEAR(t, 1.5 * std::numbers::pi, 1e-9);
  ASSERT_EQ(integrator.root_info().size(), 2u);
  EXPECT_EQ(integrator.root_info()[0], +1);
  EXPECT_EQ(integrator.root_info()[1], 0);
  EXPECT_NEAR(x[0], 0.0, 1e-9);
  EXPECT_NEAR(x[1], 1.0, 1e-9);

  // The same function with direction -1: reported at pi/2, as a falling crossing.
  integrator.Restart(0.0, Vec({1.0, 0.0}), std::vector<int>{-1, 0});
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 0.5 * std::numbers::pi, 1e-9);
  EXPECT_EQ(integrator.root_info()[0], -1);

  // Direction 0: both crossings, in order.
  integrator.Restart(0.0, Vec({1.0, 0.0}), std::vector<int>{0, 0});
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 0.5 * std::numbers::pi, 1e-9);
  EXPECT_EQ(integrator.root_info()[0], -1);
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 1.5 * std::numbers::pi, 1e-9);
  EXPECT_EQ(integrator.root_info()[0], +1);
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 2.5 * std::numbers::pi, 1e-9);
  // No more roots before the stop time.
  EXPECT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  EXPECT_EQ(t, 10.0);
  EXPECT_NEAR(x[0], std::cos(10.0), 1e-8);
}

TEST(CvodeIntegratorTest, RestartChangesTheNumberOfRootsAndTheState) {
  // x' = 1 (a clock).
  FunctionSystem clock([](double, const double*, double* dx) { dx[0] = 1.0; });
  clock.SetRoots({[](double, const double* x) { return x[0] - 1.0; }});
  CvodeIntegrator integrator(&clock, 1, {});
  integrator.Restart(0.0, Vec({0.0}), std::vector<int>{+1});
  double t = 0.0;
  Eigen::VectorXd x;
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 1.0, 1e-12);
  ASSERT_EQ(integrator.root_info().size(), 1u);

  // Three root functions now, and a jump of the state (x := 5).
  clock.SetRoots({[](double, const double* x) { return x[0] - 5.0; },  // zero at the restart
                  [](double, const double* x) { return x[0] - 7.5; },
                  [](double, const double* x) { return x[0] - 6.0; }});
  integrator.Restart(t, Vec({5.0}), std::vector<int>{0, +1, +1});
  EXPECT_EQ(integrator.root_info().size(), 3u);
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 2.0, 1e-12);  // x = 5 + (t - 1) reaches 6
  EXPECT_EQ(integrator.root_info(), (std::vector<int>{0, 0, +1}));
  ASSERT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kRoot);
  EXPECT_NEAR(t, 3.5, 1e-12);
  EXPECT_EQ(integrator.root_info(), (std::vector<int>{0, +1, 0}));

  // No root functions at all.
  clock.SetRoots({});
  integrator.Restart(t, x, {});
  EXPECT_TRUE(integrator.root_info().empty());
  EXPECT_EQ(AdvanceUntil(integrator, 10.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  EXPECT_NEAR(x[0], 7.5 + 6.5, 1e-10);
}

TEST(CvodeIntegratorTest, InterpolatesInsideTheLastStepOnly) {
  FunctionSystem osc = Oscillator();
  CvodeIntegrator integrator(&osc, 2, {});
  integrator.Restart(0.0, Vec({1.0, 0.0}), {});
  double t = 0.0, t_prev = 0.0;
  Eigen::VectorXd x, y;
  // Take steps until one is long enough to make interior points meaningful.
  for (int i = 0; i < 1000 && t - t_prev < 1e-2; ++i) {
    t_prev = t;
    ASSERT_EQ(integrator.Advance(20.0, &t, &x), CvodeIntegrator::Status::kStep);
  }
  ASSERT_GT(t - t_prev, 1e-2);
  for (double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double s = t_prev + f * (t - t_prev);
    ASSERT_TRUE(integrator.Interpolate(s, &y)) << "s = " << s;
    ASSERT_EQ(y.size(), 2);
    EXPECT_NEAR(y[0], std::cos(s), 1e-8) << "s = " << s;
    EXPECT_NEAR(y[1], -std::sin(s), 1e-8) << "s = " << s;
  }
  ASSERT_TRUE(integrator.Interpolate(t, &y));
  EXPECT_EQ(y, x);  // the step end is the returned state
  // Outside the last step: refused, and the output is left alone.
  y = Vec({42.0, 43.0});
  EXPECT_FALSE(integrator.Interpolate(t + 10.0 * (t - t_prev) + 1.0, &y));
  EXPECT_FALSE(integrator.Interpolate(t_prev - 10.0 * (t - t_prev) - 1.0, &y));
  EXPECT_EQ(y, Vec({42.0, 43.0}));
}

TEST(CvodeIntegratorTest, BlowUpIsAFailureStatusNotAnException) {
  // x' = x^2 from x = 1: x = 1 / (1 - t) blows up at t = 1.
  FunctionSystem blow([](double, const double* x, double* dx) { dx[0] = x[0] * x[0]; });
  CvodeIntegrator integrator(&blow, 1, {});
  integrator.Restart(0.0, Vec({1.0}), {});
  double t = 0.0;
  Eigen::VectorXd x;
  CvodeIntegrator::Status status = CvodeIntegrator::Status::kStep;
  ASSERT_NO_THROW(status = AdvanceUntil(integrator, 2.0, &t, &x));
  EXPECT_EQ(status, CvodeIntegrator::Status::kFailure);
  EXPECT_FALSE(integrator.message().empty());
  EXPECT_NE(integrator.message().find("CV"), std::string::npos) << integrator.message();
  EXPECT_LT(t, 1.0);
  EXPECT_GT(t, 0.99);

  // The integrator is usable again after a restart.
  integrator.Restart(0.0, Vec({-1.0}), {});  // x = -1 / (1 + t): no blow-up forwards
  ASSERT_EQ(AdvanceUntil(integrator, 2.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  EXPECT_NEAR(x[0], -1.0 / 3.0, 1e-9);
}

TEST(CvodeIntegratorTest, CollapsingStepsEndAsFailureAfterMaxSteps) {
  // The derivative turns NaN at t = 0.5: CVODE shrinks its step below roundoff and would stay at
  // t = 0.5 for ever; the wrapper gives up after max_steps steps towards the same stop time.
  FunctionSystem nan([](double t, const double*, double* dx) {
    dx[0] = t < 0.5 ? 1.0 : std::numeric_limits<double>::quiet_NaN();
  });
  CvodeIntegrator::Options options;
  options.max_steps = 2000;
  CvodeIntegrator integrator(&nan, 1, options);
  integrator.Restart(0.0, Vec({0.0}), {});
  double t = 0.0;
  Eigen::VectorXd x;
  EXPECT_EQ(AdvanceUntil(integrator, 2.0, &t, &x, 10 * options.max_steps),
            CvodeIntegrator::Status::kFailure);
  EXPECT_NE(integrator.message().find("CV_TOO_MUCH_WORK"), std::string::npos)
      << integrator.message();
  EXPECT_NEAR(t, 0.5, 1e-9);
  ASSERT_EQ(x.size(), 1);
  EXPECT_NEAR(x[0], t, 1e-9);  // the state at the returned time

  // A sliding mode: x' = -sign(x) chatters around 0 with steps of about 1e-13.
  FunctionSystem sliding([](double, const double* x, double* dx) {
    dx[0] = x[0] > 0.0 ? -1.0 : (x[0] < 0.0 ? 1.0 : 0.0);
  });
  CvodeIntegrator chatter(&sliding, 1, options);
  chatter.Restart(0.0, Vec({0.5}), {});
  EXPECT_EQ(AdvanceUntil(chatter, 5.0, &t, &x, 10 * options.max_steps),
            CvodeIntegrator::Status::kFailure);
  EXPECT_NE(chatter.message().find("CV_TOO_MUCH_WORK"), std::string::npos);
  EXPECT_NEAR(t, 0.5, 1e-6);
}

TEST(CvodeIntegratorTest, MaxStepsCountsStepsTowardsOneStopTime) {
  FunctionSystem clock([](double, const double*, double* dx) { dx[0] = 1.0; });
  CvodeIntegrator::Options options;
  options.max_step = 0.1;
  options.max_steps = 30;
  CvodeIntegrator integrator(&clock, 1, options);
  integrator.Restart(0.0, Vec({0.0}), {});
  double t = 0.0;
  Eigen::VectorXd x;
  // Many short hops, each well within the limit: never a failure.
  for (int k = 1; k <= 40; ++k) {
    ASSERT_EQ(AdvanceUntil(integrator, 0.5 * k, &t, &x), CvodeIntegrator::Status::kReachedTime)
        << integrator.message();
  }
  EXPECT_GT(integrator.steps(), 30);
  // One far stop time needs about 100 steps of 0.1: refused after 30.
  EXPECT_EQ(AdvanceUntil(integrator, 30.0, &t, &x), CvodeIntegrator::Status::kFailure);
  EXPECT_NE(integrator.message().find("CV_TOO_MUCH_WORK"), std::string::npos);
  EXPECT_GT(t, 20.0);
  EXPECT_LT(t, 30.0);
  EXPECT_NEAR(x[0], t, 1e-10);
  // A restart resets the count.
  integrator.Restart(t, x, {});
  EXPECT_EQ(integrator.Advance(30.0, &t, &x), CvodeIntegrator::Status::kStep);
}

TEST(CvodeIntegratorTest, MaxStepBoundsTheInternalSteps) {
  FunctionSystem clock([](double, const double*, double* dx) { dx[0] = 1.0; });
  CvodeIntegrator::Options options;
  options.max_step = 0.25;
  CvodeIntegrator integrator(&clock, 1, options);
  integrator.Restart(0.0, Vec({0.0}), {});
  double t = 0.0, t_prev = 0.0;
  Eigen::VectorXd x;
  CvodeIntegrator::Status status;
  while ((status = integrator.Advance(10.0, &t, &x)) == CvodeIntegrator::Status::kStep) {
    EXPECT_LE(t - t_prev, 0.25 * (1 + 1e-12));
    t_prev = t;
  }
  EXPECT_EQ(status, CvodeIntegrator::Status::kReachedTime);
  EXPECT_LE(t - t_prev, 0.25 * (1 + 1e-12));
  EXPECT_GE(integrator.steps(), 40);
  EXPECT_NEAR(x[0], 10.0, 1e-10);
}

TEST(CvodeIntegratorTest, CvodeMessagesAreKeptNotPrinted) {
  FunctionSystem clock([](double, const double*, double* dx) { dx[0] = 1.0; });
  CvodeIntegrator integrator(&clock, 1, {});
  double t = 0.0;
  Eigen::VectorXd x;
  ::testing::internal::CaptureStderr();
  // A stop time one ulp after the restart time: CVODE cannot start (CV_TOO_CLOSE).
  integrator.Restart(1.0, Vec({0.0}), {});
  const CvodeIntegrator::Status status = integrator.Advance(std::nextafter(1.0, 2.0), &t, &x);
  // Steps below the resolution of t (t + h = t warnings) as x' = x^2 blows up at t = 1.
  FunctionSystem blow([](double, const double* y, double* dy) { dy[0] = y[0] * y[0]; });
  CvodeIntegrator blow_up(&blow, 1, {});
  blow_up.Restart(0.0, Vec({1.0}), {});
  double tb = 0.0;
  Eigen::VectorXd xb;
  const CvodeIntegrator::Status blow_status = AdvanceUntil(blow_up, 2.0, &tb, &xb);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(status, CvodeIntegrator::Status::kFailure);
  EXPECT_NE(integrator.message().find("CV_TOO_CLOSE"), std::string::npos) << integrator.message();
  EXPECT_NE(integrator.message().find("tout too close to t0"), std::string::npos)
      << integrator.message();
  EXPECT_EQ(t, 1.0);  // where it stayed
  EXPECT_EQ(blow_status, CvodeIntegrator::Status::kFailure);
  EXPECT_FALSE(blow_up.message().empty());
  // Still usable: a restart and a reachable stop time.
  integrator.Restart(1.0, Vec({0.0}), {});
  ASSERT_EQ(AdvanceUntil(integrator, 2.0, &t, &x), CvodeIntegrator::Status::kReachedTime)
      << integrator.message();
  EXPECT_NEAR(x[0], 1.0, 1e-12);
}

TEST(CvodeIntegratorTest, FirstStepIsSizedNearTheCurrentTimeNotTheStopTime) {
  EXPECT_EQ(InitialStepTarget(0.0, 1e50), 1000.0);
  EXPECT_EQ(InitialStepTarget(60.0, 100.0), 100.0);
  EXPECT_EQ(InitialStepTarget(1e6, 1e50), 1e6 + 1e9);
  EXPECT_EQ(InitialStepTarget(-5.0, 1e50), 4995.0);
  // x' = -0.1 x (time scale 10) restarted at t = 60 towards a stop time of 1e20 or 1e50: the
  // trajectory is the analytic one and every step stays within the time scale. (Sized towards
  // the stop time, CVODE's first step is at least 100 * unit roundoff * 1e50 = 2e36: the run
  // failed at 1e20 and jumped to x = 0 at 1e50.)
  FunctionSystem decay([](double, const double* x, double* dx) { dx[0] = -0.1 * x[0]; });
  for (double stop : {1e3, 1e20, 1e50, 1e300}) {
    SCOPED_TRACE(stop);
    CvodeIntegrator integrator(&decay, 1, {});
    integrator.Restart(60.0, Vec({20.0}), {});
    double t = 60.0, t_prev = 60.0;
    Eigen::VectorXd x;
    while (t < 200.0) {
      ASSERT_EQ(integrator.Advance(stop, &t, &x), CvodeIntegrator::Status::kStep)
          << integrator.message();
      EXPECT_LT(t - t_prev, 10.0);
      EXPECT_NEAR(x[0], 20.0 * std::exp(-0.1 * (t - 60.0)), 1e-7);
      t_prev = t;
    }
  }
}

TEST(CvodeIntegratorTest, FailuresLeakNothingAndSpeakOfTheSolver) {
  // Each failure names CVODE's return flag (CVodeGetReturnFlagName allocates the name). Under
  // LeakSanitizer (HYBRID_SANITIZE) a lost name fails the test binary; here the heap in use must
  // not grow with the number of failures either.
  FunctionSystem clock([](double, const double*, double* dx) { dx[0] = 1.0; });
  CvodeIntegrator integrator(&clock, 1, {});
  double t = 0.0;
  Eigen::VectorXd x;
  auto fail_once = [&] {
    integrator.Restart(1.0, Vec({0.0}), {});
    return integrator.Advance(std::nextafter(1.0, 2.0), &t, &x);  // CV_TOO_CLOSE
  };
  ASSERT_EQ(fail_once(), CvodeIntegrator::Status::kFailure);
  const std::string message = integrator.message();
  EXPECT_NE(message.find("CVODE"), std::string::npos) << message;
  EXPECT_NE(message.find("CV_TOO_CLOSE"), std::string::npos) << message;
  EXPECT_EQ(message.find("::"), std::string::npos) << message;
  const size_t before = mallinfo2().uordblks;
  for (int i = 0; i < 10000; ++i) ASSERT_EQ(fail_once(), CvodeIntegrator::Status::kFailure);
  const size_t after = mallinfo2().uordblks;
  // 10000 lost names would be 240 kB or more (sanitizers keep their own books: 0 here).
  EXPECT_LT(after, before + 10000) << "heap grew by " << after - before << " bytes";
  try {
    CvodeIntegrator none(nullptr, 1, {});
    ADD_FAILURE() << "accepted a null system";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find("::"), std::string::npos) << e.what();
  }
}

TEST(CvodeIntegratorTest, MovedIntegratorKeepsWorking) {
  FunctionSystem decay([](double, const double* x, double* dx) { dx[0] = -x[0]; });
  CvodeIntegrator a(&decay, 1, {});
  a.Restart(0.0, Vec({2.0}), {});
  double t = 0.0;
  Eigen::VectorXd x;
  ASSERT_EQ(AdvanceUntil(a, 1.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  CvodeIntegrator b(std::move(a));
  ASSERT_EQ(AdvanceUntil(b, 2.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  EXPECT_NEAR(x[0], 2.0 * std::exp(-2.0), 1e-8);
  CvodeIntegrator c(&decay, 1, {});
  c = std::move(b);
  ASSERT_EQ(AdvanceUntil(c, 3.0, &t, &x), CvodeIntegrator::Status::kReachedTime);
  EXPECT_NEAR(x[0], 2.0 * std::exp(-3.0), 1e-8);
}

}  // namespace
}  // namespace hybrid
