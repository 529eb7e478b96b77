#include "hybrid/checking/trace.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hybrid {

std::vector<UncertainParameter> UncertainParameters(const System& system) {
  std::vector<UncertainParameter> out;
  for (const Component& c : system.components()) {
    const Automaton& a = c.automaton;
    const std::vector<double> env = a.ParameterEnvironment();
    for (const auto& [slot, value] : a.parameters()) {
      const std::optional<Range> range = a.ParameterRange(slot);
      if (!range) continue;
      const std::string& name = system.symbols()[c.global_slot[slot]].name;
      if (std::any_of(out.begin(), out.end(), [&](const auto& p) { return p.name == name; })) {
        continue;  // a shared parameter: one entry
      }
      out.push_back({name, env[slot], range->lo.Evaluate(env), range->hi.Evaluate(env)});
    }
  }
  return out;
}

namespace {

// The System environment of a recorded state: parameters, continuous and discrete variables.
std::vector<double> StateEnvironment(const Simulator& simulator, const StateSample& sample) {
  const System& system = simulator.system();
  std::vector<double> env(system.symbols().size(), 0.0);
  for (const Component& c : system.components()) {
    const std::vector<double> local = c.automaton.ParameterEnvironment();
    for (const auto& [slot, value] : c.automaton.parameters())
      env[c.global_slot[slot]] = local[slot];
  }
  const auto& names = simulator.variable_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (auto slot = system.symbols().Find(names[i])) env[*slot] = sample.x[static_cast<int>(i)];
  }
  for (std::size_t ci = 0; ci < system.components().size(); ++ci) {
    const Component& c = system.components()[ci];
    const Mode& mode = c.automaton.mode(ModeId(sample.modes[ci]));
    for (const auto& [slot, value] : mode.discrete_values) env[c.global_slot[slot]] = value;
  }
  return env;
}

// Whether `sample` lies in its modes' invariants, each comparison within `tol` times (1 + the
// magnitudes of its sides). Comparisons that read an input (not recorded) are not checked.
bool InsideInvariants(const Simulator& simulator, const StateSample& sample, double tol) {
  const System& system = simulator.system();
  const std::vector<double> env = StateEnvironment(simulator, sample);
  for (std::size_t ci = 0; ci < system.components().size(); ++ci) {
    const Component& c = system.components()[ci];
    const Automaton& a = c.automaton;
    std::vector<double> local(static_cast<std::size_t>(a.symbols().size()), 0.0);
    for (std::size_t s = 0; s < local.size(); ++s) local[s] = env[c.global_slot[s]];
    for (const Comparison& cmp : a.mode(ModeId(sample.modes[ci])).invariant.comparisons) {
      bool reads_input = false;
      for (const Expression* side : {&cmp.lhs, &cmp.rhs}) {
        for (int slot : side->Slots()) {
          reads_input = reads_input || a.symbols()[slot].kind == SymbolKind::kInput;
        }
      }
      if (reads_input) continue;
      const double scale =
          1.0 + std::abs(cmp.lhs.Evaluate(local)) + std::abs(cmp.rhs.Evaluate(local));
      if (!cmp.Holds(local, tol * scale, Boundary::kClosure)) return false;  // invariants: closure
    }
  }
  return true;
}

std::vector<std::string> ModeNames(const Simulator& simulator, const StateSample& sample) {
  std::vector<std::string> out;
  for (std::size_t c = 0; c < sample.modes.size(); ++c) {
    out.push_back(simulator.ModeName(static_cast<int>(c), sample.modes[c]));
  }
  return out;
}

}  // namespace

bool IsTarget(const Simulator& simulator, const Property& property, const StateSample& sample,
              double tolerance) {
  const std::vector<double> env = StateEnvironment(simulator, sample);
  const std::vector<std::string> modes = ModeNames(simulator, sample);
  switch (property.kind) {
    case Property::Kind::kAlways:
      return !property.predicate.Lenient(env, modes, tolerance);
    case Property::Kind::kNever:
      return !Predicate::Not(property.predicate).Lenient(env, modes, tolerance);
    case Property::Kind::kReach:
      // A witness meets the target clear of rounding: non-strict comparisons within the
      // tolerance, strict ones beyond it (x = 1 is no witness of `reach x < 1`).
      return property.predicate.Witnessed(env, modes, tolerance);
  }
  return false;
}

namespace {

// Moves `value` of variable `name` (a System name, slot `slot` of `c`) onto the range of c's first
// initial state, which it may miss by rounding only (1e-9 relative); throws otherwise.
double IntoInitialRange(const Component& c, int slot, const std::string& name, double value) {
  const Automaton& a = c.automaton;
  if (a.initial_states().empty()) return value;  // the simulator rejects the component
  const InitialState& init = a.initial_states().front();
  const std::vector<double> env = a.ParameterEnvironment();
  for (const InitialValue& iv : init.values) {
    if (iv.slot != slot) continue;
    const double lo = iv.range.lo.Evaluate(env), hi = iv.range.hi.Evaluate(env);
    const double tol = 1e-9 * std::max({1.0, std::abs(lo), std::abs(hi)});
    if (!(value >= lo - tol && value <= hi + tol)) {
      throw std::invalid_argument("replay: initial value " + name + " = " + FormatNumber(value) +
                                  " is not in the initial state's range [" + FormatNumber(lo) +
                                  ", " + FormatNumber(hi) + "] (mode " +
                                  a.modes()[init.mode.value()].name + ")");
    }
    return std::clamp(value, lo, hi);
  }
  return value;
}

// Applies the trace's choice of initial states, then its initial values, each checked against
// (and moved onto) the chosen initial state's range: no start outside every `init` is simulated.
// The trace keeps the values simulated, so that it states the run it stands for.
void ApplyStart(System& copy, Trace& trace) {
  for (const auto& [component, index] : trace.initial_states) {
    copy.SelectInitialState(component, index);
  }
  for (auto& [name, value] : trace.initial_values) {
    for (const Component& c : copy.components()) {
      const std::optional<int> slot = c.automaton.symbols().Find(name);
      if (!slot || c.automaton.symbols()[*slot].kind != SymbolKind::kVariable) continue;
      value = IntoInitialRange(c, *slot, name, value);
    }
    copy.SetInitialValue(name, value);
  }
}

}  // namespace

bool ReplayTrace(const System& system, const Property& property, Trace& trace,
                 const ReplayOptions& options) {
  System copy = system;
  for (const auto& [name, value] : trace.parameters) copy.SetParameter(name, value);
  ApplyStart(copy, trace);
  if (!(trace.inputs.until > 0.0) || !std::isfinite(trace.inputs.until)) {
    throw std::invalid_argument("replay: the trace's horizon must be positive and finite");
  }
  const Simulator simulator(copy);
  SimulationOptions sim;
  sim.until = trace.inputs.until;
  sim.sample_step = options.sample_fraction > 0 ? trace.inputs.until * options.sample_fraction : 0;
  sim.lazy_schedule = trace.schedule;
  trace.run = simulator.Run(sim, trace.inputs.inputs);
  trace.state_index = -1;
  const double horizon = property.horizon.value_or(INFINITY);
  for (std::size_t i = 0; i < trace.run.samples.size(); ++i) {
    const StateSample& s = trace.run.samples[i];
    if (s.time > horizon) break;
    // A state outside its modes' invariants (the simulator records the state a jump leads to
    // even then) is no state of a run of the model: the run ends before it.
    if (!InsideInvariants(simulator, s, options.tolerance)) break;
    if (IsTarget(simulator, property, s, options.tolerance)) {
      trace.state_index = static_cast<int>(i);
      return true;
    }
  }
  return false;
}

}  // namespace hybrid
