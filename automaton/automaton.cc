#include "hybrid/automaton/automaton.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace hybrid {
namespace {

// Messages speak of the model (names, modes, values), never of this API: they reach users as
// they are (the parser reports them at the offending declaration).
[[noreturn]] void Fail(const std::string& message) { throw std::invalid_argument(message); }

// `context` names what is wrong ("flow of 'x' in mode 'm'").
[[noreturn]] void Fail(std::string_view context, const std::string& message) {
  throw std::invalid_argument(std::string(context) + ": " + message);
}

// "[lo, hi]" in shortest round-trip form.
std::string RangeText(double lo, double hi) {
  return "[" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
}

// The message for an expression or predicate of `depth` levels, beyond kMaxExpressionDepth.
std::string TooDeep(int depth) {
  return "expression too long or nested too deeply (" + std::to_string(depth) +
         " levels, more than " + std::to_string(kMaxExpressionDepth) + ")";
}

template <class T, class Key>
bool SortedUnique(const std::vector<T>& items, Key key) {
  for (size_t i = 1; i < items.size(); ++i) {
    if (!(key(items[i - 1]) < key(items[i]))) return false;
  }
  return true;
}

}  // namespace

Automaton::Automaton(std::string name) : name_(std::move(name)) {
  if (name_.empty()) Fail("an automaton needs a name");
}

void Automaton::CheckSlots(const Expression& e, std::string_view context, bool allow_inputs,
                           bool allow_state) const {
  if (e.depth() > kMaxExpressionDepth) Fail(context, TooDeep(e.depth()));
  for (int slot : e.Slots()) {
    if (slot >= symbols_.size()) {
      Fail(context,
           "expression '" + e.ToString() + "' reads undeclared slot " + std::to_string(slot));
    }
    const Symbol& s = symbols_[slot];
    const bool ok =
        s.kind == SymbolKind::kParameter || (s.kind == SymbolKind::kInput && allow_inputs) ||
        ((s.kind == SymbolKind::kVariable || s.kind == SymbolKind::kDiscrete) && allow_state);
    if (!ok) {
      Fail(context, std::string(KindName(s.kind)) + " '" + s.name + "' is not allowed here");
    }
  }
}

double Automaton::EvaluateConstant(const Expression& e, std::string_view context) const {
  CheckSlots(e, context, false, false);
  const double v = e.Evaluate(ParameterEnvironment());
  if (!std::isfinite(v)) Fail(context, "'" + e.ToString() + "' is not finite");
  return v;
}

int Automaton::AddVariable(std::string name, std::string unit, std::optional<Range> domain) {
  if (domain) {
    const double lo = EvaluateConstant(domain->lo, "domain of " + name);
    const double hi = EvaluateConstant(domain->hi, "domain of " + name);
    if (lo > hi) Fail("empty domain for '" + name + "'");
  }
  int slot;
  try {
    slot = symbols_.Add({std::move(name), SymbolKind::kVariable, std::move(unit)});
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
  variables_.push_back({slot, std::move(domain)});
  return slot;
}

int Automaton::AddDiscreteVariable(std::string name) {
  if (!modes_.empty()) {
    Fail("'" + name + "' declared after the first mode");
  }
  int slot;
  try {
    slot = symbols_.Add({std::move(name), SymbolKind::kDiscrete, ""});
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
  discrete_.push_back(slot);
  return slot;
}

int Automaton::AddInput(std::string name, Range bounds, std::string unit) {
  const double lo = EvaluateConstant(bounds.lo, "bounds of " + name);
  const double hi = EvaluateConstant(bounds.hi, "bounds of " + name);
  if (lo > hi) Fail("empty bounds for '" + name + "'");
  int slot;
  try {
    slot = symbols_.Add({std::move(name), SymbolKind::kInput, std::move(unit)});
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
  inputs_.push_back({slot, std::move(bounds)});
  return slot;
}

int Automaton::AddParameter(std::string name, Expression value, std::string unit,
                            std::optional<Range> range) {
  const double v = EvaluateConstant(value, "value of " + name);
  if (range) {
    const std::string context = "range of '" + name + "'";
    const double lo = EvaluateConstant(range->lo, context);
    const double hi = EvaluateConstant(range->hi, context);
    if (lo > hi) Fail("empty range " + RangeText(lo, hi) + " for parameter '" + name + "'");
    if (v < lo || v > hi) {
      Fail("value " + FormatNumber(v) + " of parameter '" + name + "' is outside its range " +
           RangeText(lo, hi));
    }
  }
  int slot;
  try {
    slot = symbols_.Add({std::move(name), SymbolKind::kParameter, std::move(unit)});
  } catch (const std::invalid_argument& e) {
    Fail(e.what());
  }
  parameters_.emplace_back(slot, std::move(value));
  parameter_ranges_.push_back(std::move(range));
  return slot;
}

std::optional<Range> Automaton::ParameterRange(int slot) const {
  for (size_t i = 0; i < parameters_.size(); ++i) {
    if (parameters_[i].first == slot) return parameter_ranges_[i];
  }
  return std::nullopt;
}

void Automaton::SetParameter(std::string_view name, double value) {
  const std::optional<int> slot = symbols_.Find(name);
  if (!slot || symbols_[*slot].kind != SymbolKind::kParameter) {
    Fail("'" + std::string(name) + "' is not a parameter of automaton '" + name_ + "'");
  }
  if (!std::isfinite(value)) Fail("value of '" + std::string(name) + "' is not finite");
  const std::pair<int, double> set = {*slot, value};
  ParameterEnvironment({&set, 1}, "setting '" + std::string(name) + "' to " + FormatNumber(value));
  auto it = std::find_if(parameters_.begin(), parameters_.end(),
                         [&](const auto& p) { return p.first == *slot; });
  it->second = Expression::Constant(value);
}

std::vector<double> Automaton::ParameterEnvironment(std::span<const std::pair<int, double>> values,
                                                    const std::string& setting) const {
  auto set = [&](int s) -> const std::pair<int, double>* {
    for (const auto& v : values) {
      if (v.first == s) return &v;
    }
    return nullptr;
  };
  std::vector<double> env(symbols_.size(), 0.0);
  for (const auto& [s, definition] : parameters_) {
    const auto* v = set(s);
    env[s] = v ? v->second : definition.Evaluate(env);
  }
  // Every parameter and range bound is evaluated in the new environment; ranges read only
  // earlier parameters.
  for (size_t i = 0; i < parameters_.size(); ++i) {
    const int s = parameters_[i].first;
    const std::string& p = symbols_[s].name;
    if (!std::isfinite(env[s])) Fail(setting + " makes parameter '" + p + "' non-finite");
    const std::optional<Range>& range = parameter_ranges_[i];
    if (!range) continue;
    const double lo = range->lo.Evaluate(env);
    const double hi = range->hi.Evaluate(env);
    if (!std::isfinite(lo) || !std::isfinite(hi)) {
      Fail(setting + " makes the range of parameter '" + p + "' non-finite");
    }
    if (lo > hi) Fail(setting + " makes the range of parameter '" + p + "' empty");
    if (env[s] < lo || env[s] > hi) {
      if (set(s)) {
        Fail("value " + FormatNumber(env[s]) + " of parameter '" + p + "' is outside its range " +
             RangeText(lo, hi));
      }
      Fail(setting + " puts parameter '" + p + "' (" + FormatNumber(env[s]) +
           ") outside its range " + RangeText(lo, hi));
    }
  }
  return env;
}

ModeId Automaton::AddMode(Mode mode) {
  if (mode.name.empty()) Fail("empty mode name");
  if (FindMode(mode.name)) Fail("duplicate mode '" + mode.name + "'");
  if (!SortedUnique(mode.flows, [](const auto& f) { return f.first; })) {
    Fail("flows of mode '" + mode.name + "' are not sorted by slot or repeat a variable");
  }
  for (const auto& [slot, rhs] : mode.flows) {
    if (slot < 0 || slot >= symbols_.size() || symbols_[slot].kind != SymbolKind::kVariable) {
      Fail("mode '" + mode.name +
           "' has a flow for something that is not a continuous "
           "variable (slot " +
           std::to_string(slot) + ")");
    }
    CheckSlots(rhs, "flow of '" + symbols_[slot].name + "' in mode '" + mode.name + "'", true,
               true);
  }
  for (const Comparison& c : mode.invariant.comparisons) {
    CheckSlots(c.Residual(), "invariant of mode '" + mode.name + "'", true, true);
  }
  if (!SortedUnique(mode.discrete_values, [](const auto& d) { return d.first; })) {
    Fail("discrete values of mode '" + mode.name + "' are not sorted or repeat a variable");
  }
  for (const auto& [slot, value] : mode.discrete_values) {
    if (slot < 0 || slot >= symbols_.size() || symbols_[slot].kind != SymbolKind::kDiscrete) {
      Fail("mode '" + mode.name +
           "' sets a value for something that is not a discrete "
           "variable (slot " +
           std::to_string(slot) + ")");
    }
  }
  if (mode.discrete_values.size() != discrete_.size()) {
    for (int d : discrete_) {
      if (!mode.DiscreteValueOf(d)) {
        Fail("mode '" + mode.name + "' does not set discrete variable '" + symbols_[d].name + "'");
      }
    }
  }
  mode_index_.emplace(mode.name, num_modes());
  modes_.push_back(std::move(mode));
  return ModeId(num_modes() - 1);
}

std::optional<ModeId> Automaton::FindMode(std::string_view name) const {
  auto it = mode_index_.find(std::string(name));
  if (it == mode_index_.end()) return std::nullopt;
  return ModeId(it->second);
}

TransitionId Automaton::AddTransition(Transition t) {
  if (t.name.empty()) Fail("empty transition name");
  if (transition_index_.count(t.name)) Fail("duplicate transition '" + t.name + "'");
  if (!t.source.is_valid() || t.source.value() >= num_modes()) {
    Fail("transition '" + t.name + "' has an unknown source mode");
  }
  if (!t.target.is_valid() || t.target.value() >= num_modes()) {
    Fail("transition '" + t.name + "' has an unknown target mode");
  }
  for (const Comparison& c : t.guard.comparisons) {
    CheckSlots(c.Residual(), "guard of '" + t.name + "'", true, true);
  }
  if (!SortedUnique(t.resets, [](const Reset& r) { return r.slot; })) {
    Fail("transition '" + t.name + "' resets a variable twice");
  }
  for (const Reset& r : t.resets) {
    if (r.slot < 0 || r.slot >= symbols_.size() || symbols_[r.slot].kind != SymbolKind::kVariable) {
      Fail("transition '" + t.name + "' resets something that is not a continuous variable");
    }
    CheckSlots(r.value, "reset of '" + symbols_[r.slot].name + "' in '" + t.name + "'", true, true);
  }
  transition_index_.emplace(t.name, num_transitions());
  transitions_.push_back(std::move(t));
  return TransitionId(num_transitions() - 1);
}

void Automaton::DeclareLabel(std::string label) {
  if (label.empty()) throw std::invalid_argument("empty label");
  declared_labels_.insert(std::move(label));
}

void Automaton::SetGuard(TransitionId id, Constraint guard) {
  if (!id.is_valid() || id.value() >= num_transitions()) {
    Fail("guard for a transition that automaton '" + name_ + "' does not have");
  }
  Transition& t = transitions_[id.value()];
  for (const Comparison& c : guard.comparisons) {
    CheckSlots(c.Residual(), "guard of '" + t.name + "'", true, true);
  }
  t.guard = std::move(guard);
}

void Automaton::SetInitialValue(int slot, const InitialValue& value) {
  if (slot < 0 || slot >= symbols_.size() || symbols_[slot].kind != SymbolKind::kVariable ||
      value.slot != slot) {
    Fail("initial value for something that is not a continuous variable of automaton '" + name_ +
         "'");
  }
  const std::string context = "value of '" + symbols_[slot].name + "'";
  if (EvaluateConstant(value.range.lo, context) > EvaluateConstant(value.range.hi, context)) {
    Fail("empty initial range for '" + symbols_[slot].name + "'");
  }
  for (InitialState& state : initial_states_) {
    auto it = std::lower_bound(state.values.begin(), state.values.end(), slot,
                               [](const InitialValue& v, int s) { return v.slot < s; });
    if (it != state.values.end() && it->slot == slot) {
      *it = value;
    } else {
      state.values.insert(it, value);
    }
  }
}

void Automaton::KeepInitialState(int index) {
  if (index < 0 || index >= static_cast<int>(initial_states_.size())) {
    Fail("automaton '" + name_ + "' has no initial state number " + std::to_string(index + 1));
  }
  InitialState kept = std::move(initial_states_[static_cast<std::size_t>(index)]);
  initial_states_.clear();
  initial_states_.push_back(std::move(kept));
}

void Automaton::AddInitialState(InitialState state) {
  if (!state.mode.is_valid() || state.mode.value() >= num_modes()) {
    Fail("initial state in a mode that automaton '" + name_ + "' does not have");
  }
  const std::string& mode_name = modes_[state.mode.value()].name;
  if (!SortedUnique(state.values, [](const InitialValue& v) { return v.slot; })) {
    Fail("initial state in '" + mode_name + "' gives a variable twice");
  }
  for (const InitialValue& v : state.values) {
    if (v.slot < 0 || v.slot >= symbols_.size() || symbols_[v.slot].kind != SymbolKind::kVariable) {
      Fail("initial state in '" + mode_name +
           "' sets something that is not a continuous "
           "variable");
    }
    const std::string context = "initial value of '" + symbols_[v.slot].name + "'";
    const double lo = EvaluateConstant(v.range.lo, context);
    const double hi = EvaluateConstant(v.range.hi, context);
    if (lo > hi) Fail("empty initial range for '" + symbols_[v.slot].name + "'");
  }
  for (const VariableInfo& var : variables_) {
    const bool given = std::any_of(state.values.begin(), state.values.end(),
                                   [&](const InitialValue& v) { return v.slot == var.slot; });
    if (!given) {
      Fail("initial state in '" + mode_name + "' gives no value for '" + symbols_[var.slot].name +
           "'");
    }
  }
  initial_states_.push_back(std::move(state));
}

void Automaton::AddProperty(Property property) {
  if (property.name.empty()) Fail("empty property name");
  for (const Property& p : properties_) {
    if (p.name == property.name) Fail("duplicate property '" + property.name + "'");
  }
  const std::string context = "property '" + property.name + "'";
  if (property.predicate.depth() > kMaxExpressionDepth) {
    Fail(context, TooDeep(property.predicate.depth()));
  }
  property.predicate.ForEachComparison(
      [&](const Comparison& c) { CheckSlots(c.Residual(), context, false, true); });
  property.predicate.ForEachMode([&](const std::string& m) {
    if (!FindMode(m)) Fail(context, "unknown mode '" + m + "'");
  });
  if (property.horizon && !(*property.horizon > 0.0 && std::isfinite(*property.horizon))) {
    Fail(context, "horizon must be positive and finite");
  }
  properties_.push_back(std::move(property));
}

void Automaton::SetScenario(Scenario scenario) {
  if (!(scenario.until > 0.0) || !std::isfinite(scenario.until)) {
    Fail("'until' must be positive and finite");
  }
  std::set<int> seen;
  for (const InputSignal& s : scenario.inputs) {
    if (s.slot < 0 || s.slot >= symbols_.size() || symbols_[s.slot].kind != SymbolKind::kInput) {
      Fail("signal for something that is not an input");
    }
    const std::string& name = symbols_[s.slot].name;
    if (!seen.insert(s.slot).second) Fail("input '" + name + "' driven twice");
    if (s.points.empty()) Fail("signal for '" + name + "' has no points");
    for (size_t i = 0; i < s.points.size(); ++i) {
      if (!std::isfinite(s.points[i].first) || !std::isfinite(s.points[i].second)) {
        Fail("signal for '" + name + "' has a non-finite point");
      }
      if (i > 0 && !(s.points[i - 1].first < s.points[i].first)) {
        Fail("signal for '" + name + "': times must increase strictly");
      }
    }
    const auto& bounds = std::find_if(inputs_.begin(), inputs_.end(), [&](const InputInfo& in) {
                           return in.slot == s.slot;
                         })->bounds;
    const double lo = EvaluateConstant(bounds.lo, "bounds of input '" + name + "'");
    const double hi = EvaluateConstant(bounds.hi, "bounds of input '" + name + "'");
    for (const auto& [t, v] : s.points) {
      if (v < lo || v > hi) {
        Fail("signal for '" + name + "' takes value " + FormatNumber(v) + " outside its bounds [" +
             FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
      }
    }
  }
  scenario_ = std::move(scenario);
}

std::vector<double> Automaton::ParameterEnvironment() const {
  std::vector<double> env(symbols_.size(), 0.0);
  for (const auto& [slot, value] : parameters_) env[slot] = value.Evaluate(env);
  return env;
}

Automaton CopySymbols(const Automaton& a) {
  Automaton out(a.name());
  const SymbolTable& symbols = a.symbols();
  for (int slot = 0; slot < symbols.size(); ++slot) {
    const Symbol& s = symbols[slot];
    switch (s.kind) {
      case SymbolKind::kVariable: {
        std::optional<Range> domain;
        for (const VariableInfo& v : a.variables()) {
          if (v.slot == slot) domain = v.domain;
        }
        out.AddVariable(s.name, s.unit, domain);
        break;
      }
      case SymbolKind::kDiscrete:
        out.AddDiscreteVariable(s.name);
        break;
      case SymbolKind::kInput: {
        for (const InputInfo& in : a.inputs()) {
          if (in.slot == slot) out.AddInput(s.name, in.bounds, s.unit);
        }
        break;
      }
      case SymbolKind::kParameter: {
        for (const auto& [p, value] : a.parameters()) {
          if (p == slot) out.AddParameter(s.name, value, s.unit, a.ParameterRange(slot));
        }
        break;
      }
    }
  }
  return out;
}

}  // namespace hybrid
