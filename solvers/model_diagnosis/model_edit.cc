#include "hybrid/model_diagnosis/model_edit.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

namespace hybrid {
namespace {

// Names already taken: the automaton's symbols and the identifiers handed out so far.
class Names {
 public:
  explicit Names(const Automaton& a) {
    for (int slot = 0; slot < a.symbols().size(); ++slot) taken_.insert(a.symbols()[slot].name);
  }
  // `base`, or base_2, base_3, ... if taken; then taken.
  std::string Unique(const std::string& base) {
    std::string name = base;
    for (int k = 2; taken_.contains(name); ++k) name = base + "_" + std::to_string(k);
    taken_.insert(name);
    return name;
  }

 private:
  std::set<std::string> taken_;
};

std::string Identifier(std::string name) {
  std::replace(name.begin(), name.end(), '.', '_');
  return name;
}

// Whether `e` reads only parameters (or nothing).
bool ReadsOnlyParameters(const Automaton& a, const Expression& e) {
  for (int slot : e.Slots()) {
    if (a.symbols()[slot].kind != SymbolKind::kParameter) return false;
  }
  return true;
}

// Measured [min, max] of each observed variable (by name); absent when never measured.
std::map<std::string, std::pair<double, double>> MeasuredRanges(const TraceData& data) {
  std::map<std::string, std::pair<double, double>> ranges;
  for (const TraceRun& run : data.runs) {
    for (size_t c = 0; c < data.observed_names.size(); ++c) {
      for (double v : run.observed[c]) {
        if (std::isnan(v)) continue;
        auto [it, fresh] = ranges.try_emplace(data.observed_names[c], v, v);
        it->second.first = std::min(it->second.first, v);
        it->second.second = std::max(it->second.second, v);
      }
    }
  }
  return ranges;
}

// The candidate generation's shared state.
class Generator {
 public:
  Generator(const Automaton& a, const TraceData& data)
      : a_(a), names_(a), env_(a.ParameterEnvironment()), ranges_(MeasuredRanges(data)) {
    for (const TraceRun& run : data.runs) {
      if (!run.time.empty()) duration_ = std::max(duration_, run.time.back());
    }
  }

  CandidateSet Run(const TraceData& data) {
    AddParameters();
    for (const std::string& x : data.observed_names) AddSensor(x);
    AddFlowGains();
    for (const Transition& t : a_.transitions()) {
      if (t.urgency != Urgency::kUrgent) {
        if (!t.guard.empty()) {
          set_.notes.push_back("the guard of lazy transition '" + t.name +
                               "' is not a candidate: a simulation takes a lazy transition at "
                               "its source's invariant boundary, so its guard never decides a "
                               "trace (the invariant's threshold is a candidate)");
        }
        continue;
      }
      AddThresholds(EditKind::kGuardThreshold, t.name, ".threshold", t.guard);
    }
    for (const Mode& m : a_.modes()) {
      AddThresholds(EditKind::kInvariantThreshold, m.name, ".invariant", m.invariant);
    }
    for (const InputInfo& in : a_.inputs()) AddInputOffset(in);
    for (const Transition& t : a_.transitions()) {
      if (t.urgency == Urgency::kUrgent && duration_ > 0) {
        Add(ModelEdit{EditKind::kDelay, t.name + ".delay", "", "", t.name, 0, 0.0, 0.0,
                      0.1 * duration_});
      }
    }
    return std::move(set_);
  }

 private:
  void Add(ModelEdit e, bool own_identifier = false) {
    if (!own_identifier) e.identifier = names_.Unique(Identifier(e.name));
    set_.edits.push_back(std::move(e));
  }

  void AddParameters() {
    for (const auto& [slot, value] : a_.parameters()) {
      if (!value.is_constant()) continue;  // defined from other parameters: follows them
      ModelEdit e;
      e.kind = EditKind::kParameter;
      e.name = e.identifier = a_.symbols()[slot].name;
      e.neutral = value.constant();
      if (const std::optional<Range> r = a_.ParameterRange(slot)) {
        e.lo = r->lo.Evaluate(env_);
        e.hi = r->hi.Evaluate(env_);
      } else {
        const double h = e.neutral == 0.0 ? 1.0 : 0.5 * std::abs(e.neutral);
        e.lo = e.neutral - h;
        e.hi = e.neutral + h;
      }
      if (e.hi > e.lo) Add(std::move(e), true);
    }
  }

  void AddSensor(const std::string& x) {
    const auto it = ranges_.find(x);
    const double span = it == ranges_.end() ? 0.0 : it->second.second - it->second.first;
    const double h = span > 0 ? 0.5 * span : 1.0;
    Add(ModelEdit{EditKind::kSensorBias, x + "_bias", "", x, "", 0, 0.0, -h, h, true});
    Add(ModelEdit{EditKind::kSensorGain, x + "_gain", "", x, "", 0, 1.0, 0.8, 1.2, true});
  }

  void AddFlowGains() {
    for (const Mode& m : a_.modes()) {
      for (const auto& [slot, f] : m.flows) {
        if (f.is_constant() && f.constant() == 0.0) continue;
        const std::string& x = a_.symbols()[slot].name;
        Add(ModelEdit{EditKind::kFlowGain, m.name + "." + x + "_gain", "", x, m.name, 0, 1.0, 0.5,
                      1.5});
      }
    }
  }

  // The half-width of a threshold's range for a comparison whose variable side is `side`.
  double ThresholdHalfWidth(const Expression& side, double value) const {
    const std::optional<AffineForm> form = side.AsAffine();
    if (form && form->terms.size() == 1) {
      const auto [slot, coefficient] = form->terms.front();
      const auto it = ranges_.find(a_.symbols()[slot].name);
      if (it != ranges_.end() && it->second.second > it->second.first) {
        return 0.25 * std::abs(coefficient) * (it->second.second - it->second.first);
      }
    }
    return std::max(1.0, 0.25 * std::abs(value));
  }

  void AddThresholds(EditKind kind, const std::string& owner, const std::string& suffix,
                     const Constraint& c) {
    for (size_t k = 0; k < c.comparisons.size(); ++k) {
      const Comparison& cmp = c.comparisons[k];
      const bool lhs_constant = ReadsOnlyParameters(a_, cmp.lhs);
      const bool rhs_constant = ReadsOnlyParameters(a_, cmp.rhs);
      if (lhs_constant == rhs_constant) continue;  // both sides read variables, or neither
      const Expression& constant = lhs_constant ? cmp.lhs : cmp.rhs;
      const Expression& side = lhs_constant ? cmp.rhs : cmp.lhs;
      const double value = constant.Evaluate(env_);
      const double h = ThresholdHalfWidth(side, value);
      std::string name = owner + suffix;
      if (k > 0) name.append("_").append(std::to_string(k));
      Add(ModelEdit{kind, name, "", "", owner, static_cast<int>(k), value, value - h, value + h});
    }
  }

  void AddInputOffset(const InputInfo& in) {
    const double lo = in.bounds.lo.Evaluate(env_), hi = in.bounds.hi.Evaluate(env_);
    const double h = hi > lo ? 0.25 * (hi - lo) : 1.0;
    const std::string& u = a_.symbols()[in.slot].name;
    Add(ModelEdit{EditKind::kInputOffset, u + "_offset", "", u, "", 0, 0.0, -h, h});
  }

  const Automaton& a_;
  Names names_;
  std::vector<double> env_;
  std::map<std::string, std::pair<double, double>> ranges_;
  double duration_ = 0.0;  // of the longest run
  CandidateSet set_;
};

// The rebuilding of an automaton with edits (ApplyEdits).
class Editor {
 public:
  Editor(const Automaton& a, std::span<const std::pair<ModelEdit, double>> edits)
      : a_(a), edits_(edits), out_(CopySymbols(a)), names_(a) {}

  Automaton Run() {
    DeclareParameters();
    DeclareMeasured();
    DeclareDelays();
    for (const Mode& m : a_.modes()) out_.AddMode(EditedMode(m));
    AddPendingModes();
    for (const Transition& t : a_.transitions()) AddTransition(t);
    for (const InitialState& s : a_.initial_states()) out_.AddInitialState(EditedStart(s));
    for (const Property& p : a_.properties()) out_.AddProperty(p);
    if (a_.scenario()) out_.SetScenario(*a_.scenario());
    return std::move(out_);
  }

 private:
  // A sensor's measured variable and the parameters it reads (-1: absent).
  struct Sensor {
    int measured = -1, bias = -1, gain = -1;
  };

  // A delayed transition's parameter, clock and pending mode.
  struct Delay {
    int parameter = -1, clock = -1;
    ModeId pending;
  };

  void DeclareDelays() {
    for (const auto& [e, value] : edits_) {
      if (e.kind != EditKind::kDelay) continue;
      if (!(value >= 0)) throw std::invalid_argument("delay '" + e.name + "' must be >= 0");
      Delay& d = delays_[e.owner];
      d.parameter = out_.AddParameter(e.identifier, Expression::Constant(value));
      d.clock = out_.AddVariable(names_.Unique(e.owner + "_clock"));
    }
  }

  // `base`, or base_2, base_3, ... if `taken` says it is taken.
  static std::string Fresh(const std::string& base,
                           const std::function<bool(const std::string&)>& taken) {
    std::string name = base;
    for (int k = 2; taken(name); ++k) name = base + "_" + std::to_string(k);
    return name;
  }

  Expression SlotSymbol(int slot) const {
    return Expression::Symbol(out_.symbols()[slot].name, slot);
  }

  // The pending mode of each delayed transition: its source's flows and discrete values, the
  // clock running, staying while the clock is below the delay.
  void AddPendingModes() {
    for (auto& [name, d] : delays_) {
      const Transition* t = FindTransition(name);
      Mode pending = EditedMode(a_.mode(t->source));
      pending.name = Fresh(name + "_pending", [&](const std::string& n) {
        for (const Mode& m : out_.modes()) {
          if (m.name == n) return true;
        }
        return false;
      });
      pending.flows.emplace_back(d.clock, Expression::Constant(1.0));
      pending.invariant = Constraint{
          {Comparison{SlotSymbol(d.clock), Relation::kLessEqual, SlotSymbol(d.parameter)}}};
      d.pending = out_.AddMode(std::move(pending));
    }
  }

  const Transition* FindTransition(const std::string& name) const {
    for (const Transition& t : a_.transitions()) {
      if (t.name == name) return &t;
    }
    throw std::invalid_argument("the model has no transition '" + name + "'");
  }

  // Transition `t` edited; a delayed one into its pending mode (resetting the clock), then out
  // of it (its resets and label) once the clock reaches the delay.
  void AddTransition(const Transition& t) {
    Transition edited = EditedTransition(t);
    const auto it = delays_.find(t.name);
    if (it == delays_.end()) {
      out_.AddTransition(std::move(edited));
      return;
    }
    const Delay& d = it->second;
    Transition done = edited;
    done.name = Fresh(t.name + "_done", [&](const std::string& n) {
      for (const Transition& other : a_.transitions()) {
        if (other.name == n) return true;
      }
      return false;
    });
    done.source = d.pending;
    done.guard = Constraint{
        {Comparison{SlotSymbol(d.clock), Relation::kGreaterEqual, SlotSymbol(d.parameter)}}};
    edited.target = d.pending;
    edited.label.clear();
    edited.resets = {Reset{d.clock, Expression::Constant(0.0)}};
    out_.AddTransition(std::move(edited));
    out_.AddTransition(std::move(done));
  }

  int SlotOf(const std::string& name) const {
    const std::optional<int> slot = a_.symbols().Find(name);
    if (!slot) throw std::invalid_argument("the model has no '" + name + "'");
    return *slot;
  }

  // The side of the edited comparison that reads no variable or input.
  Expression ConstantSide(const ModelEdit& e) const {
    const Constraint* c = nullptr;
    for (const Transition& t : a_.transitions()) {
      if (e.kind == EditKind::kGuardThreshold && t.name == e.owner) c = &t.guard;
    }
    for (const Mode& m : a_.modes()) {
      if (e.kind == EditKind::kInvariantThreshold && m.name == e.owner) c = &m.invariant;
    }
    if (!c || e.atom < 0 || e.atom >= static_cast<int>(c->comparisons.size())) {
      throw std::invalid_argument("edit '" + e.name + "' names no comparison of '" + e.owner + "'");
    }
    const Comparison& cmp = c->comparisons[e.atom];
    return ReadsOnlyParameters(a_, cmp.lhs) ? cmp.lhs : cmp.rhs;
  }

  Expression Parameter(const std::string& name) const {
    return Expression::Symbol(name, *out_.symbols().Find(name));
  }

  void DeclareParameters() {
    for (const auto& [e, value] : edits_) {
      switch (e.kind) {
        case EditKind::kParameter:
          out_.SetParameter(e.name, value);
          break;
        case EditKind::kInputOffset:
          offsets_[SlotOf(e.variable)] =
              out_.AddParameter(e.identifier, Expression::Constant(value));
          break;
        case EditKind::kFlowGain:
          out_.AddParameter(e.identifier, Expression::Constant(value));
          break;
        case EditKind::kGuardThreshold:
        case EditKind::kInvariantThreshold:
          // At its neutral value the threshold is the comparison's own side (`param
          // on_invariant = high;`), so that it follows the parameters it reads when they are
          // set per run, as the guards that read them do.
          out_.AddParameter(e.identifier,
                            value == e.neutral ? ConstantSide(e) : Expression::Constant(value));
          break;
        default:
          break;
      }
    }
  }

  void DeclareMeasured() {
    for (const auto& [e, value] : edits_) {
      if (e.kind != EditKind::kSensorBias && e.kind != EditKind::kSensorGain) continue;
      Sensor& sensor = sensors_[SlotOf(e.variable)];
      (e.kind == EditKind::kSensorBias ? sensor.bias : sensor.gain) =
          out_.AddParameter(e.identifier, Expression::Constant(value));
    }
    for (auto& [slot, sensor] : sensors_) {
      const Symbol& x = a_.symbols()[slot];
      sensor.measured = out_.AddVariable(names_.Unique(x.name + "_measured"), x.unit);
    }
  }

  // `e` with every input u that has an offset read as (u + u_offset).
  Expression WithOffsets(const Expression& e) const {
    if (offsets_.empty()) return e;
    return e.Substitute([&](const std::string& name, int slot) -> std::optional<Expression> {
      const auto it = offsets_.find(slot);
      if (it == offsets_.end()) return std::nullopt;
      return Expression::Symbol(name, slot) +
             Expression::Symbol(out_.symbols()[it->second].name, it->second);
    });
  }

  // g * e + b for the sensor (without the factor or term it does not have).
  Expression Measured(const Sensor& s, Expression e, bool with_bias) const {
    if (s.gain >= 0) e = Expression::Symbol(out_.symbols()[s.gain].name, s.gain) * e;
    if (with_bias && s.bias >= 0) e = e + Expression::Symbol(out_.symbols()[s.bias].name, s.bias);
    return e;
  }

  Constraint EditedConstraint(const Constraint& c, EditKind kind, const std::string& owner) const {
    Constraint out;
    for (const Comparison& cmp : c.comparisons) {
      out.comparisons.push_back(
          Comparison{WithOffsets(cmp.lhs), cmp.relation, WithOffsets(cmp.rhs)});
    }
    for (const auto& [e, value] : edits_) {
      if (e.kind != kind || e.owner != owner) continue;
      if (e.atom < 0 || e.atom >= static_cast<int>(out.comparisons.size())) {
        throw std::invalid_argument("edit '" + e.name + "' names no comparison of '" + owner + "'");
      }
      Comparison& cmp = out.comparisons[e.atom];
      (ReadsOnlyParameters(a_, c.comparisons[e.atom].lhs) ? cmp.lhs : cmp.rhs) =
          Parameter(e.identifier);
    }
    return out;
  }

  Mode EditedMode(const Mode& m) const {
    Mode out = m;
    for (auto& [slot, f] : out.flows) {
      f = WithOffsets(f);
      for (const auto& [e, value] : edits_) {
        if (e.kind == EditKind::kFlowGain && e.owner == m.name && SlotOf(e.variable) == slot) {
          f = Parameter(e.identifier) * f;
        }
      }
    }
    for (const auto& [slot, sensor] : sensors_) {
      if (const std::optional<Expression> f = out.FlowOf(slot)) {
        out.flows.emplace_back(sensor.measured, Measured(sensor, *f, false));
      }
    }
    out.invariant = EditedConstraint(m.invariant, EditKind::kInvariantThreshold, m.name);
    return out;
  }

  Transition EditedTransition(const Transition& t) const {
    Transition out = t;
    out.guard = EditedConstraint(t.guard, EditKind::kGuardThreshold, t.name);
    for (Reset& r : out.resets) r.value = WithOffsets(r.value);
    for (const auto& [slot, sensor] : sensors_) {
      for (const Reset& r : std::vector<Reset>(out.resets)) {
        if (r.slot == slot)
          out.resets.push_back(Reset{sensor.measured, Measured(sensor, r.value, true)});
      }
    }
    return out;
  }

  InitialState EditedStart(const InitialState& s) const {
    InitialState out = s;
    std::vector<InitialValue> clocks;
    for (const auto& [name, d] : delays_) {
      const Range zero{Expression::Constant(0.0), Expression::Constant(0.0)};
      clocks.push_back(InitialValue{d.clock, zero, true});
    }
    for (const auto& [slot, sensor] : sensors_) {
      for (const InitialValue& v : s.values) {
        if (v.slot != slot) continue;
        Range r{Measured(sensor, v.range.lo, true), Measured(sensor, v.range.hi, true)};
        if (v.is_point) r.hi = r.lo;
        out.values.push_back(InitialValue{sensor.measured, r, v.is_point});
      }
    }
    out.values.insert(out.values.end(), clocks.begin(), clocks.end());
    std::sort(out.values.begin(), out.values.end(),
              [](const InitialValue& a, const InitialValue& b) { return a.slot < b.slot; });
    return out;
  }

  const Automaton& a_;
  std::span<const std::pair<ModelEdit, double>> edits_;
  Automaton out_;
  Names names_;
  std::map<int, int> offsets_;           // input slot -> offset parameter slot
  std::map<int, Sensor> sensors_;        // variable slot -> its sensor
  std::map<std::string, Delay> delays_;  // transition name -> its delay
};

}  // namespace

Automaton ApplyEdits(const Automaton& automaton,
                     std::span<const std::pair<ModelEdit, double>> edits) {
  return Editor(automaton, edits).Run();
}

CandidateSet CandidateEdits(const Automaton& automaton, const TraceData& data) {
  return Generator(automaton, data).Run(data);
}

}  // namespace hybrid
