#include "solvers/simulation/compiled_model.h"

#include <cmath>
#include <optional>
#include <stdexcept>

namespace hybrid {

namespace {

// Marks in `fixed` every parameter that a fixed one is defined from (`p = 2 * q`: q changes p).
// Definitions read only earlier parameters, so one pass backwards reaches them all.
void FixDefiningParameters(const System& system, std::vector<char>& fixed) {
  for (const Component& comp : system.components()) {
    const auto& parameters = comp.automaton.parameters();
    for (auto it = parameters.rbegin(); it != parameters.rend(); ++it) {
      if (!fixed[comp.global_slot[it->first]]) continue;
      for (const int slot : it->second.Slots()) fixed[comp.global_slot[slot]] = 1;
    }
  }
}

[[noreturn]] void BadParameter(const std::string& message) { throw std::invalid_argument(message); }

// Component `comp`'s parameters with `value` (System slot -> a value set for the run) in place
// of their definitions, into `env` (System slots); checked as Automaton::SetParameter checks.
void EvaluateParameters(const Component& comp, const std::vector<std::optional<double>>& value,
                        std::vector<double>& env) {
  const Automaton& a = comp.automaton;
  std::vector<std::pair<int, double>> set;
  std::string setting;
  for (const auto& [slot, definition] : a.parameters()) {
    if (const std::optional<double>& v = value[comp.global_slot[slot]]) {
      set.emplace_back(slot, *v);
      setting += (setting.empty() ? "setting '" : ", '") + a.symbols()[slot].name + "' to " +
                 FormatNumber(*v);
    }
  }
  if (set.empty()) return;
  const std::vector<double> local = a.ParameterEnvironment(set, setting + " for the run");
  for (const auto& [slot, definition] : a.parameters()) env[comp.global_slot[slot]] = local[slot];
}

}  // namespace

CompiledModel::CompiledModel(const System& system) : system_(system) {
  const SymbolTable& symbols = system.symbols();
  std::vector<int> x_index(symbols.size(), -1);
  for (int s = 0; s < symbols.size(); ++s) {
    if (symbols[s].kind == SymbolKind::kVariable) {
      x_index[s] = static_cast<int>(variable_slots_.size());
      variable_slots_.push_back(s);
      variable_names_.push_back(symbols[s].name);
    }
  }
  parameter_env_.assign(symbols.size(), 0.0);
  for (const Component& comp : system.components()) {
    const Automaton& a = comp.automaton;
    const std::vector<double> local_env = a.ParameterEnvironment();
    for (const auto& [slot, value] : a.parameters()) {
      parameter_env_[comp.global_slot[slot]] = local_env[slot];
    }
  }
  fixed_.assign(symbols.size(), 0);
  for (int c = 0; c < static_cast<int>(system.components().size()); ++c) {
    const Component& comp = system.components()[static_cast<std::size_t>(c)];
    components_.push_back(CompileComponent(symbols, comp, x_index, parameter_env_, fixed_));
    components_.back().alphabet = system.Alphabet(c);  // the IR's synchronisation alphabet
  }
  FixDefiningParameters(system, fixed_);
}

std::vector<double> CompiledModel::ParameterEnvironment(
    std::span<const std::pair<std::string, double>> parameters) const {
  std::vector<double> env = parameter_env_;
  if (parameters.empty()) return env;
  std::vector<std::optional<double>> value(static_cast<size_t>(system_.symbols().size()));
  for (const auto& [name, v] : parameters) {
    const std::optional<int> slot = system_.symbols().Find(name);
    if (!slot || system_.symbols()[*slot].kind != SymbolKind::kParameter) {
      BadParameter("'" + name + "' is not a parameter of the model");
    }
    if (!std::isfinite(v)) BadParameter("value of parameter '" + name + "' is not finite");
    if (fixed_[*slot]) {
      BadParameter("parameter '" + name +
                   "' cannot be set for a run: an initial value reads it, or it scales a "
                   "variable in a guard or invariant (set it in the model)");
    }
    value[*slot] = v;
  }
  for (const Component& comp : system_.components()) EvaluateParameters(comp, value, env);
  return env;
}

std::string CompiledModel::ModeName(int component, int mode) const {
  const CompiledComponent& cc = components_.at(component);
  return cc.instance.empty() ? cc.mode_names.at(mode) : cc.instance + "." + cc.mode_names.at(mode);
}

std::string CompiledModel::ModeLabel(std::span<const int> modes) const {
  std::string out;
  for (size_t c = 0; c < modes.size(); ++c) {
    out += (c > 0 ? "|" : "") + ModeName(static_cast<int>(c), modes[c]);
  }
  return out;
}

}  // namespace hybrid
