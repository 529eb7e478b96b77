#include "solvers/simulation/simulator.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <stdexcept>

#include "automaton/compiled_expression.h"
#include "solvers/simulation/cvode_integrator.h"

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
  }
  return "?";
}

namespace {

// Whether an expression can be followed exactly along a straight-line trajectory: its affine
// coefficients on the continuous variables (parameters folded), or none when it is not affine in
// them, and every System slot it reads (to reject inputs that vary within a segment).
struct Linearity {
  std::optional<std::vector<std::pair<int, double>>> terms;  // (index in x, coefficient)
  std::vector<int> slots;
};

struct CompiledComparison {
  CompiledExpression residual;  // lhs - rhs over System slots
  Relation relation;
  std::string text;
  Linearity linearity;
  // The two sides, for the scale of the resolution tolerance.
  CompiledExpression lhs;
  CompiledExpression rhs;
  // The residual may jump (sign, tan, atan2, a division by a non-constant): exempt from the
  // resolution check, since a located crossing of a jump is not on its boundary.
  bool may_jump = false;
};

struct CompiledTransition {
  std::string name;  // qualified
  std::string label;
  int source = 0;
  int target = 0;
  Urgency urgency = Urgency::kUrgent;
  std::vector<CompiledComparison> guard;
  std::vector<std::pair<int, CompiledExpression>> resets;  // (index in x, value)
};

struct CompiledMode {
  std::vector<std::pair<int, CompiledExpression>> flows;  // (index in x, rhs)
  // The flows read no continuous variable: the state moves on a straight line between events
  // while the inputs they read (flow_slots) are constant.
  bool constant_rate = false;
  std::vector<int> flow_slots;
  std::vector<CompiledComparison> invariant;
  std::vector<int> outgoing;                     // transition indices
  std::vector<std::pair<int, double>> discrete;  // (System slot, value)
};

struct CompiledComponent {
  std::string instance;
  std::vector<std::string> mode_names;
  std::vector<CompiledMode> modes;
  std::vector<CompiledTransition> transitions;
  std::set<std::string> alphabet;
  int initial_mode = 0;
  std::vector<std::pair<int, double>> initial_values;  // (index in x, value)
};

// Residual semantics (automaton/constraint.h's ResidualHolds, the one definition of a comparison
// within tolerance). `closure`: strict comparisons are taken as non-strict.
bool Holds(Relation relation, double r, double tol, bool closure) {
  return ResidualHolds(relation, r, tol, closure ? Boundary::kClosure : Boundary::kExact);
}

// Whether `e` contains an operation whose value may jump as the state moves continuously: sign,
// tan, atan2, or a division by something that reads a slot for which `varies` holds. Shared
// subexpressions are visited once.
bool MayJump(const Expression& e, const std::function<bool(int)>& varies) {
  std::vector<Expression> stack = {e};
  std::set<const void*> seen;
  while (!stack.empty()) {
    const Expression node = stack.back();
    stack.pop_back();
    if (!seen.insert(node.node_id()).second) continue;
    switch (node.op()) {
      case Op::kSign:
      case Op::kTan:
      case Op::kAtan2:
        return true;
      case Op::kDiv: {
        const std::vector<int> slots = node.args()[1].Slots();
        if (std::any_of(slots.begin(), slots.end(), varies)) return true;
        break;
      }
      default:
        break;
    }
    for (const Expression& arg : node.args()) stack.push_back(arg);
  }
  return false;
}

// Crossing direction that makes a guard comparison become true.
int GuardDirection(Relation r) {
  switch (r) {
    case Relation::kLess:
    case Relation::kLessEqual:
      return -1;
    case Relation::kGreater:
    case Relation::kGreaterEqual:
      return 1;
    case Relation::kEqual:
      return 0;
  }
  return 0;
}

// Compiles one component of a System: its flows, guards, resets and invariants as expressions over
// the System's slots (through the component's global_slot map), with what the run needs to know
// about each comparison (linearity, jumps) and the component's first initial state.
class ComponentCompiler {
 public:
  // `x_index`: System slot -> index in x (-1 for a slot that is not a continuous variable);
  // `parameter_env`: the System's slots with the parameters filled. All must outlive the compiler.
  // `fixed`: System slot -> whether the compiled model holds the parameter there as a constant
  // (set by Compile; see SimulationOptions::parameters).
  ComponentCompiler(const SymbolTable& symbols, const Component& comp,
                    const std::vector<int>& x_index, const std::vector<double>& parameter_env,
                    std::vector<char>& fixed)
      : symbols_(symbols),
        comp_(comp),
        x_index_(x_index),
        parameter_env_(parameter_env),
        fixed_(fixed) {}

  // The compiled component: its modes, then its transitions (each the outgoing one of its source
  // mode), then its first initial state (interval values at their
  // midpoint). Throws std::invalid_argument if the component has no initial state.
  CompiledComponent Compile() const {
    const Automaton& a = comp_.automaton;
    CompiledComponent cc;
    cc.instance = comp_.instance;
    for (const Mode& m : a.modes()) {
      CompiledMode cm = CompileMode(m);
      cc.mode_names.push_back(m.name);
      cc.modes.push_back(std::move(cm));
    }
    for (int t = 0; t < a.num_transitions(); ++t) {
      const Transition& tr = a.transitions()[t];
      CompiledTransition ct = CompileTransition(tr);
      cc.modes[ct.source].outgoing.push_back(t);
      cc.transitions.push_back(std::move(ct));
    }
    if (a.initial_states().empty()) {
      throw std::invalid_argument("component '" + a.name() +
                                  "' has no initial state: it cannot be simulated");
    }
    const InitialState& init = a.initial_states().front();
    cc.initial_mode = init.mode.value();
    const std::vector<double> env = a.ParameterEnvironment();
    for (const InitialValue& v : init.values) {
      const double lo = v.range.lo.Evaluate(env);
      const double hi = v.range.hi.Evaluate(env);
      for (const Expression* bound : {&v.range.lo, &v.range.hi}) {
        for (const int slot : Global(*bound).Slots()) FixParameter(slot);
      }
      cc.initial_values.emplace_back(x_index_[comp_.global_slot[v.slot]], 0.5 * (lo + hi));
    }
    return cc;
  }

 private:
  // `e` with the component's slots renamed to the System's.
  Expression Global(const Expression& e) const {
    return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
      const int g = comp_.global_slot[slot];
      return Expression::Symbol(symbols_[g].name, g);
    });
  }

  // The linearity of `e` (System slots): its affine terms in x with the parameters folded, if it
  // is affine, and every slot it reads.
  Linearity LinearityOf(const Expression& e) const {
    Linearity l;
    l.slots = e.Slots();
    const Expression folded =
        e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
          if (symbols_[slot].kind != SymbolKind::kParameter) return std::nullopt;
          return Expression::Constant(parameter_env_[slot]);
        });
    if (const auto affine = folded.AsAffine()) {
      // Coefficients that parameters may change: not affine with the parameters as unknowns.
      if (!e.AsAffine()) {
        for (const int slot : l.slots) FixParameter(slot);
      }
      l.terms.emplace();
      for (const auto& [slot, coefficient] : affine->terms) {
        if (x_index_[slot] >= 0) l.terms->emplace_back(x_index_[slot], coefficient);
      }
    }
    return l;
  }

  // A guard or invariant comparison of the component.
  CompiledComparison CompileComparison(const Comparison& c) const {
    const Expression residual = Global(c.Residual());
    return CompiledComparison{CompiledExpression(residual),
                              c.relation,
                              c.ToString(),
                              LinearityOf(residual),
                              CompiledExpression(Global(c.lhs)),
                              CompiledExpression(Global(c.rhs)),
                              MayJump(residual, [&](int slot) {
                                return symbols_[slot].kind == SymbolKind::kVariable ||
                                       symbols_[slot].kind == SymbolKind::kInput;
                              })};
  }

  // A mode: flows (constant_rate when none reads a continuous variable), invariant, discrete
  // values; its outgoing transitions are added by Compile.
  CompiledMode CompileMode(const Mode& m) const {
    CompiledMode cm;
    cm.constant_rate = true;
    for (const auto& [slot, rhs] : m.flows) {
      const Expression e = Global(rhs);
      cm.flows.emplace_back(x_index_[comp_.global_slot[slot]], CompiledExpression(e));
      for (int read : e.Slots()) {
        cm.constant_rate = cm.constant_rate && x_index_[read] < 0;
        cm.flow_slots.push_back(read);
      }
    }
    for (const Comparison& c : m.invariant.comparisons)
      cm.invariant.push_back(CompileComparison(c));
    for (const auto& [slot, value] : m.discrete_values) {
      cm.discrete.emplace_back(comp_.global_slot[slot], value);
    }
    return cm;
  }

  // A transition, its name qualified by the instance.
  CompiledTransition CompileTransition(const Transition& tr) const {
    CompiledTransition ct;
    ct.name = comp_.instance.empty() ? tr.name : comp_.instance + "." + tr.name;
    ct.label = tr.label;
    ct.source = tr.source.value();
    ct.target = tr.target.value();
    ct.urgency = tr.urgency;
    for (const Comparison& c : tr.guard.comparisons) ct.guard.push_back(CompileComparison(c));
    for (const Reset& r : tr.resets) {
      ct.resets.emplace_back(x_index_[comp_.global_slot[r.slot]],
                             CompiledExpression(Global(r.value)));
    }
    return ct;
  }

  void FixParameter(int slot) const {
    if (symbols_[slot].kind == SymbolKind::kParameter) fixed_[slot] = 1;
  }

  const SymbolTable& symbols_;
  const Component& comp_;
  const std::vector<int>& x_index_;
  const std::vector<double>& parameter_env_;
  std::vector<char>& fixed_;
};

}  // namespace

struct Simulator::Compiled {
  const System* system = nullptr;
  std::vector<std::string> variable_names;
  std::vector<int> variable_slots;  // index in x -> System slot
  std::vector<CompiledComponent> components;
  std::vector<double> parameter_env;  // System slots, parameters filled
  // System slot -> the parameter there cannot be set per run (SimulationOptions::parameters).
  std::vector<char> fixed;
};

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

Simulator::Simulator(const System& system) : c_(std::make_unique<Compiled>()) {
  c_->system = &system;
  const SymbolTable& symbols = system.symbols();
  std::vector<int> x_index(symbols.size(), -1);
  for (int s = 0; s < symbols.size(); ++s) {
    if (symbols[s].kind == SymbolKind::kVariable) {
      x_index[s] = static_cast<int>(c_->variable_slots.size());
      c_->variable_slots.push_back(s);
      c_->variable_names.push_back(symbols[s].name);
    }
  }
  c_->parameter_env.assign(symbols.size(), 0.0);
  for (const Component& comp : system.components()) {
    const Automaton& a = comp.automaton;
    const std::vector<double> local_env = a.ParameterEnvironment();
    for (const auto& [slot, value] : a.parameters()) {
      c_->parameter_env[comp.global_slot[slot]] = local_env[slot];
    }
  }
  c_->fixed.assign(symbols.size(), 0);
  for (int c = 0; c < static_cast<int>(system.components().size()); ++c) {
    const Component& comp = system.components()[static_cast<std::size_t>(c)];
    c_->components.push_back(
        ComponentCompiler(symbols, comp, x_index, c_->parameter_env, c_->fixed).Compile());
    c_->components.back().alphabet = system.Alphabet(c);  // the IR's synchronisation alphabet
  }
  FixDefiningParameters(system, c_->fixed);
}

std::vector<double> Simulator::ParameterEnvironment(
    std::span<const std::pair<std::string, double>> parameters) const {
  std::vector<double> env = c_->parameter_env;
  if (parameters.empty()) return env;
  const System& system = *c_->system;
  std::vector<std::optional<double>> value(static_cast<size_t>(system.symbols().size()));
  for (const auto& [name, v] : parameters) {
    const std::optional<int> slot = system.symbols().Find(name);
    if (!slot || system.symbols()[*slot].kind != SymbolKind::kParameter) {
      BadParameter("'" + name + "' is not a parameter of the model");
    }
    if (!std::isfinite(v)) BadParameter("value of parameter '" + name + "' is not finite");
    if (c_->fixed[*slot]) {
      BadParameter("parameter '" + name +
                   "' cannot be set for a run: an initial value reads it, or it scales a "
                   "variable in a guard or invariant (set it in the model)");
    }
    value[*slot] = v;
  }
  for (const Component& comp : system.components()) EvaluateParameters(comp, value, env);
  return env;
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;

const std::vector<std::string>& Simulator::variable_names() const { return c_->variable_names; }
const System& Simulator::system() const { return *c_->system; }

std::string Simulator::ModeName(int component, int mode) const {
  const CompiledComponent& cc = c_->components.at(component);
  return cc.instance.empty() ? cc.mode_names.at(mode) : cc.instance + "." + cc.mode_names.at(mode);
}

std::string Simulator::ModeLabel(std::span<const int> modes) const {
  std::string out;
  for (size_t c = 0; c < modes.size(); ++c) {
    out += (c > 0 ? "|" : "") + ModeName(static_cast<int>(c), modes[c]);
  }
  return out;
}

namespace {

// One root function of the current modes.
struct RootRef {
  bool invariant = false;
  int component = 0;
  int index = 0;       // transition index (guard) or unused (invariant)
  int comparison = 0;  // comparison index within the guard or invariant
  int direction = 0;
};

// The state of one run; also the OdeSystem CVODE calls back.
class Run final : public OdeSystem {
 public:
  Run(const std::vector<CompiledComponent>& components, const std::vector<int>& variable_slots,
      std::vector<double> env, std::vector<InputSignal> signals, const SimulationOptions& options)
      : components_(components),
        variable_slots_(variable_slots),
        env_(std::move(env)),
        signals_(std::move(signals)),
        options_(options) {}

  // A model without continuous variables is integrated as one constant dummy variable (CVODE
  // needs at least one), whose derivative must be written too.
  void Derivatives(double t, const double* x, double* dxdt) override {
    Load(t, x);
    for (size_t i = 0; i < std::max<size_t>(x_size(), 1); ++i) dxdt[i] = 0.0;
    for (const auto& [index, rhs] : active_flows_) dxdt[index] = rhs->Evaluate(env_.data());
  }

  void Roots(double t, const double* x, double* g) override {
    Load(t, x);
    for (size_t i = 0; i < root_residuals_.size(); ++i) {
      g[i] = root_residuals_[i]->Evaluate(env_.data());
    }
  }

  size_t x_size() const { return variable_slots_.size(); }

  // Puts (t, x) into the environment; linear inputs follow t, step inputs stay at their segment
  // value (set by SetStepInputs) so that a step at a stop time does not leak into the segment.
  void Load(double t, const double* x) {
    for (size_t i = 0; i < variable_slots_.size(); ++i) env_[variable_slots_[i]] = x[i];
    for (const InputSignal& s : signals_) {
      if (s.shape == InputSignal::Shape::kLinear) env_[s.slot] = s.ValueAt(t);
    }
  }
  void SetStepInputs(double t) {
    for (const InputSignal& s : signals_) {
      if (s.shape == InputSignal::Shape::kStep) env_[s.slot] = s.ValueAt(t);
    }
  }

  void SetModes(const std::vector<int>& modes) {
    modes_ = modes;
    active_flows_.clear();
    roots_.clear();
    directions_.clear();
    for (size_t c = 0; c < components_.size(); ++c) {
      const CompiledMode& m = components_[c].modes[modes_[c]];
      for (const auto& [index, rhs] : m.flows) active_flows_.emplace_back(index, &rhs);
      for (const auto& [slot, value] : m.discrete) env_[slot] = value;
      for (int t : m.outgoing) {
        const CompiledTransition& tr = components_[c].transitions[t];
        for (size_t k = 0; k < tr.guard.size(); ++k) {
          roots_.push_back({false, static_cast<int>(c), t, static_cast<int>(k),
                            GuardDirection(tr.guard[k].relation)});
        }
      }
      for (size_t k = 0; k < m.invariant.size(); ++k) {
        if (m.invariant[k].relation == Relation::kEqual) continue;
        roots_.push_back({true, static_cast<int>(c), 0, static_cast<int>(k),
                          -GuardDirection(m.invariant[k].relation)});
      }
    }
    for (const RootRef& r : roots_) directions_.push_back(r.direction);
    // Resolved once per mode change: Roots runs at every step and inside CVODE's root search.
    root_residuals_.clear();
    for (const RootRef& r : roots_) root_residuals_.push_back(&ComparisonOf(r).residual);
    // Exact segments: every flow constant and every root function affine in the state, none of
    // them reading an input that varies within a segment (a linear signal).
    auto steady = [&](const std::vector<int>& slots) {
      return std::none_of(slots.begin(), slots.end(), [&](int slot) {
        return std::any_of(signals_.begin(), signals_.end(), [&](const InputSignal& s) {
          return s.slot == slot && s.shape == InputSignal::Shape::kLinear;
        });
      });
    };
    exact_ = true;
    for (size_t c = 0; c < components_.size() && exact_; ++c) {
      const CompiledMode& m = components_[c].modes[modes_[c]];
      exact_ = m.constant_rate && steady(m.flow_slots);
    }
    for (size_t i = 0; i < roots_.size() && exact_; ++i) {
      const Linearity& l = ComparisonOf(roots_[i]).linearity;
      exact_ = l.terms.has_value() && steady(l.slots);
    }
  }

  /// True when the current modes move the state on a straight line and every root function is
  /// affine along it, so that crossings are found exactly without a solver.
  bool exact() const { return exact_; }
  /// d g_i / dt along the straight line with constant rate `dxdt`.
  double Slope(int i, const Eigen::VectorXd& dxdt) const {
    double slope = 0.0;
    for (const auto& [index, coefficient] : *ComparisonOf(roots_[i]).linearity.terms) {
      slope += coefficient * dxdt[index];
    }
    return slope;
  }

  const CompiledComparison& ComparisonOf(const RootRef& r) const {
    const CompiledComponent& cc = components_[r.component];
    return r.invariant ? cc.modes[modes_[r.component]].invariant[r.comparison]
                       : cc.transitions[r.index].guard[r.comparison];
  }

  bool GuardHolds(int component, int t, bool closure) const {
    for (const CompiledComparison& c : components_[component].transitions[t].guard) {
      if (!Holds(c.relation, c.residual.Evaluate(env_.data()), options_.event_tolerance, closure)) {
        return false;
      }
    }
    return true;
  }

  // The first comparison of component c's current invariant violated beyond event_tolerance.
  std::optional<std::string> ViolatedInvariantOf(size_t c) const {
    for (const CompiledComparison& cmp : components_[c].modes[modes_[c]].invariant) {
      if (!Holds(cmp.relation, cmp.residual.Evaluate(env_.data()), options_.event_tolerance,
                 true)) {
        return cmp.text;
      }
    }
    return std::nullopt;
  }
  // The first comparison of the current modes' invariants violated beyond tolerance, as text.
  std::optional<std::string> ViolatedInvariant() const {
    for (size_t c = 0; c < components_.size(); ++c) {
      if (auto violated = ViolatedInvariantOf(c)) return violated;
    }
    return std::nullopt;
  }

  // How far from its boundary a located event may leave comparison `c` at the current state
  // (SimulationOptions::resolution_tolerance).
  double ResolutionTolerance(const CompiledComparison& c) const {
    return options_.event_tolerance +
           options_.resolution_tolerance *
               (std::abs(c.lhs.Evaluate(env_.data())) + std::abs(c.rhs.Evaluate(env_.data())));
  }
  // Root function i at the current state, if it is off its boundary by more than its resolution
  // tolerance: (residual, tolerance).
  std::optional<std::pair<double, double>> OffBoundary(int i) const {
    const CompiledComparison& c = ComparisonOf(roots_[i]);
    if (c.may_jump) return std::nullopt;
    const double residual = c.residual.Evaluate(env_.data());
    const double tolerance = ResolutionTolerance(c);
    if (std::abs(residual) <= tolerance) return std::nullopt;
    return std::make_pair(residual, tolerance);
  }

  // Loads a recorded state (its modes' discrete values, its variables and the inputs at
  // `input_time`, normally its own time) and returns the first invariant comparison it violates
  // beyond the resolution tolerance, with its residual, or nullopt. Leaves the environment at
  // that state: for after the run.
  std::optional<std::pair<std::string, double>> OutsideInvariant(const StateSample& s,
                                                                 double input_time) {
    for (size_t c = 0; c < components_.size(); ++c) {
      for (const auto& [slot, value] : components_[c].modes[s.modes[c]].discrete) {
        env_[slot] = value;
      }
    }
    for (size_t i = 0; i < variable_slots_.size(); ++i) env_[variable_slots_[i]] = s.x[i];
    for (const InputSignal& signal : signals_) env_[signal.slot] = signal.ValueAt(input_time);
    for (size_t c = 0; c < components_.size(); ++c) {
      for (const CompiledComparison& cmp : components_[c].modes[s.modes[c]].invariant) {
        if (cmp.may_jump) continue;
        const double residual = cmp.residual.Evaluate(env_.data());
        if (!Holds(cmp.relation, residual, ResolutionTolerance(cmp), true)) {
          return std::make_pair(cmp.text, residual);
        }
      }
    }
    return std::nullopt;
  }

  const std::vector<int>& modes() const { return modes_; }
  const std::vector<RootRef>& roots() const { return roots_; }
  const std::vector<int>& directions() const { return directions_; }
  std::vector<double>& env() { return env_; }
  const std::vector<CompiledComponent>& components() const { return components_; }

 private:
  const std::vector<CompiledComponent>& components_;
  const std::vector<int>& variable_slots_;
  std::vector<double> env_;
  std::vector<InputSignal> signals_;
  const SimulationOptions& options_;
  std::vector<int> modes_;
  std::vector<std::pair<int, const CompiledExpression*>> active_flows_;
  std::vector<RootRef> roots_;
  std::vector<const CompiledExpression*> root_residuals_;  // roots_[i]'s residual
  bool exact_ = false;
  std::vector<int> directions_;
};

// A candidate jump: the participating (component, transition) pairs.
using Jump = std::vector<std::pair<int, int>>;

// The scenario's signals overridden by `signals`. Throws std::invalid_argument for a signal that
// drives something other than an input.
std::vector<InputSignal> MergedInputs(const System& system, std::span<const InputSignal> signals) {
  const SymbolTable& symbols = system.symbols();
  std::vector<InputSignal> inputs;
  if (system.scenario()) inputs = system.scenario()->inputs;
  for (const InputSignal& s : signals) {
    if (s.slot < 0 || s.slot >= symbols.size() || symbols[s.slot].kind != SymbolKind::kInput) {
      throw std::invalid_argument("a signal drives something that is not an input");
    }
    std::erase_if(inputs, [&](const InputSignal& x) { return x.slot == s.slot; });
    inputs.push_back(s);
  }
  return inputs;
}

// The first recorded state outside its modes' invariants (beyond the resolution tolerance): its
// index and a message, or nullopt. Exempt: a state that a jump leaves at its own instant (a
// kBeforeEvent sample in the same modes at the same time, itself or later) if it was entered at
// that instant (an urgent transition may leave at once a mode entered outside its invariant) or
// was inside with the inputs just before that instant (an input jump put it outside: a lazy
// transition takes it away); and states at or after `exempt_from` (the final instant of a run
// that stopped on a violated invariant).
std::optional<std::pair<size_t, std::string>> StateOutsideInvariant(
    Run& run, const std::vector<StateSample>& samples, const Simulator& simulator,
    double exempt_from = std::numeric_limits<double>::infinity()) {
  for (size_t i = 0; i < samples.size(); ++i) {
    const StateSample& s = samples[i];
    if (s.time >= exempt_from) break;
    const auto outside = run.OutsideInvariant(s, s.time);
    if (!outside) continue;
    auto same_instant = [&](size_t j) {
      return samples[j].time == s.time && samples[j].modes == s.modes;
    };
    bool left = false, entered = false;
    for (size_t j = i; j < samples.size() && same_instant(j) && !left; ++j) {
      left = samples[j].kind == StateSample::Kind::kBeforeEvent;
    }
    for (size_t j = i + 1; j-- > 0 && same_instant(j) && !entered;) {
      entered = samples[j].kind == StateSample::Kind::kAfterEvent;
    }
    const double before = std::nextafter(s.time, -std::numeric_limits<double>::infinity());
    if (left && (entered || !run.OutsideInvariant(s, before))) continue;
    return std::make_pair(
        i, "the state recorded at t = " + FormatNumber(s.time) + " lies outside the invariant '" +
               outside->first + "' of mode " + simulator.ModeLabel(s.modes) + " (residual " +
               FormatNumber(outside->second) + "): the run is not resolved there");
  }
  return std::nullopt;
}

// Ends `result` as kUnresolved at its recorded state `index` (which is not trustworthy): the
// states and events from that state's time on are dropped, and the last state kept is repeated
// as the end. The start (index 0) is always kept.
void TruncateUnresolved(SimulationResult& result, size_t index, std::string message) {
  result.status = SimulationStatus::kUnresolved;
  result.message = std::move(message);
  result.zeno.reset();
  const double bad_time = result.samples[index].time;
  std::erase_if(result.events, [&](const EventRecord& e) { return e.time >= bad_time; });
  size_t keep = index;
  while (keep > 1 && result.samples[keep - 1].time >= bad_time) --keep;
  result.samples.resize(std::max<size_t>(keep, 1));
  StateSample end = result.samples.back();
  end.kind = StateSample::Kind::kEnd;
  result.samples.push_back(std::move(end));
}

}  // namespace

void ValidateSimulationOptions(const SimulationOptions& o, double until) {
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  auto positive = [&](double v, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      fail(std::string("the ") + what + " must be positive and finite, got " + FormatNumber(v));
    }
  };
  auto non_negative = [&](double v, const char* what) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      fail(std::string("the ") + what + " must be finite and >= 0, got " + FormatNumber(v));
    }
  };
  positive(until, "horizon (--until)");
  positive(o.relative_tolerance, "relative tolerance");
  positive(o.absolute_tolerance, "absolute tolerance");
  non_negative(o.event_tolerance, "event tolerance");
  non_negative(o.resolution_tolerance, "resolution tolerance");
  non_negative(o.sample_step, "sample step (--sample)");
  non_negative(o.max_step, "largest step");
  non_negative(o.zeno_window, "Zeno window");
  non_negative(o.zeno_horizon, "Zeno horizon");
  if (o.dense_checks < 0 || o.dense_checks > 1000) fail("dense checks must lie in [0, 1000]");
  if (o.max_event_iterations < 1) fail("the event iteration bound must be at least 1");
  if (o.zeno_events < 0) fail("the Zeno event count must be >= 0");
  if (o.max_events < 0) fail("the event limit must be >= 0");
  if (o.max_samples < 0) fail("the sample limit must be >= 0");
  if (o.max_steps < 1) fail("the step limit must be at least 1");
  for (size_t i = 0; i < o.lazy_schedule.size(); ++i) {
    const double t = o.lazy_schedule[i].time;
    if (!(t >= 0.0) || !(t <= until) || (i > 0 && t < o.lazy_schedule[i - 1].time)) {
      fail("scheduled jump " + std::to_string(i + 1) + " at t = " + FormatNumber(t) +
           ": jump times must be non-decreasing and within [0, " + FormatNumber(until) + "]");
    }
  }
  // Samples at sample times: refused before the run rather than grown without bound.
  const double uniform = o.sample_step > 0.0 ? std::floor(until / o.sample_step) : 0.0;
  const double planned = uniform + static_cast<double>(o.sample_times.size());
  if (planned > static_cast<double>(o.max_samples)) {
    std::string what;
    if (uniform > 0.0) {
      what = "recording the state every " + FormatNumber(o.sample_step) +
             " (--sample) up to t = " + FormatNumber(until) + " (--until)";
    }
    if (!o.sample_times.empty()) {
      what += (what.empty() ? "recording the state at " : " and at ") +
              std::to_string(o.sample_times.size()) + " listed times";
    }
    fail(what + " would record " + FormatNumber(planned) + " samples, more than the limit of " +
         std::to_string(o.max_samples) +
         (uniform > 0.0 ? ": give a larger sample step or a shorter horizon" : ""));
  }
}

namespace {

// The horizon of a run: options.until, else the scenario's. Throws std::invalid_argument if there
// is neither.
double Horizon(const System& system, const SimulationOptions& options) {
  if (options.until) return *options.until;
  if (system.scenario()) return system.scenario()->until;
  throw std::invalid_argument("no horizon: give one (--until) or declare a scenario in the model");
}

// Throws std::invalid_argument, naming the first offending time, unless options.sample_times is
// finite, within [0, until] and non-decreasing.
void ValidateSampleTimes(const SimulationOptions& options, double until) {
  for (size_t i = 0; i < options.sample_times.size(); ++i) {
    const double ts = options.sample_times[i];
    if (!std::isfinite(ts) || ts < 0.0 || ts > until) {
      throw std::invalid_argument("sample time " + FormatNumber(ts) + " lies outside [0, " +
                                  FormatNumber(until) + "]");
    }
    if (i > 0 && ts < options.sample_times[i - 1]) {
      throw std::invalid_argument("sample times must not decrease");
    }
  }
}

// Throws std::invalid_argument for a signal of `inputs` with no points, a non-finite point, times
// that do not increase strictly or a value outside its input's bounds (signal by signal, in that
// order), then for an input of `system` with no signal whose bounds exclude 0.
void ValidateInputs(const System& system, const std::vector<InputSignal>& inputs) {
  const SymbolTable& symbols = system.symbols();
  auto fail = [&](const std::string& message) { throw std::invalid_argument(message); };
  for (const InputSignal& s : inputs) {
    const std::string& name = symbols[s.slot].name;
    if (s.points.empty()) fail("signal for '" + name + "' has no points");
    for (size_t i = 0; i < s.points.size(); ++i) {
      if (!std::isfinite(s.points[i].first) || !std::isfinite(s.points[i].second)) {
        fail("signal for '" + name + "' has a non-finite point");
      }
      if (i > 0 && !(s.points[i - 1].first < s.points[i].first)) {
        fail("signal for '" + name + "': times must increase strictly");
      }
    }
    const auto [lo, hi] = system.InputBounds(s.slot);
    for (const auto& [t, v] : s.points) {
      if (v < lo || v > hi) {
        fail("input '" + name + "' = " + FormatNumber(v) + " at t = " + FormatNumber(t) +
             " lies outside its bounds [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
      }
    }
  }
  for (int s : symbols.SlotsOfKind(SymbolKind::kInput)) {
    const bool driven = std::any_of(inputs.begin(), inputs.end(),
                                    [s](const InputSignal& x) { return x.slot == s; });
    const auto [lo, hi] = system.InputBounds(s);
    if (!driven && (lo > 0.0 || hi < 0.0)) {
      fail("input '" + symbols[s].name + "' has no signal and 0 lies outside its bounds");
    }
  }
}

// The breakpoints of the inputs and the times of scheduled jumps: the times in (0, until) of
// their points, sorted and distinct. Integration restarts there.
std::vector<double> Breakpoints(const std::vector<InputSignal>& inputs, double until,
                                const std::vector<ScheduledJump>& schedule) {
  std::vector<double> breakpoints;
  for (const InputSignal& s : inputs) {
    for (const auto& [t, v] : s.points) {
      if (t > 0.0 && t < until) breakpoints.push_back(t);
    }
  }
  for (const ScheduledJump& j : schedule) {
    if (j.time > 0.0 && j.time < until) breakpoints.push_back(j.time);
  }
  std::sort(breakpoints.begin(), breakpoints.end());
  breakpoints.erase(std::unique(breakpoints.begin(), breakpoints.end()), breakpoints.end());
  return breakpoints;
}

// Whether the intervals `d` (at least two) shrink geometrically: all positive, every ratio of
// consecutive intervals within 1% of r = (d_last / d_first)^(1 / (|d| - 1)), and r < 1. Sets *r
// when all are positive (left alone otherwise).
bool ShrinkGeometrically(const std::vector<double>& d, double* r) {
  bool geometric = std::all_of(d.begin(), d.end(), [](double x) { return x > 0.0; });
  if (geometric) {
    *r = std::pow(d.back() / d.front(), 1.0 / static_cast<double>(d.size() - 1));
    for (size_t i = 1; i < d.size() && geometric; ++i) {
      geometric = std::abs(d[i] / d[i - 1] - *r) <= 0.01 * *r;
    }
    geometric = geometric && *r < 1.0;
  }
  return geometric;
}

// The transitions of each of the last k of `events` (k <= events.size()), an event's qualified
// names joined with "+", oldest first.
std::vector<std::string> LastTransitionNames(const std::vector<EventRecord>& events, size_t k) {
  std::vector<std::string> names;
  for (size_t i = events.size() - k; i < events.size(); ++i) {
    std::string joined;
    for (const auto& s : events[i].transitions) joined += (joined.empty() ? "" : "+") + s;
    names.push_back(joined);
  }
  return names;
}

// The shortest cycle that `names` repeats (a period p of at most half its length: names[i] ==
// names[i - p] throughout), as its last p names; empty if there is none.
std::vector<std::string> RepeatingCycle(const std::vector<std::string>& names) {
  std::vector<std::string> cycle;
  for (size_t p = 1; p <= names.size() / 2; ++p) {
    bool periodic = true;
    for (size_t i = p; i < names.size() && periodic; ++i) periodic = names[i] == names[i - p];
    if (periodic) {
      cycle.assign(names.end() - static_cast<long>(p), names.end());
      break;
    }
  }
  return cycle;
}

// Consecutive passes of the loop that neither advanced time nor jumped. A few are normal (a root
// at the segment start, then a stop time there); more mean that the loop is stuck.
constexpr int kMaxStalledPasses = 100;
// A segment after a restart shorter than this times |t| is not given to CVODE (see ShortGap).
constexpr double kShortGap = 100 * std::numeric_limits<double>::epsilon();

// The event loop of one run, in the manner of Drake's Simulator::AdvanceTo: each pass integrates
// towards the next stop time (horizon, sample time, input breakpoint) on an exact segment, a
// tangent over a short gap or CVODE (IntegrateToStop); locates the crossings inside the step
// (FindInteriorCrossing); at a crossing chooses and fires the jumps and iterates at that instant,
// watching for Zeno (HandleCrossings); records the samples due and applies input jumps
// (ReachStopTimes); and guards against a loop that makes no progress (EndPass). The members hold
// what the steps share: time and state, the result so far, what the current instant reached, the
// integrator and the anchor of exact segments.
class EventLoop {
 public:
  // `run` must be at the start state (step inputs at 0, modes set, (0, x) loaded) and `x` be that
  // state (at least one entry); the start state lies inside its invariants. `breakpoints` are
  // those of the inputs (Breakpoints). The references must outlive the loop.
  EventLoop(const Simulator& simulator, const std::vector<CompiledComponent>& components, Run& run,
            const SimulationOptions& options, double until, std::vector<double> breakpoints,
            Eigen::VectorXd x);

  // Records the start, fires what is enabled there, runs passes until the horizon or a stop, and
  // returns the result (Finish). Call once.
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

  // One pass: integrate to the next stop, locate crossings, act on them, reach the stop times.
  // Returns false when the run must stop (status set, or an early stop such as kUnresolved).
  bool RunPass();
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
  // Exact segments: marks crossed_ settled at t_ (reset when the instant or the events changed).
  void Settle();
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

  // Discrete steps at one instant.
  // The transitions that can fire now, best first: urgent before lazy, then component order,
  // then declaration order. Urgent transitions whose guard crossed at this instant
  // (reached_guards_) are enabled when their guard holds in its closure, others when it holds
  // strictly. Lazy transitions of a component are candidates only when its invariant boundary
  // was reached (reached_invariant_).
  std::vector<Jump> Candidates() const;
  // Completes `jump`, transition of component c labelled `label`, with the first enabled
  // transition of that label of every other component that uses the label (its guard in its
  // closure where it crossed at this instant, strictly otherwise). False if some component has
  // none (the jump is blocked).
  bool AddPartners(size_t c, const std::string& label, Jump* jump) const;
  // Fires `jump` at t_: records the states before and after and the event; resets are evaluated
  // in the state before the jump.
  void Fire(const Jump& jump, EventRecord::Cause cause);
  // Fires the first of `jumps` and then whatever becomes enabled at the same instant, at most
  // max_event_iterations times and within max_events. Returns false when the run must stop
  // (kZeno, kEventLimit or kInvariantViolated set).
  bool JumpAndIterate(std::vector<Jump> jumps, EventRecord::Cause cause);
  // The cause of the next jump of an event iteration: a lazy transition at its invariant
  // boundary, an urgent one whose guard crossed with the one just taken, or one the jump enabled.
  EventRecord::Cause CauseInIteration(const std::vector<Jump>& jumps) const;
  // Event iteration that does not settle: sets kZeno with the last events' transitions.
  void StopIterationZeno();
  // Zeno across time: many events in a vanishing window, or geometrically shrinking intervals
  // close to their accumulation point. If so sets kZeno with its report and returns true.
  bool ZenoCheck();
  // The message if a root function of `crossed` lies off its boundary beyond its resolution
  // tolerance at the state reached; nullopt otherwise.
  std::optional<std::string> UnresolvedCrossing(const std::vector<int>& crossed) const;
  // A step input jumped at t_: a component left outside its invariant has reached its boundary;
  // fires what is enabled. Returns false when the run must stop.
  bool InputJump();

  // What the current instant reached (reached_invariant_, reached_guards_).
  void ForgetReached();
  void NoteReached(const std::vector<int>& crossed);
  bool GuardReached(int c, int ti) const;

  // Helpers.
  // Records (t_, modes, x_) as a sample of `kind`.
  void Record(StateSample::Kind kind);
  // Records the listed sample times already reached.
  void RecordListed();
  // The next uniform or listed sample time, or the horizon.
  double NextSampleTime() const;
  // The root functions at (time, state), into *g (resized to their number).
  void EvaluateRoots(double time, const Eigen::VectorXd& state, std::vector<double>* g);
  // Root function i reported at `time` without firing anything (exact segments).
  bool IsSettled(size_t i, double time) const;
  // Root function i starts this pass on its boundary (g_prev_ exactly 0, or an invariant past it
  // within event_tolerance) with a crossing direction.
  bool OnBoundary(size_t i) const;
  // The current modes, as a label for messages.
  std::string ModesLabel() const { return simulator_.ModeLabel(run_.modes()); }

  const Simulator& simulator_;
  const std::vector<CompiledComponent>& components_;
  Run& run_;
  const SimulationOptions& options_;
  const double until_;
  const std::vector<double> breakpoints_;
  const int n_;  // number of continuous variables (x_ has at least one entry)
  double t_ = 0.0;
  Eigen::VectorXd x_;
  SimulationResult result_;
  // What the current instant reached and no jump has acted on yet, per component: the text of
  // an invariant comparison whose boundary it reached (empty: none) and the transitions whose
  // guard comparisons crossed. Set from the root functions that fired; kept through the event
  // iteration at that instant for the components that have not jumped, so that one component's
  // jump does not discard what another one reached at the same instant; forgotten when time
  // advances.
  std::vector<std::string> reached_invariant_;
  std::vector<std::vector<int>> reached_guards_;
  CvodeIntegrator::Options integrator_options_;
  // Created on first use: a run that stays in constant-rate modes never needs it.
  std::optional<CvodeIntegrator> integrator_;
  bool stale_ = true;  // the integrator must be restarted at (t, x) before its next step
  Eigen::VectorXd rate_;
  // Exact segments are computed from an anchor, the state where the current constant rates took
  // over (after a jump, an input breakpoint, a restart or a solver pass), not from the last stop:
  // a recorded sample stops the loop, and computing on from its rounded state made the state at
  // a later event (a guard reached exactly at an input breakpoint) depend on --sample.
  bool anchored_ = false;
  double anchor_t_ = 0.0;
  Eigen::VectorXd anchor_x_, anchor_rate_;
  std::vector<double> anchor_g_;
  size_t next_break_ = 0;
  size_t next_scheduled_ = 0;  // the first entry of options_.lazy_schedule not yet due
  double next_uniform_;
  size_t next_listed_ = 0;  // in options.sample_times
  double next_sample_ = 0.0;
  std::vector<double> g_prev_, g_mid_;
  Eigen::VectorXd x_new_, x_mid_, x_start_;
  // Per-step buffers, reused so that a step allocates nothing.
  std::vector<double> ga_, gm_;
  std::vector<int> crossed_;
  // Exact segments: the root functions reported at `settled_time_` that fired nothing there. The
  // state reached at a crossing is rounded, so such a root function can be left a hair before its
  // boundary (theta2 = -8.9e-16 for `theta2 == 0`); its crossing time t - g / s then rounds to t
  // itself and would be reported again and again at the same instant without anything changing.
  // A settled root function is not reported again at that instant; a jump (new root functions)
  // or an input jump there (the other conjuncts may hold now) unsettles them all.
  std::vector<char> settled_;
  double settled_time_ = std::numeric_limits<double>::quiet_NaN();
  size_t settled_events_ = 0;
  int stalled_ = 0;
  long passes_ = 0;  // SimulationOptions::max_steps
};

EventLoop::EventLoop(const Simulator& simulator, const std::vector<CompiledComponent>& components,
                     Run& run, const SimulationOptions& options, double until,
                     std::vector<double> breakpoints, Eigen::VectorXd x)
    : simulator_(simulator),
      components_(components),
      run_(run),
      options_(options),
      until_(until),
      breakpoints_(std::move(breakpoints)),
      n_(static_cast<int>(run.x_size())),
      x_(std::move(x)),
      reached_invariant_(components.size()),
      reached_guards_(components.size()),
      rate_(Eigen::VectorXd::Zero(std::max(n_, 1))),
      next_uniform_(options.sample_step > 0.0 ? options.sample_step : until) {
  integrator_options_.relative_tolerance = options.relative_tolerance;
  integrator_options_.absolute_tolerance = options.absolute_tolerance;
  integrator_options_.max_step = options.max_step;
}

SimulationResult EventLoop::Simulate() {
  // The listed samples, the start and a few events (the vector grows past that as needed).
  result_.samples.reserve(options_.sample_times.size() + 16);
  Record(StateSample::Kind::kStart);
  bool running = JumpAndIterate(Candidates(), EventRecord::Cause::kEnabled);
  if (running) running = FireScheduled();
  if (running && ZenoCheck()) running = false;
  // Listed times already reached (0, or before the first step): recorded now, after the start.
  RecordListed();
  next_sample_ = NextSampleTime();
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
  t_ = p.t_new;
  x_ = x_new_;
  run_.Load(t_, x_.data());
  bool restart = p.interior;

  ForgetReached();  // a new instant
  if (p.status == CvodeIntegrator::Status::kRoot || p.interior) {
    if (!HandleCrossings(p, &restart)) return false;
  }
  if (!ReachStopTimes(&restart)) return false;
  return EndPass(p, restart);
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
  p.t_stop = std::min({until_, next_sample_,
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
    const bool on_line = anchored_ && rate_ == anchor_rate_;
    for (size_t i = 0; i < g_prev_.size() && exact; ++i) {
      const double slope = run_.Slope(static_cast<int>(i), rate_);
      const bool boundary = on_line && g_prev_[i] == 0.0
                                ? anchor_t_ - anchor_g_[i] / slope == p.t_prev
                                : OnBoundary(i);
      exact = !(boundary && run_.roots()[i].direction * slope > 0.0);
    }
  }
  return exact;
}

void EventLoop::ExactSegment(Pass& p) {
  if (!anchored_ || rate_ != anchor_rate_) {
    anchored_ = true;
    anchor_t_ = p.t_prev;
    anchor_x_ = x_;
    anchor_rate_ = rate_;
    anchor_g_ = g_prev_;
  }
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
  x_new_ = anchor_x_ + rate_.head(x_.size()) * (p.t_new - anchor_t_);
  stale_ = true;
}

std::optional<double> EventLoop::ExactCrossing(size_t i, const Pass& p, double limit,
                                               double tie) const {
  const double slope = run_.Slope(static_cast<int>(i), rate_);
  const int dir = run_.roots()[i].direction;
  // Where the root function crosses is decided on its line from the anchor, never from
  // the rounded state of a stop in between (which may already lie a hair past the
  // boundary, so that the crossing would be missed).
  const double g0 = anchor_g_[i];
  const bool toward =
      (dir <= 0 && g0 > 0.0 && slope < 0.0) || (dir >= 0 && g0 < 0.0 && slope > 0.0);
  if (!toward) return std::nullopt;
  const double on_line = anchor_t_ - g0 / slope;
  // Crossed before this pass: reported by the pass that reached it.
  if (on_line < p.t_prev - tie) return std::nullopt;
  const double crossing = std::max(on_line, p.t_prev);
  if (crossing > p.t_new + tie || crossing > limit) return std::nullopt;
  // Already reported at this instant, and nothing fired: no progress to make here.
  if (crossing <= p.t_prev + tie && IsSettled(i, p.t_prev)) return std::nullopt;
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
  if (!integrator_) integrator_.emplace(&run_, std::max(n_, 1), integrator_options_);
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
  NoteReached(crossed_);
  std::vector<Jump> jumps = Candidates();
  const bool jumped = !jumps.empty();
  bool running = true;
  if (jumped) {
    const auto [c0, t0] = jumps.front().front();
    const EventRecord::Cause cause = components_[c0].transitions[t0].urgency == Urgency::kLazy
                                         ? EventRecord::Cause::kInvariant
                                         : EventRecord::Cause::kCrossing;
    running = JumpAndIterate(std::move(jumps), cause);
    *restart = true;
  }
  // A component that reached its invariant boundary and has not left its mode (nothing was
  // enabled, or only other components jumped at this instant) violates its invariant.
  for (size_t c = 0; running && c < reached_invariant_.size(); ++c) {
    if (reached_invariant_[c].empty()) continue;
    result_.status = SimulationStatus::kInvariantViolated;
    result_.message = "at t = " + FormatNumber(t_) + " the state leaves the invariant '" +
                      reached_invariant_[c] + "' of mode " + ModesLabel() +
                      " and no transition is enabled";
    running = false;
  }
  if (running && jumped && ZenoCheck()) running = false;
  if (running && p.exact && !jumped) Settle();
  return running;
}

void EventLoop::Settle() {
  if (!(t_ == settled_time_ && result_.events.size() == settled_events_)) {
    settled_.assign(run_.roots().size(), 0);
    settled_time_ = t_;
    settled_events_ = result_.events.size();
  }
  for (int r : crossed_) settled_[r] = 1;
}

bool EventLoop::ReachStopTimes(bool* restart) {
  // Stop times reached by this step (also when a root lies exactly on one: otherwise the sample
  // or the input jump there would be skipped, and the next Advance would be asked to stop at
  // the current time).
  if (t_ >= next_uniform_ && options_.sample_step > 0.0 && t_ < until_) {
    Record(StateSample::Kind::kSample);
    // The k-th sample is at k * sample_step exactly (no accumulated drift).
    next_uniform_ = std::min(
        until_, options_.sample_step * (std::floor(t_ / options_.sample_step + 0.5) + 1.0));
  }
  RecordListed();
  next_sample_ = NextSampleTime();
  if (next_break_ < breakpoints_.size() && t_ >= breakpoints_[next_break_]) {
    run_.SetStepInputs(t_);
    run_.Load(t_, x_.data());
    settled_time_ = std::numeric_limits<double>::quiet_NaN();  // the inputs changed
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
    settled_time_ = std::numeric_limits<double>::quiet_NaN();
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
  if (restart || !p.exact) anchored_ = false;
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
  if (auto outside = StateOutsideInvariant(run_, result_.samples, simulator_, exempt_from)) {
    TruncateUnresolved(result_, outside->first, std::move(outside->second));
  }
  return std::move(result_);
}

std::vector<Jump> EventLoop::Candidates() const {
  std::vector<Jump> jumps;
  for (int pass = 0; pass < 2; ++pass) {  // urgent first, then lazy
    const Urgency urgency = pass == 0 ? Urgency::kUrgent : Urgency::kLazy;
    for (size_t c = 0; c < components_.size(); ++c) {
      if (urgency == Urgency::kLazy && reached_invariant_[c].empty()) continue;
      const CompiledComponent& cc = components_[c];
      for (int ti : cc.modes[run_.modes()[c]].outgoing) {
        const CompiledTransition& tr = cc.transitions[ti];
        if (tr.urgency != urgency) continue;
        const bool crossed_now = GuardReached(static_cast<int>(c), ti);
        const bool enabled = urgency == Urgency::kLazy
                                 ? run_.GuardHolds(static_cast<int>(c), ti, true)
                                 : (crossed_now ? run_.GuardHolds(static_cast<int>(c), ti, true)
                                                : run_.GuardHolds(static_cast<int>(c), ti, false));
        if (!enabled) continue;
        // Synchronisation partners.
        Jump jump = {{static_cast<int>(c), ti}};
        if (tr.label.empty() || AddPartners(c, tr.label, &jump)) jumps.push_back(std::move(jump));
      }
    }
  }
  return jumps;
}

bool EventLoop::AddPartners(size_t c, const std::string& label, Jump* jump) const {
  for (size_t d = 0; d < components_.size(); ++d) {
    if (d == c || !components_[d].alphabet.count(label)) continue;
    const CompiledComponent& dc = components_[d];
    bool found = false;
    for (int ui : dc.modes[run_.modes()[d]].outgoing) {
      // A partner's guard is read as the leader's: in its closure only where it crossed at this
      // instant (a comparison of an input or parameter stays strict, as in every engine).
      if (dc.transitions[ui].label == label &&
          run_.GuardHolds(static_cast<int>(d), ui, GuardReached(static_cast<int>(d), ui))) {
        jump->emplace_back(static_cast<int>(d), ui);
        found = true;
        break;
      }
    }
    if (!found) return false;
  }
  return true;
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
    for (const auto& [c, ti] : jumps.front()) {  // these components are in new modes now
      reached_invariant_[c].clear();
      reached_guards_[c].clear();
    }
    if (auto violated = run_.ViolatedInvariant()) {
      // Still allowed if an urgent transition leaves at once.
      jumps = Candidates();
      if (jumps.empty()) {
        result_.status = SimulationStatus::kInvariantViolated;
        result_.message = "after the jump at t = " + FormatNumber(t_) + " the state violates '" +
                          *violated + "' of mode " + ModesLabel();
        return false;
      }
    } else {
      jumps = Candidates();
    }
    cause = CauseInIteration(jumps);
  }
  return true;
}

EventRecord::Cause EventLoop::CauseInIteration(const std::vector<Jump>& jumps) const {
  EventRecord::Cause cause = EventRecord::Cause::kEnabled;
  if (!jumps.empty()) {
    const auto [c0, t0] = jumps.front().front();
    if (components_[c0].transitions[t0].urgency == Urgency::kLazy) {
      cause = EventRecord::Cause::kInvariant;
    } else {
      for (const auto& [c, ti] : jumps.front()) {
        if (GuardReached(c, ti)) cause = EventRecord::Cause::kCrossing;
      }
    }
  }
  return cause;
}

void EventLoop::StopIterationZeno() {
  result_.status = SimulationStatus::kZeno;
  result_.message = "more than " + std::to_string(options_.max_event_iterations) +
                    " jumps at t = " + FormatNumber(t_) + " (event iteration does not settle)";
  ZenoReport z;
  z.accumulation_time = t_;
  const size_t k = std::min<size_t>(result_.events.size(), 8);
  for (size_t i = result_.events.size() - k; i < result_.events.size(); ++i) {
    for (const auto& name : result_.events[i].transitions) z.cycle.push_back(name);
  }
  result_.zeno = z;
}

bool EventLoop::ZenoCheck() {
  const size_t k = static_cast<size_t>(std::max(options_.zeno_events, 4));
  const auto& ev = result_.events;
  if (ev.size() < k) return false;
  const double first = ev[ev.size() - k].time;
  const double last = ev.back().time;
  const double scale = std::max(1.0, std::abs(last));
  std::vector<double> d;  // the k - 1 intervals
  for (size_t i = ev.size() - k + 1; i < ev.size(); ++i) d.push_back(ev[i].time - ev[i - 1].time);
  double r = 0.0;
  const bool geometric = ShrinkGeometrically(d, &r);
  // The shortest cycle of transition names that repeats over the last k events.
  const std::vector<std::string> names = LastTransitionNames(ev, k);
  const std::vector<std::string> cycle = RepeatingCycle(names);
  const double remaining = geometric ? d.back() * r / (1.0 - r) : 0.0;
  const bool chattering = last - first < options_.zeno_window * scale;
  // Accumulation needs the events to repeat a cycle: a last event that breaks the pattern (the
  // ball's `stop` into `resting`) ends the sequence instead of continuing it.
  const bool accumulating =
      geometric && !cycle.empty() && remaining < options_.zeno_horizon * scale;
  if (!chattering && !accumulating) return false;
  ZenoReport z;
  z.accumulation_time = geometric ? last + remaining : last;
  z.cycle = cycle.empty() ? names : cycle;
  result_.status = SimulationStatus::kZeno;
  result_.message = std::to_string(k) + " events within " + FormatNumber(last - first) +
                    " time units before t = " + FormatNumber(last) +
                    "; events accumulate near t = " + FormatNumber(z.accumulation_time);
  result_.zeno = std::move(z);
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
  for (size_t c = 0; c < reached_invariant_.size(); ++c) {
    if (auto violated = run_.ViolatedInvariantOf(c)) reached_invariant_[c] = *violated;
  }
  std::vector<Jump> jumps = Candidates();
  EventRecord::Cause cause = EventRecord::Cause::kEnabled;
  if (!jumps.empty()) {
    const auto [c0, t0] = jumps.front().front();
    if (components_[c0].transitions[t0].urgency == Urgency::kLazy) {
      cause = EventRecord::Cause::kInvariant;
    }
  }
  if (!JumpAndIterate(std::move(jumps), cause)) return false;
  for (size_t c = 0; c < reached_invariant_.size(); ++c) {
    if (reached_invariant_[c].empty()) continue;
    result_.status = SimulationStatus::kInvariantViolated;
    result_.message = "at t = " + FormatNumber(t_) + " the input jump leaves the state outside " +
                      "the invariant '" + reached_invariant_[c] + "' of mode " + ModesLabel() +
                      " and no transition is enabled";
    return false;
  }
  return !ZenoCheck();
}

void EventLoop::ForgetReached() {
  for (auto& s : reached_invariant_) s.clear();
  for (auto& g : reached_guards_) g.clear();
}

void EventLoop::NoteReached(const std::vector<int>& crossed) {
  for (int r : crossed) {
    const RootRef& ref = run_.roots()[r];
    if (ref.invariant) {
      reached_invariant_[ref.component] = components_[ref.component]
                                              .modes[run_.modes()[ref.component]]
                                              .invariant[ref.comparison]
                                              .text;
    } else {
      reached_guards_[ref.component].push_back(ref.index);
    }
  }
}

bool EventLoop::GuardReached(int c, int ti) const {
  return std::find(reached_guards_[c].begin(), reached_guards_[c].end(), ti) !=
         reached_guards_[c].end();
}

void EventLoop::Record(StateSample::Kind kind) {
  result_.samples.push_back({t_, kind, run_.modes(), x_.head(n_)});
}

void EventLoop::RecordListed() {
  const std::vector<double>& listed = options_.sample_times;
  while (next_listed_ < listed.size() && listed[next_listed_] <= t_) {
    Record(StateSample::Kind::kSample);
    ++next_listed_;
  }
}

double EventLoop::NextSampleTime() const {
  const std::vector<double>& listed = options_.sample_times;
  return std::min(next_uniform_, next_listed_ < listed.size() ? listed[next_listed_] : until_);
}

void EventLoop::EvaluateRoots(double time, const Eigen::VectorXd& state, std::vector<double>* g) {
  g->resize(run_.roots().size());
  if (!g->empty()) run_.Roots(time, state.data(), g->data());
}

bool EventLoop::IsSettled(size_t i, double time) const {
  return time == settled_time_ && result_.events.size() == settled_events_ && i < settled_.size() &&
         settled_[i] != 0;
}

bool EventLoop::OnBoundary(size_t i) const {
  const RootRef& ref = run_.roots()[i];
  return ref.direction != 0 &&
         (g_prev_[i] == 0.0 || (ref.invariant && ref.direction * g_prev_[i] > 0.0 &&
                                std::abs(g_prev_[i]) <= options_.event_tolerance));
}

}  // namespace

SimulationResult Simulator::Run(const SimulationOptions& options,
                                std::span<const InputSignal> signals) const {
  const System& system = *c_->system;
  const double until = Horizon(system, options);
  ValidateSimulationOptions(options, until);
  ValidateSampleTimes(options, until);
  const std::vector<InputSignal> inputs = MergedInputs(system, signals);
  ValidateInputs(system, inputs);
  std::vector<double> breakpoints = Breakpoints(inputs, until, options.lazy_schedule);

  // Initial state.
  const int n = static_cast<int>(c_->variable_slots.size());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(std::max(n, 1));
  std::vector<int> modes;
  for (const CompiledComponent& cc : c_->components) {
    modes.push_back(cc.initial_mode);
    for (const auto& [index, value] : cc.initial_values) x[index] = value;
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      throw std::invalid_argument("initial value of '" + c_->variable_names[i] + "' is not finite");
    }
  }

  hybrid::Run run(c_->components, c_->variable_slots, ParameterEnvironment(options.parameters),
                  inputs, options);
  const double t = 0.0;
  run.SetStepInputs(t);
  run.SetModes(modes);
  run.Load(t, x.data());
  if (auto violated = run.ViolatedInvariant()) {
    throw std::invalid_argument("the initial state violates the invariant '" + *violated +
                                "' of mode " + ModeLabel(modes));
  }
  EventLoop loop(*this, c_->components, run, options, until, std::move(breakpoints), std::move(x));
  return loop.Simulate();
}

std::optional<std::string> Simulator::FirstStateOutsideInvariant(
    const SimulationResult& result, const SimulationOptions& options,
    std::span<const InputSignal> signals) const {
  const size_t n = c_->variable_slots.size();
  for (const StateSample& s : result.samples) {
    bool modes_ok = s.modes.size() == c_->components.size();
    for (size_t c = 0; c < s.modes.size() && modes_ok; ++c) {
      modes_ok = s.modes[c] >= 0 && s.modes[c] < static_cast<int>(c_->components[c].modes.size());
    }
    if (!modes_ok || static_cast<size_t>(s.x.size()) != n) {
      throw std::invalid_argument("a recorded state does not fit the model (modes or variables)");
    }
  }
  hybrid::Run run(c_->components, c_->variable_slots, ParameterEnvironment(options.parameters),
                  MergedInputs(*c_->system, signals), options);
  const auto outside = StateOutsideInvariant(run, result.samples, *this);
  if (!outside) return std::nullopt;
  return outside->second;
}

}  // namespace hybrid
