#include "hybrid/simulation/simulator.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "solvers/simulation/compiled_model.h"
#include "solvers/simulation/event_loop.h"
#include "solvers/simulation/invariant_guard.h"
#include "solvers/simulation/option_validation.h"
#include "solvers/simulation/run_inputs.h"
#include "solvers/simulation/run_state.h"

namespace hybrid {

std::string_view StatusName(SimulationStatus status) {
  switch (status) {
    case SimulationStatus::kCompleted:
      return "completed";
    case SimulationStatus::kZeno:
      return "zeno";
    case SimulationStatus::kInvariantViolated:
      return "invariant_violated";
    case SimulationStatus::kSolverFailure:
      return "solver_failure";
    case SimulationStatus::kEventLimit:
      return "event_limit";
    case SimulationStatus::kStepLimit:
      return "step_limit";
    case SimulationStatus::kUnresolved:
      return "unresolved";
    case SimulationStatus::kStopped:
      return "stopped";
  }
  return "?";
}

Simulator::Simulator(const System& system) : model_(std::make_unique<CompiledModel>(system)) {}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;

const std::vector<std::string>& Simulator::variable_names() const {
  return model_->variable_names();
}
const System& Simulator::system() const { return model_->system(); }

std::string Simulator::ModeName(int component, int mode) const {
  return model_->ModeName(component, mode);
}

std::string Simulator::ModeLabel(std::span<const int> modes) const {
  return model_->ModeLabel(modes);
}

std::vector<double> Simulator::ParameterEnvironment(
    std::span<const std::pair<std::string, double>> parameters) const {
  return model_->ParameterEnvironment(parameters);
}

namespace {

// The first initial state of every component of `model`: x (max(1, number of variables)
// entries, variables without an initial value at 0) and the modes. Throws std::invalid_argument
// for an initial value that is not finite.
std::pair<Eigen::VectorXd, std::vector<int>> StartState(const CompiledModel& model) {
  const int n = static_cast<int>(model.variable_slots().size());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(std::max(n, 1));
  std::vector<int> modes;
  for (const CompiledComponent& cc : model.components()) {
    modes.push_back(cc.initial_mode);
    for (const auto& [index, value] : cc.initial_values) x[index] = value;
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      throw std::invalid_argument("initial value of '" + model.variable_names()[i] +
                                  "' is not finite");
    }
  }
  return {std::move(x), std::move(modes)};
}

// SimulationOptions::start_modes and start_x, checked against `model`: x as StartState gives it.
std::pair<Eigen::VectorXd, std::vector<int>> GivenStart(const CompiledModel& model,
                                                        const SimulationOptions& options) {
  const std::vector<CompiledComponent>& components = model.components();
  const std::vector<int>& modes = options.start_modes;
  bool fits = modes.size() == components.size();
  for (size_t c = 0; c < modes.size() && fits; ++c) {
    fits = modes[c] >= 0 && modes[c] < static_cast<int>(components[c].modes.size());
  }
  const int n = static_cast<int>(model.variable_slots().size());
  if (!fits || options.start_x.size() != n) {
    throw std::invalid_argument("the start state does not fit the model (" +
                                std::to_string(components.size()) + " modes and " +
                                std::to_string(n) + " variables expected)");
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(std::max(n, 1));
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(options.start_x[i])) {
      throw std::invalid_argument("start value of '" + model.variable_names()[i] +
                                  "' is not finite");
    }
    x[i] = options.start_x[i];
  }
  return {std::move(x), modes};
}

}  // namespace

SimulationResult Simulator::Run(const SimulationOptions& options,
                                std::span<const InputSignal> signals) const {
  const System& system = model_->system();
  const double until = Horizon(system, options);
  ValidateSimulationOptions(options, until);
  ValidateSampleTimes(options, until);
  const std::vector<InputSignal> inputs = MergedInputs(system, signals);
  ValidateInputs(system, inputs);
  std::vector<double> breakpoints = Breakpoints(inputs, until, options.lazy_schedule);
  auto [x, modes] =
      options.start_modes.empty() ? StartState(*model_) : GivenStart(*model_, options);

  RunState run(*model_, ParameterEnvironment(options.parameters), inputs, options);
  const double t = 0.0;
  run.SetStepInputs(t);
  run.SetModes(modes);
  run.Load(t, x.data());
  if (auto violated = run.ViolatedInvariant()) {
    throw std::invalid_argument(
        std::string(options.start_modes.empty() ? "the initial" : "the start") +
        " state violates the invariant '" + *violated + "' of mode " + ModeLabel(modes));
  }
  EventLoop loop(*model_, run, options, until, std::move(breakpoints), std::move(x));
  return loop.Simulate();
}

std::optional<std::string> Simulator::FirstStateOutsideInvariant(
    const SimulationResult& result, const SimulationOptions& options,
    std::span<const InputSignal> signals) const {
  const size_t n = model_->variable_slots().size();
  const std::vector<CompiledComponent>& components = model_->components();
  for (const StateSample& s : result.samples) {
    bool modes_ok = s.modes.size() == components.size();
    for (size_t c = 0; c < s.modes.size() && modes_ok; ++c) {
      modes_ok = s.modes[c] >= 0 && s.modes[c] < static_cast<int>(components[c].modes.size());
    }
    if (!modes_ok || static_cast<size_t>(s.x.size()) != n) {
      throw std::invalid_argument("a recorded state does not fit the model (modes or variables)");
    }
  }
  RunState run(*model_, ParameterEnvironment(options.parameters),
               MergedInputs(model_->system(), signals), options);
  const auto outside = StateOutsideInvariant(run, result.samples, *model_);
  if (!outside) return std::nullopt;
  return outside->second;
}

}  // namespace hybrid
