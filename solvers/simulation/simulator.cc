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

// Residual semantics. `closure`: strict comparisons are taken as non-strict.
bool Holds(Relation relation, double r, double tol, bool closure) {
  switch (relation) {
    case Relation::kLess:
      return closure ? r <= tol : r < 0.0;
    case Relation::kLessEqual:
      return r <= tol;
    case Relation::kGreater:
      return closure ? r >= -tol : r > 0.0;
    case Relation::kGreaterEqual:
      return r >= -tol;
    case Relation::kEqual:
      return std::abs(r) <= tol;
  }
  return false;
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

}  // namespace

struct Simulator::Compiled {
  const System* system = nullptr;
  std::vector<std::string> variable_names;
  std::vector<int> variable_slots;  // index in x -> System slot
  std::vector<CompiledComponent> components;
  std::vector<double> parameter_env;  // System slots, parameters filled
};

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
  for (const Component& comp : system.components()) {
    const Automaton& a = comp.automaton;
    auto global = [&](const Expression& e) {
      return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
        const int g = comp.global_slot[slot];
        return Expression::Symbol(symbols[g].name, g);
      });
    };
    auto linearity = [&](const Expression& e) {
      Linearity l;
      l.slots = e.Slots();
      const Expression folded =
          e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
            if (symbols[slot].kind != SymbolKind::kParameter) return std::nullopt;
            return Expression::Constant(c_->parameter_env[slot]);
          });
      if (const auto affine = folded.AsAffine()) {
        l.terms.emplace();
        for (const auto& [slot, coefficient] : affine->terms) {
          if (x_index[slot] >= 0) l.terms->emplace_back(x_index[slot], coefficient);
        }
      }
      return l;
    };
    auto comparison = [&](const Comparison& c) {
      const Expression residual = global(c.Residual());
      return CompiledComparison{CompiledExpression(residual),
                                c.relation,
                                c.ToString(),
                                linearity(residual),
                                CompiledExpression(global(c.lhs)),
                                CompiledExpression(global(c.rhs)),
                                MayJump(residual, [&](int slot) {
                                  return symbols[slot].kind == SymbolKind::kVariable ||
                                         symbols[slot].kind == SymbolKind::kInput;
                                })};
    };
    CompiledComponent cc;
    cc.instance = comp.instance;
    for (const Mode& m : a.modes()) {
      CompiledMode cm;
      cm.constant_rate = true;
      for (const auto& [slot, rhs] : m.flows) {
        const Expression e = global(rhs);
        cm.flows.emplace_back(x_index[comp.global_slot[slot]], CompiledExpression(e));
        for (int read : e.Slots()) {
          cm.constant_rate = cm.constant_rate && x_index[read] < 0;
          cm.flow_slots.push_back(read);
        }
      }
      for (const Comparison& c : m.invariant.comparisons) cm.invariant.push_back(comparison(c));
      for (const auto& [slot, value] : m.discrete_values) {
        cm.discrete.emplace_back(comp.global_slot[slot], value);
      }
      cc.mode_names.push_back(m.name);
      cc.modes.push_back(std::move(cm));
    }
    for (int t = 0; t < a.num_transitions(); ++t) {
      const Transition& tr = a.transitions()[t];
      CompiledTransition ct;
      ct.name = comp.instance.empty() ? tr.name : comp.instance + "." + tr.name;
      ct.label = tr.label;
      ct.source = tr.source.value();
      ct.target = tr.target.value();
      ct.urgency = tr.urgency;
      for (const Comparison& c : tr.guard.comparisons) ct.guard.push_back(comparison(c));
      for (const Reset& r : tr.resets) {
        ct.resets.emplace_back(x_index[comp.global_slot[r.slot]],
                               CompiledExpression(global(r.value)));
      }
      if (!tr.label.empty()) cc.alphabet.insert(tr.label);
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
      cc.initial_values.emplace_back(x_index[comp.global_slot[v.slot]], 0.5 * (lo + hi));
    }
    c_->components.push_back(std::move(cc));
  }
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

  void Derivatives(double t, const double* x, double* dxdt) override {
    Load(t, x);
    for (size_t i = 0; i < x_size(); ++i) dxdt[i] = 0.0;
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

SimulationResult Simulator::Run(const SimulationOptions& options,
                                std::span<const InputSignal> signals) const {
  const System& system = *c_->system;
  const SymbolTable& symbols = system.symbols();
  auto fail = [&](const std::string& message) { throw std::invalid_argument(message); };

  // Horizon and inputs.
  double until = 0.0;
  if (options.until) {
    until = *options.until;
  } else if (system.scenario()) {
    until = system.scenario()->until;
  } else {
    fail("no horizon: give one (--until) or declare a scenario in the model");
  }
  ValidateSimulationOptions(options, until);
  for (size_t i = 0; i < options.sample_times.size(); ++i) {
    const double ts = options.sample_times[i];
    if (!std::isfinite(ts) || ts < 0.0 || ts > until) {
      fail("sample time " + FormatNumber(ts) + " lies outside [0, " + FormatNumber(until) + "]");
    }
    if (i > 0 && ts < options.sample_times[i - 1]) fail("sample times must not decrease");
  }
  const std::vector<InputSignal> inputs = MergedInputs(system, signals);
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

  // Breakpoints of the inputs: integration restarts there.
  std::vector<double> breakpoints;
  for (const InputSignal& s : inputs) {
    for (const auto& [t, v] : s.points) {
      if (t > 0.0 && t < until) breakpoints.push_back(t);
    }
  }
  std::sort(breakpoints.begin(), breakpoints.end());
  breakpoints.erase(std::unique(breakpoints.begin(), breakpoints.end()), breakpoints.end());

  // Initial state.
  const int n = static_cast<int>(c_->variable_slots.size());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(std::max(n, 1));
  std::vector<int> modes;
  for (const CompiledComponent& cc : c_->components) {
    modes.push_back(cc.initial_mode);
    for (const auto& [index, value] : cc.initial_values) x[index] = value;
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]))
      fail("initial value of '" + c_->variable_names[i] + "' is not finite");
  }

  hybrid::Run run(c_->components, c_->variable_slots, c_->parameter_env, inputs, options);
  double t = 0.0;
  run.SetStepInputs(t);
  run.SetModes(modes);
  run.Load(t, x.data());
  if (auto violated = run.ViolatedInvariant()) {
    fail("the initial state violates the invariant '" + *violated + "' of mode " +
         ModeLabel(modes));
  }

  SimulationResult result;
  auto record = [&](StateSample::Kind kind) {
    result.samples.push_back({t, kind, run.modes(), x.head(n)});
  };
  record(StateSample::Kind::kStart);

  // What the current instant reached and no jump has acted on yet, per component: the text of
  // an invariant comparison whose boundary it reached (empty: none) and the transitions whose
  // guard comparisons crossed. Set from the root functions that fired; kept through the event
  // iteration at that instant for the components that have not jumped, so that one component's
  // jump does not discard what another one reached at the same instant; forgotten when time
  // advances.
  std::vector<std::string> reached_invariant(c_->components.size());
  std::vector<std::vector<int>> reached_guards(c_->components.size());
  auto forget_reached = [&]() {
    for (auto& s : reached_invariant) s.clear();
    for (auto& g : reached_guards) g.clear();
  };
  auto note_reached = [&](const std::vector<int>& crossed) {
    for (int r : crossed) {
      const RootRef& ref = run.roots()[r];
      if (ref.invariant) {
        reached_invariant[ref.component] = c_->components[ref.component]
                                               .modes[run.modes()[ref.component]]
                                               .invariant[ref.comparison]
                                               .text;
      } else {
        reached_guards[ref.component].push_back(ref.index);
      }
    }
  };
  auto guard_reached = [&](int c, int ti) {
    return std::find(reached_guards[c].begin(), reached_guards[c].end(), ti) !=
           reached_guards[c].end();
  };

  // The transitions that can fire now, best first. Urgent transitions whose guard crossed at this
  // instant (reached_guards) are enabled when their guard holds in its closure, others when it
  // holds strictly. Lazy transitions of a component are candidates only when its invariant
  // boundary was reached (reached_invariant).
  auto candidates = [&]() {
    std::vector<Jump> jumps;
    for (int pass = 0; pass < 2; ++pass) {  // urgent first, then lazy
      const Urgency urgency = pass == 0 ? Urgency::kUrgent : Urgency::kLazy;
      for (size_t c = 0; c < c_->components.size(); ++c) {
        if (urgency == Urgency::kLazy && reached_invariant[c].empty()) continue;
        const CompiledComponent& cc = c_->components[c];
        for (int ti : cc.modes[run.modes()[c]].outgoing) {
          const CompiledTransition& tr = cc.transitions[ti];
          if (tr.urgency != urgency) continue;
          const bool crossed_now = guard_reached(static_cast<int>(c), ti);
          const bool enabled = urgency == Urgency::kLazy
                                   ? run.GuardHolds(static_cast<int>(c), ti, true)
                                   : (crossed_now ? run.GuardHolds(static_cast<int>(c), ti, true)
                                                  : run.GuardHolds(static_cast<int>(c), ti, false));
          if (!enabled) continue;
          // Synchronisation partners.
          Jump jump = {{static_cast<int>(c), ti}};
          bool blocked = false;
          if (!tr.label.empty()) {
            for (size_t d = 0; d < c_->components.size() && !blocked; ++d) {
              if (d == c || !c_->components[d].alphabet.count(tr.label)) continue;
              const CompiledComponent& dc = c_->components[d];
              bool found = false;
              for (int ui : dc.modes[run.modes()[d]].outgoing) {
                if (dc.transitions[ui].label == tr.label &&
                    run.GuardHolds(static_cast<int>(d), ui, true)) {
                  jump.emplace_back(static_cast<int>(d), ui);
                  found = true;
                  break;
                }
              }
              blocked = !found;
            }
          }
          if (!blocked) jumps.push_back(std::move(jump));
        }
      }
    }
    return jumps;
  };

  auto fire = [&](const Jump& jump, EventRecord::Cause cause) {
    EventRecord e;
    e.time = t;
    e.cause = cause;
    e.modes_before = run.modes();
    e.before = x.head(n);
    record(StateSample::Kind::kBeforeEvent);
    std::vector<int> modes_after = run.modes();
    Eigen::VectorXd x_after = x;
    for (const auto& [c, ti] : jump) {
      const CompiledTransition& tr = c_->components[c].transitions[ti];
      e.transitions.push_back(tr.name);
      if (e.label.empty()) e.label = tr.label;
      for (const auto& [index, value] : tr.resets)
        x_after[index] = value.Evaluate(run.env().data());
      modes_after[c] = tr.target;
    }
    x = x_after;
    run.SetModes(modes_after);
    run.Load(t, x.data());
    e.modes_after = run.modes();
    e.after = x.head(n);
    record(StateSample::Kind::kAfterEvent);
    result.events.push_back(std::move(e));
  };

  // Fires `first` and then whatever becomes enabled at the same instant. Returns false when the
  // run must stop (status set).
  auto jump_and_iterate = [&](std::vector<Jump> jumps, EventRecord::Cause cause) {
    for (int iteration = 0; !jumps.empty(); ++iteration) {
      if (iteration >= options.max_event_iterations) {
        result.status = SimulationStatus::kZeno;
        result.message = "more than " + std::to_string(options.max_event_iterations) +
                         " jumps at t = " + FormatNumber(t) + " (event iteration does not settle)";
        ZenoReport z;
        z.accumulation_time = t;
        const size_t k = std::min<size_t>(result.events.size(), 8);
        for (size_t i = result.events.size() - k; i < result.events.size(); ++i) {
          for (const auto& name : result.events[i].transitions) z.cycle.push_back(name);
        }
        result.zeno = z;
        return false;
      }
      if (static_cast<long>(result.events.size()) >= options.max_events) {
        result.status = SimulationStatus::kEventLimit;
        result.message = "more than " + std::to_string(options.max_events) + " events";
        return false;
      }
      fire(jumps.front(), cause);
      for (const auto& [c, ti] : jumps.front()) {  // these components are in new modes now
        reached_invariant[c].clear();
        reached_guards[c].clear();
      }
      if (auto violated = run.ViolatedInvariant()) {
        // Still allowed if an urgent transition leaves at once.
        jumps = candidates();
        if (jumps.empty()) {
          result.status = SimulationStatus::kInvariantViolated;
          result.message = "after the jump at t = " + FormatNumber(t) + " the state violates '" +
                           *violated + "' of mode " + ModeLabel(run.modes());
          return false;
        }
      } else {
        jumps = candidates();
      }
      // What remains at this instant: a lazy transition at its invariant boundary, an urgent one
      // whose guard crossed together with the one just taken, or one the jump enabled.
      cause = EventRecord::Cause::kEnabled;
      if (!jumps.empty()) {
        const auto [c0, t0] = jumps.front().front();
        if (c_->components[c0].transitions[t0].urgency == Urgency::kLazy) {
          cause = EventRecord::Cause::kInvariant;
        } else {
          for (const auto& [c, ti] : jumps.front()) {
            if (guard_reached(c, ti)) cause = EventRecord::Cause::kCrossing;
          }
        }
      }
    }
    return true;
  };

  // Zeno across time: many events in a vanishing window, or geometrically shrinking intervals
  // close to their accumulation point.
  auto zeno_check = [&]() {
    const size_t k = static_cast<size_t>(std::max(options.zeno_events, 4));
    const auto& ev = result.events;
    if (ev.size() < k) return false;
    const double first = ev[ev.size() - k].time;
    const double last = ev.back().time;
    const double scale = std::max(1.0, std::abs(last));
    std::vector<double> d;  // the k - 1 intervals
    for (size_t i = ev.size() - k + 1; i < ev.size(); ++i) d.push_back(ev[i].time - ev[i - 1].time);
    bool geometric = std::all_of(d.begin(), d.end(), [](double x) { return x > 0.0; });
    double r = 0.0;
    if (geometric) {
      r = std::pow(d.back() / d.front(), 1.0 / static_cast<double>(d.size() - 1));
      for (size_t i = 1; i < d.size() && geometric; ++i) {
        geometric = std::abs(d[i] / d[i - 1] - r) <= 0.01 * r;
      }
      geometric = geometric && r < 1.0;
    }
    // The shortest cycle of transition names that repeats over the last k events.
    std::vector<std::string> names, cycle;
    for (size_t i = ev.size() - k; i < ev.size(); ++i) {
      std::string joined;
      for (const auto& s : ev[i].transitions) joined += (joined.empty() ? "" : "+") + s;
      names.push_back(joined);
    }
    for (size_t p = 1; p <= names.size() / 2; ++p) {
      bool periodic = true;
      for (size_t i = p; i < names.size() && periodic; ++i) periodic = names[i] == names[i - p];
      if (periodic) {
        cycle.assign(names.end() - static_cast<long>(p), names.end());
        break;
      }
    }
    const double remaining = geometric ? d.back() * r / (1.0 - r) : 0.0;
    const bool chattering = last - first < options.zeno_window * scale;
    // Accumulation needs the events to repeat a cycle: a last event that breaks the pattern (the
    // ball's `stop` into `resting`) ends the sequence instead of continuing it.
    const bool accumulating =
        geometric && !cycle.empty() && remaining < options.zeno_horizon * scale;
    if (!chattering && !accumulating) return false;
    ZenoReport z;
    z.accumulation_time = geometric ? last + remaining : last;
    z.cycle = cycle.empty() ? names : cycle;
    result.status = SimulationStatus::kZeno;
    result.message = std::to_string(k) + " events within " + FormatNumber(last - first) +
                     " time units before t = " + FormatNumber(last) +
                     "; events accumulate near t = " + FormatNumber(z.accumulation_time);
    result.zeno = std::move(z);
    return true;
  };

  // A located event must sit on its boundary: the root functions that crossed are within their
  // resolution tolerance of zero at the state reached. Otherwise time, rounded to doubles, no
  // longer resolves the dynamics there (or the solver's root location failed): a message.
  auto unresolved_crossing = [&](const std::vector<int>& crossed) -> std::optional<std::string> {
    for (int i : crossed) {
      const auto off = run.OffBoundary(i);
      if (!off) continue;
      const RootRef& ref = run.roots()[i];
      const double resolution = std::nextafter(t, std::numeric_limits<double>::infinity()) - t;
      return "at t = " + FormatNumber(t) + " the event on '" + run.ComparisonOf(ref).text +
             "' in mode " + ModeLabel(run.modes()) + " cannot be located: the state reached is " +
             FormatNumber(std::abs(off->first)) + " from its boundary, beyond the tolerance " +
             FormatNumber(off->second) + "; time is resolved only to " + FormatNumber(resolution) +
             " there (a shorter horizon, or larger tolerances)";
    }
    return std::nullopt;
  };

  // A step input jumped at t: an urgent guard may hold now, and a component the jump leaves
  // outside its invariant has reached its boundary at this instant (its lazy transitions may
  // fire; if none does, the invariant is violated). Returns false when the run must stop.
  auto input_jump = [&]() {
    for (size_t c = 0; c < reached_invariant.size(); ++c) {
      if (auto violated = run.ViolatedInvariantOf(c)) reached_invariant[c] = *violated;
    }
    std::vector<Jump> jumps = candidates();
    EventRecord::Cause cause = EventRecord::Cause::kEnabled;
    if (!jumps.empty()) {
      const auto [c0, t0] = jumps.front().front();
      if (c_->components[c0].transitions[t0].urgency == Urgency::kLazy) {
        cause = EventRecord::Cause::kInvariant;
      }
    }
    if (!jump_and_iterate(std::move(jumps), cause)) return false;
    for (size_t c = 0; c < reached_invariant.size(); ++c) {
      if (reached_invariant[c].empty()) continue;
      result.status = SimulationStatus::kInvariantViolated;
      result.message = "at t = " + FormatNumber(t) + " the input jump leaves the state outside " +
                       "the invariant '" + reached_invariant[c] + "' of mode " +
                       ModeLabel(run.modes()) + " and no transition is enabled";
      return false;
    }
    return !zeno_check();
  };

  CvodeIntegrator::Options io;
  io.relative_tolerance = options.relative_tolerance;
  io.absolute_tolerance = options.absolute_tolerance;
  io.max_step = options.max_step;
  // Created on first use: a run that stays in constant-rate modes never needs it.
  std::optional<CvodeIntegrator> integrator;
  bool stale = true;  // the integrator must be restarted at (t, x) before its next step
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(std::max(n, 1));
  // Exact segments are computed from an anchor, the state where the current constant rates took
  // over (after a jump, an input breakpoint, a restart or a solver pass), not from the last stop:
  // a recorded sample stops the loop, and computing on from its rounded state made the state at
  // a later event (a guard reached exactly at an input breakpoint) depend on --sample.
  bool anchored = false;
  double anchor_t = 0.0;
  Eigen::VectorXd anchor_x, anchor_rate;
  std::vector<double> anchor_g;

  bool running = jump_and_iterate(candidates(), EventRecord::Cause::kEnabled);
  if (running && zeno_check()) running = false;
  size_t next_break = 0;
  double next_uniform = options.sample_step > 0.0 ? options.sample_step : until;
  size_t next_listed = 0;
  const std::vector<double>& listed = options.sample_times;
  // Listed times already reached (0, or before the first step): recorded now, after the start.
  auto record_listed = [&]() {
    while (next_listed < listed.size() && listed[next_listed] <= t) {
      record(StateSample::Kind::kSample);
      ++next_listed;
    }
  };
  auto next_sample_time = [&]() {
    return std::min(next_uniform, next_listed < listed.size() ? listed[next_listed] : until);
  };
  record_listed();
  double next_sample = next_sample_time();
  std::vector<double> g_prev(run.roots().size()), g_mid;
  auto evaluate_roots = [&](double time, const Eigen::VectorXd& state, std::vector<double>* g) {
    g->resize(run.roots().size());
    if (!g->empty()) run.Roots(time, state.data(), g->data());
  };
  evaluate_roots(t, x, &g_prev);
  Eigen::VectorXd x_new, x_mid, x_start;
  // Per-step buffers, reused so that a step allocates nothing.
  std::vector<double> ga, gm;
  std::vector<int> crossed;
  // Exact segments: the root functions reported at `settled_time` that fired nothing there. The
  // state reached at a crossing is rounded, so such a root function can be left a hair before its
  // boundary (theta2 = -8.9e-16 for `theta2 == 0`); its crossing time t - g / s then rounds to t
  // itself and would be reported again and again at the same instant without anything changing.
  // A settled root function is not reported again at that instant; a jump (new root functions)
  // or an input jump there (the other conjuncts may hold now) unsettles them all.
  std::vector<char> settled;
  double settled_time = std::numeric_limits<double>::quiet_NaN();
  size_t settled_events = 0;
  auto is_settled = [&](size_t i, double time) {
    return time == settled_time && result.events.size() == settled_events && i < settled.size() &&
           settled[i] != 0;
  };
  // Consecutive passes of the loop that neither advanced time nor jumped. A few are normal (a
  // root at the segment start, then a stop time there); more mean that the loop is stuck.
  constexpr int kMaxStalledPasses = 100;
  // A segment after a restart shorter than this times |t| is not given to CVODE (see its use).
  constexpr double kShortGap = 100 * std::numeric_limits<double>::epsilon();
  int stalled = 0;
  long passes = 0;  // SimulationOptions::max_steps

  while (running && t < until) {
    if (++passes > options.max_steps) {
      result.status = SimulationStatus::kStepLimit;
      result.message =
          "more than " + std::to_string(options.max_steps) +
          " integration steps (solver steps and exact segments) before t = " + FormatNumber(t);
      break;
    }
    while (next_break < breakpoints.size() && breakpoints[next_break] <= t) ++next_break;
    const double t_stop = std::min(
        {until, next_sample, next_break < breakpoints.size() ? breakpoints[next_break] : until});
    const double t_prev = t;
    x_start = x;
    const size_t events_before = result.events.size();
    double t_new = t;
    crossed.clear();
    auto on_boundary = [&](size_t i) {
      const RootRef& ref = run.roots()[i];
      return ref.direction != 0 &&
             (g_prev[i] == 0.0 || (ref.invariant && ref.direction * g_prev[i] > 0.0 &&
                                   std::abs(g_prev[i]) <= options.event_tolerance));
    };
    // Exact segment: constant rates and affine root functions. Each root function is
    // g_i(t) = g_i(t_prev) + s_i (t - t_prev); the first crossing in its direction is a division.
    // A root function starting on its boundary is left to the solver path (its conventions for
    // that case apply), so both paths fire the same events.
    const bool at_breakpoint = next_break < breakpoints.size() && t_stop == breakpoints[next_break];
    bool exact = run.exact();
    if (exact) {
      run.Derivatives(t, x.data(), rate.data());
      // On the anchor's line, a root function is exactly on its boundary where its line says
      // so, not where a stop's rounded state happens to give 0.
      const bool on_line = anchored && rate == anchor_rate;
      for (size_t i = 0; i < g_prev.size() && exact; ++i) {
        const double slope = run.Slope(static_cast<int>(i), rate);
        const bool boundary =
            on_line && g_prev[i] == 0.0 ? anchor_t - anchor_g[i] / slope == t_prev : on_boundary(i);
        exact = !(boundary && run.roots()[i].direction * slope > 0.0);
      }
    }
    CvodeIntegrator::Status status;
    bool short_gap = false;  // stepped over a gap too short for CVODE
    bool restarted = false;  // CVODE was restarted for this pass
    if (exact) {
      if (!anchored || rate != anchor_rate) {
        anchored = true;
        anchor_t = t_prev;
        anchor_x = x;
        anchor_rate = rate;
        anchor_g = g_prev;
      }
      const double tie =
          4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t_stop));
      // A crossing up to a tie after a recorded sample's time still ends this pass, at its own
      // time: the sample must not split crossings that the run without it fires together (and
      // chooses between by priority), nor move one onto its time; the sample is then recorded
      // at the event's time. Input breakpoints and the horizon are hard stops.
      const double limit = at_breakpoint || t_stop >= until ? t_stop : t_stop + tie;
      t_new = limit;  // the earliest crossing so far
      for (size_t i = 0; i < g_prev.size(); ++i) {
        const double slope = run.Slope(static_cast<int>(i), rate);
        const int dir = run.roots()[i].direction;
        // Where the root function crosses is decided on its line from the anchor, never from
        // the rounded state of a stop in between (which may already lie a hair past the
        // boundary, so that the crossing would be missed).
        const double g0 = anchor_g[i];
        const bool toward =
            (dir <= 0 && g0 > 0.0 && slope < 0.0) || (dir >= 0 && g0 < 0.0 && slope > 0.0);
        if (!toward) continue;
        const double on_line = anchor_t - g0 / slope;
        // Crossed before this pass: reported by the pass that reached it.
        if (on_line < t_prev - tie) continue;
        const double crossing = std::max(on_line, t_prev);
        if (crossing > t_new + tie || crossing > limit) continue;
        // Already reported at this instant, and nothing fired: no progress to make here.
        if (crossing <= t_prev + tie && is_settled(i, t_prev)) continue;
        // An invariant boundary reached exactly at an input breakpoint is not left yet: the
        // input changes there. The next segment starts on the boundary and decides.
        if (run.roots()[i].invariant && at_breakpoint && crossing >= t_stop - tie) continue;
        if (crossing < t_new - tie) crossed.clear();
        t_new = std::min(t_new, crossing);
        crossed.push_back(static_cast<int>(i));
      }
      if (crossed.empty()) t_new = t_stop;
      status =
          crossed.empty() ? CvodeIntegrator::Status::kReachedTime : CvodeIntegrator::Status::kRoot;
      x_new = anchor_x + rate.head(x.size()) * (t_new - anchor_t);
      stale = true;
    } else if (stale && t_stop - t <= kShortGap * std::max(std::abs(t), std::abs(t_stop))) {
      // A stop time a few ulps after a restart (a jump one ulp before a sample time or an input
      // breakpoint): CVODE cannot start a step that short (CV_TOO_CLOSE), and CVODE itself
      // locates roots only to about this precision. Move there on the tangent instead; a root
      // function that changes sign, or leaves its boundary, crosses at the stop time.
      short_gap = true;
      run.Derivatives(t, x.data(), rate.data());
      t_new = t_stop;
      x_new = x + rate.head(x.size()) * (t_new - t_prev);
      evaluate_roots(t_new, x_new, &g_mid);
      for (size_t i = 0; i < g_mid.size(); ++i) {
        const int dir = run.roots()[i].direction;
        const double g0 = g_prev[i], g1 = g_mid[i];
        const bool moved = on_boundary(i) ? dir * g1 > dir * g0
                                          : (dir <= 0 && g0 > 0.0 && g1 <= 0.0) ||
                                                (dir >= 0 && g0 < 0.0 && g1 >= 0.0);
        if (moved) crossed.push_back(static_cast<int>(i));
      }
      status =
          crossed.empty() ? CvodeIntegrator::Status::kReachedTime : CvodeIntegrator::Status::kRoot;
    } else {
      if (!integrator) integrator.emplace(&run, std::max(n, 1), io);
      if (stale) {
        integrator->Restart(t, x, run.directions());
        stale = false;
        restarted = true;
      }
      status = integrator->Advance(t_stop, &t_new, &x_new);
      ++result.steps;
    }
    if (status == CvodeIntegrator::Status::kFailure) {
      result.status = SimulationStatus::kSolverFailure;
      result.message = integrator->message() + " at t = " + FormatNumber(t_new) + " in mode " +
                       ModeLabel(run.modes());
      break;
    }
    // Roots CVODE reports, or a double crossing inside the step found on the interpolant.
    if (!exact && !short_gap && status == CvodeIntegrator::Status::kRoot) {
      for (size_t i = 0; i < integrator->root_info().size(); ++i) {
        if (integrator->root_info()[i] != 0) crossed.push_back(static_cast<int>(i));
      }
    }
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
    bool interior = false;
    bool any_on_boundary = false;
    for (size_t i = 0; i < g_prev.size() && !any_on_boundary; ++i) {
      any_on_boundary = on_boundary(i);
    }
    if (!exact && !short_gap && (options.dense_checks > 0 || any_on_boundary) &&
        !run.roots().empty() && t_new > t_prev) {
      ga = g_prev;
      double a = t_prev;
      const int points = options.dense_checks + 1;  // the last one is the step end
      for (int j = 1; j <= points && !interior; ++j) {
        const bool end = j == points;
        if (end && !any_on_boundary) break;  // CVODE watches the step ends
        const double b = end ? t_new : t_prev + (t_new - t_prev) * j / points;
        if (end) {
          evaluate_roots(b, x_new, &g_mid);
        } else {
          if (!integrator->Interpolate(b, &x_mid)) break;
          evaluate_roots(b, x_mid, &g_mid);
        }
        for (size_t i = 0; i < g_mid.size() && !interior; ++i) {
          const int dir = run.roots()[i].direction;
          const bool boundary = on_boundary(i);
          if (end && !boundary) continue;
          // Whether root i has crossed at g since `a` or, starting on its boundary, moved on in
          // its direction since the step start.
          const double g0 = boundary ? g_prev[i] : ga[i];
          auto reached = [&](double g) {
            return boundary ? dir * g > dir * g0 : g == 0.0 || (g > 0.0) != (g0 > 0.0);
          };
          const bool change = boundary ? reached(g_mid[i])
                                       : (g0 > 0.0 && g_mid[i] <= 0.0 && dir <= 0) ||
                                             (g0 < 0.0 && g_mid[i] >= 0.0 && dir >= 0);
          if (!change) continue;
          // Bisection on the interpolant: not reached at lo, reached at hi.
          double lo = a, hi = b;
          while (hi - lo >
                 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(hi))) {
            const double mid = 0.5 * (lo + hi);
            if (!integrator->Interpolate(mid, &x_mid)) break;
            evaluate_roots(mid, x_mid, &gm);
            if (reached(gm[i]))
              hi = mid;
            else
              lo = mid;
          }
          t_new = hi;
          integrator->Interpolate(t_new, &x_new);
          crossed = {static_cast<int>(i)};
          interior = true;
        }
        a = b;
        ga = g_mid;
      }
    }
    t = t_new;
    x = x_new;
    run.Load(t, x.data());
    bool restart = interior;

    forget_reached();  // a new instant
    if (status == CvodeIntegrator::Status::kRoot || interior) {
      if (auto off = unresolved_crossing(crossed)) {
        // The state reached is not trustworthy: the run ends at the start of this pass.
        result.status = SimulationStatus::kUnresolved;
        result.message = *off;
        t = t_prev;
        x = x_start;
        run.Load(t, x.data());
        break;
      }
      note_reached(crossed);
      std::vector<Jump> jumps = candidates();
      const bool jumped = !jumps.empty();
      if (jumped) {
        const auto [c0, t0] = jumps.front().front();
        const EventRecord::Cause cause =
            c_->components[c0].transitions[t0].urgency == Urgency::kLazy
                ? EventRecord::Cause::kInvariant
                : EventRecord::Cause::kCrossing;
        running = jump_and_iterate(std::move(jumps), cause);
        restart = true;
      }
      // A component that reached its invariant boundary and has not left its mode (nothing was
      // enabled, or only other components jumped at this instant) violates its invariant.
      for (size_t c = 0; running && c < reached_invariant.size(); ++c) {
        if (reached_invariant[c].empty()) continue;
        result.status = SimulationStatus::kInvariantViolated;
        result.message = "at t = " + FormatNumber(t) + " the state leaves the invariant '" +
                         reached_invariant[c] + "' of mode " + ModeLabel(run.modes()) +
                         " and no transition is enabled";
        running = false;
      }
      if (running && jumped && zeno_check()) running = false;
      if (running && exact && !jumped) {
        if (!(t == settled_time && result.events.size() == settled_events)) {
          settled.assign(run.roots().size(), 0);
          settled_time = t;
          settled_events = result.events.size();
        }
        for (int r : crossed) settled[r] = 1;
      }
    }
    if (!running) break;
    // Stop times reached by this step (also when a root lies exactly on one: otherwise the sample
    // or the input jump there would be skipped, and the next Advance would be asked to stop at
    // the current time).
    if (t >= next_uniform && options.sample_step > 0.0 && t < until) {
      record(StateSample::Kind::kSample);
      // The k-th sample is at k * sample_step exactly (no accumulated drift).
      next_uniform =
          std::min(until, options.sample_step * (std::floor(t / options.sample_step + 0.5) + 1.0));
    }
    record_listed();
    next_sample = next_sample_time();
    if (next_break < breakpoints.size() && t >= breakpoints[next_break]) {
      run.SetStepInputs(t);
      run.Load(t, x.data());
      settled_time = std::numeric_limits<double>::quiet_NaN();  // the inputs changed
      running = input_jump();
      restart = true;
    }
    if (!running) break;
    evaluate_roots(t, x, &g_prev);
    // Also restart after a root that fired nothing when some root function is exactly 0 there:
    // CVODE would fail on the next step (CV_ILL_INPUT, "root found at and very near t") if it is
    // still 0 just after the root, as when the state lands exactly on a boundary value.
    if (status == CvodeIntegrator::Status::kRoot && !restart) {
      restart = std::find(g_prev.begin(), g_prev.end(), 0.0) != g_prev.end();
    }
    if (restart) stale = true;
    if (restart || !exact) anchored = false;
    // Never spin: every pass must advance time or jump, but for a bounded number of passes.
    // CVODE steps that continue without a restart are not counted: steps shorter than the
    // resolution of t (t + h = t, as a solution blows up) are bounded by its max_steps, which
    // reports CV_TOO_MUCH_WORK.
    const bool continued = !exact && !short_gap && !restarted;
    if (t > t_prev || result.events.size() != events_before) {
      stalled = 0;
    } else if (!continued && ++stalled > kMaxStalledPasses) {
      result.status = SimulationStatus::kSolverFailure;
      result.message = "no progress at t = " + FormatNumber(t) + " in mode " +
                       ModeLabel(run.modes()) + ": " + std::to_string(kMaxStalledPasses) +
                       " passes neither advanced time nor took a jump";
      break;
    }
  }
  if (result.status == SimulationStatus::kCompleted && t < until) {
    result.status = SimulationStatus::kSolverFailure;
    result.message = "stopped before the horizon";
  }
  record(StateSample::Kind::kEnd);
  // The general guard: no recorded state outside its modes' invariants (the final instant of an
  // invariant violation aside), whatever the status; the first one ends the run there.
  const double exempt_from = result.status == SimulationStatus::kInvariantViolated
                                 ? t
                                 : std::numeric_limits<double>::infinity();
  if (auto outside = StateOutsideInvariant(run, result.samples, *this, exempt_from)) {
    TruncateUnresolved(result, outside->first, std::move(outside->second));
  }
  return result;
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
  hybrid::Run run(c_->components, c_->variable_slots, c_->parameter_env,
                  MergedInputs(*c_->system, signals), options);
  const auto outside = StateOutsideInvariant(run, result.samples, *this);
  if (!outside) return std::nullopt;
  return outside->second;
}

}  // namespace hybrid
