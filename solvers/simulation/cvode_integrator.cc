#include "solvers/simulation/cvode_integrator.h"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "hybrid/automaton/expression.h"

namespace hybrid {

struct CvodeIntegrator::Handles {
  OdeSystem* system = nullptr;
  int dimension = 0;
  int num_roots = 0;
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  N_Vector dky = nullptr;  // Interpolate's output, allocated once
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  SUNNonlinearSolver fixed_point = nullptr;  // Options::fixed_point_iteration only
  void* cvode = nullptr;
  bool initialised = false;
  Options options;
  // Steps taken towards `stop` since the last Restart or change of stop time (Options::max_steps).
  double stop = std::numeric_limits<double>::quiet_NaN();
  long steps_towards_stop = 0;
  double last_t = 0.0;  // the time of the state in `y`
  // The last message CVODE reported through its error handler (errors and warnings), which would
  // otherwise be printed to stderr; empty when none since the last Advance or Restart.
  std::string last_error;

  ~Handles() {
    if (cvode) CVodeFree(&cvode);
    if (fixed_point) SUNNonlinSolFree(fixed_point);
    if (solver) SUNLinSolFree(solver);
    if (matrix) SUNMatDestroy(matrix);
    if (dky) N_VDestroy(dky);
    if (y) N_VDestroy(y);
    if (context) SUNContext_Free(&context);
  }
};

namespace {

int Rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* h = static_cast<OdeSystem*>(user_data);
  h->Derivatives(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
  return 0;
}

int RootFunctions(sunrealtype t, N_Vector y, sunrealtype* gout, void* user_data) {
  static_cast<OdeSystem*>(user_data)->Roots(t, N_VGetArrayPointer(y), gout);
  return 0;
}

// CVODE's error handler: keeps the message (in the std::string at `data`) instead of printing
// it. Warnings (error_code > 0, such as "t + h = t on the next step") are kept the same way.
void RecordError(int error_code, const char* module, const char* function, char* msg, void* data) {
  (void)error_code;
  (void)module;
  (void)function;
  *static_cast<std::string*>(data) = msg ? msg : "";
}

// "FLAG_NAME (what CVODE said)" for a failed call. CVodeGetReturnFlagName returns memory from
// malloc that the caller owns.
std::string Describe(int flag, const std::string& detail) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string out = name != nullptr ? name : "flag " + std::to_string(flag);
  std::free(name);
  if (!detail.empty()) out += " (" + detail + ")";
  return out;
}

// Setup calls fail only on misuse or exhausted memory: an internal error.
void Check(int flag, const char* call, const std::string& detail) {
  if (flag < 0) {
    throw std::runtime_error(std::string("the ODE solver CVODE could not be set up (") + call +
                             ": " + Describe(flag, detail) + ")");
  }
}

}  // namespace

double InitialStepTarget(double t, double t_stop) {
  return std::min(t_stop, t + 1e3 * std::max(std::abs(t), 1.0));
}

CvodeIntegrator::CvodeIntegrator(OdeSystem* system, int dimension, const Options& options)
    : h_(std::make_unique<Handles>()) {
  if (system == nullptr || dimension < 1) {
    throw std::invalid_argument("the ODE solver needs a system and at least one state variable");
  }
  h_->system = system;
  h_->dimension = dimension;
  h_->options = options;
  if (SUNContext_Create(nullptr, &h_->context) != 0) {
    throw std::runtime_error("the ODE solver CVODE could not create its context");
  }
  h_->y = N_VNew_Serial(dimension, h_->context);
  h_->dky = N_VNew_Serial(dimension, h_->context);
  if (options.fixed_point_iteration) {
    h_->fixed_point = SUNNonlinSol_FixedPoint(h_->y, 0, h_->context);
  } else {
    h_->matrix = SUNDenseMatrix(dimension, dimension, h_->context);
    h_->solver = SUNLinSol_Dense(h_->y, h_->matrix, h_->context);
  }
  h_->cvode = CVodeCreate(CV_ADAMS, h_->context);
  const bool solver =
      options.fixed_point_iteration ? h_->fixed_point != nullptr : h_->matrix && h_->solver;
  if (!h_->y || !h_->dky || !solver || !h_->cvode) {
    throw std::runtime_error("the ODE solver CVODE could not allocate its vectors and matrices");
  }
  // The library never prints: CVODE's messages are kept and reported through message(). Handles
  // lives on the heap, so the address of last_error survives moves of the integrator.
  Check(CVodeSetErrHandlerFn(h_->cvode, RecordError, &h_->last_error), "CVodeSetErrHandlerFn", "");
}

CvodeIntegrator::~CvodeIntegrator() = default;
CvodeIntegrator::CvodeIntegrator(CvodeIntegrator&&) noexcept = default;
CvodeIntegrator& CvodeIntegrator::operator=(CvodeIntegrator&&) noexcept = default;

void CvodeIntegrator::Restart(double t0, const Eigen::VectorXd& x0,
                              std::span<const int> directions) {
  double* y = N_VGetArrayPointer(h_->y);
  for (int i = 0; i < h_->dimension; ++i) y[i] = i < x0.size() ? x0[i] : 0.0;
  h_->last_error.clear();
  auto check = [&](int flag, const char* call) { Check(flag, call, h_->last_error); };
  if (!h_->initialised) {
    check(CVodeInit(h_->cvode, Rhs, t0, h_->y), "CVodeInit");
    check(CVodeSetUserData(h_->cvode, h_->system), "CVodeSetUserData");
    check(CVodeSStolerances(h_->cvode, h_->options.relative_tolerance,
                            h_->options.absolute_tolerance),
          "CVodeSStolerances");
    if (h_->fixed_point) {
      check(CVodeSetNonlinearSolver(h_->cvode, h_->fixed_point), "CVodeSetNonlinearSolver");
    } else {
      check(CVodeSetLinearSolver(h_->cvode, h_->solver, h_->matrix), "CVodeSetLinearSolver");
    }
    check(CVodeSetMaxNumSteps(h_->cvode, h_->options.max_steps), "CVodeSetMaxNumSteps");
    if (h_->options.max_step > 0.0 && std::isfinite(h_->options.max_step)) {
      check(CVodeSetMaxStep(h_->cvode, h_->options.max_step), "CVodeSetMaxStep");
    }
    check(CVodeSetNoInactiveRootWarn(h_->cvode), "CVodeSetNoInactiveRootWarn");
    h_->initialised = true;
  } else {
    check(CVodeReInit(h_->cvode, t0, h_->y), "CVodeReInit");
  }
  h_->num_roots = static_cast<int>(directions.size());
  check(CVodeRootInit(h_->cvode, h_->num_roots, h_->num_roots > 0 ? RootFunctions : nullptr),
        "CVodeRootInit");
  if (h_->num_roots > 0) {
    std::vector<int> dirs(directions.begin(), directions.end());
    check(CVodeSetRootDirection(h_->cvode, dirs.data()), "CVodeSetRootDirection");
  }
  root_info_.assign(h_->num_roots, 0);
  h_->steps_towards_stop = 0;
  h_->last_t = t0;
}

CvodeIntegrator::Status CvodeIntegrator::Advance(double t_stop, double* t, Eigen::VectorXd* x) {
  h_->last_error.clear();
  const int stop_flag = CVodeSetStopTime(h_->cvode, t_stop);
  if (stop_flag < 0) {
    message_ = "CVODE refused the stop time " + FormatNumber(t_stop) + ": " +
               Describe(stop_flag, h_->last_error);
    *t = h_->last_t;
    x->resize(h_->dimension);
    const double* y = N_VGetArrayPointer(h_->y);
    for (int i = 0; i < h_->dimension; ++i) (*x)[i] = y[i];
    return Status::kFailure;
  }
  if (!(t_stop == h_->stop)) {
    h_->stop = t_stop;
    h_->steps_towards_stop = 0;
  }
  if (++h_->steps_towards_stop > h_->options.max_steps) {
    message_ = "CVODE failed: CV_TOO_MUCH_WORK (more than " +
               std::to_string(h_->options.max_steps) +
               " steps towards t = " + FormatNumber(t_stop) + ")";
    *t = h_->last_t;
    x->resize(h_->dimension);
    const double* y = N_VGetArrayPointer(h_->y);
    for (int i = 0; i < h_->dimension; ++i) (*x)[i] = y[i];
    return Status::kFailure;
  }
  sunrealtype reached = 0.0;
  const int flag =
      CVode(h_->cvode, InitialStepTarget(h_->last_t, t_stop), h_->y, &reached, CV_ONE_STEP);
  *t = reached;
  h_->last_t = reached;
  x->resize(h_->dimension);
  const double* y = N_VGetArrayPointer(h_->y);
  for (int i = 0; i < h_->dimension; ++i) (*x)[i] = y[i];
  if (flag == CV_ROOT_RETURN) {
    CVodeGetRootInfo(h_->cvode, root_info_.data());
    return Status::kRoot;
  }
  if (flag < 0) {
    message_ = "CVODE failed: " + Describe(flag, h_->last_error);
    return Status::kFailure;
  }
  return flag == CV_TSTOP_RETURN || reached >= t_stop ? Status::kReachedTime : Status::kStep;
}

bool CvodeIntegrator::Interpolate(double t, Eigen::VectorXd* x) {
  const int flag = CVodeGetDky(h_->cvode, t, 0, h_->dky);
  if (flag == CV_SUCCESS) {
    x->resize(h_->dimension);
    const double* y = N_VGetArrayPointer(h_->dky);
    for (int i = 0; i < h_->dimension; ++i) (*x)[i] = y[i];
  }
  return flag == CV_SUCCESS;
}

long CvodeIntegrator::steps() const {
  long n = 0;
  if (h_->initialised) CVodeGetNumSteps(h_->cvode, &n);
  return n;
}

}  // namespace hybrid
