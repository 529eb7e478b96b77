#include "hybrid/gripper/finger_effects.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hybrid {
namespace {

constexpr double kMotorMax = 255.0;

const char* const kJointNames[3] = {"theta1", "theta2", "theta3"};

// Throws std::invalid_argument "CONTEXT: MESSAGE", `context` saying in words what was being done
// ("extending the finger model").
[[noreturn]] void Fail(std::string_view context, const std::string& message) {
  throw std::invalid_argument(std::string(context) + ": " + message);
}

int SlotOf(const Automaton& a, std::string_view name, std::string_view context) {
  const auto slot = a.symbols().Find(name);
  if (!slot) Fail(context, "the finger model has no '" + std::string(name) + "'");
  return *slot;
}

Expression Sym(const Automaton& a, std::string_view name, std::string_view context) {
  return Expression::Symbol(std::string(name), SlotOf(a, name, context));
}

Comparison Compare(Expression lhs, Relation r, Expression rhs) {
  return Comparison{std::move(lhs), r, std::move(rhs)};
}

void SetFlow(Mode& mode, int slot, std::optional<Expression> rhs) {
  std::erase_if(mode.flows, [slot](const auto& f) { return f.first == slot; });
  if (rhs) mode.flows.emplace_back(slot, std::move(*rhs));
  std::sort(mode.flows.begin(), mode.flows.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
}

void SetReset(Transition& t, int slot, Expression value) {
  std::erase_if(t.resets, [slot](const Reset& r) { return r.slot == slot; });
  t.resets.push_back(Reset{slot, std::move(value)});
  std::sort(t.resets.begin(), t.resets.end(),
            [](const Reset& x, const Reset& y) { return x.slot < y.slot; });
}

}  // namespace

std::string_view CauseName(Cause cause) {
  switch (cause) {
    case Cause::kBacklash:
      return "backlash";
    case Cause::kMotorOffset:
      return "motor_offset";
    case Cause::kJointRange:
      return "joint_range";
    case Cause::kSensorBias:
      return "sensor_bias";
    case Cause::kCompliance:
      return "compliance";
    case Cause::kTheta3Law:
      return "theta3_law";
  }
  return "?";
}

bool FingerEffects::SameDynamics(const FingerEffects& o) const {
  return joint_max == o.joint_max && compliance == o.compliance &&
         theta3_fraction == o.theta3_fraction;
}

std::string ParameterName(const EffectParameter& p) {
  switch (p.cause) {
    case Cause::kBacklash:
      return "backlash";
    case Cause::kMotorOffset:
      return "motor_offset";
    case Cause::kJointRange:
      return std::string(kJointNames[p.index]) + "_max";
    case Cause::kSensorBias:
      return std::string(kJointNames[p.index]) + "_bias";
    case Cause::kCompliance:
      return "compliance_link" + std::to_string(p.index + 1);
    case Cause::kTheta3Law:
      return "theta3_fraction";
  }
  return "?";
}

std::string_view ParameterUnit(const EffectParameter& p) {
  switch (p.cause) {
    case Cause::kBacklash:
    case Cause::kMotorOffset:
      return "count";
    case Cause::kJointRange:
    case Cause::kSensorBias:
      return "deg";
    case Cause::kCompliance:
      return "deg/count";
    case Cause::kTheta3Law:
      return "";
  }
  return "";
}

std::vector<EffectParameter> AllEffectParameters() {
  std::vector<EffectParameter> all = {{Cause::kBacklash, 0}, {Cause::kMotorOffset, 0}};
  for (int j = 0; j < 3; ++j) all.push_back({Cause::kJointRange, j});
  for (int j = 0; j < 3; ++j) all.push_back({Cause::kSensorBias, j});
  for (int i = 0; i < 2; ++i) all.push_back({Cause::kCompliance, i});
  all.push_back({Cause::kTheta3Law, 0});
  return all;
}

double NeutralValue(const EffectParameter& p, const Automaton& finger) {
  constexpr std::string_view kContext = "an effect's neutral value";
  const std::vector<double> env = finger.ParameterEnvironment();
  switch (p.cause) {
    case Cause::kJointRange:
      return env[SlotOf(finger, std::string(kJointNames[p.index]) + "_max", kContext)];
    case Cause::kTheta3Law:
      return env[SlotOf(finger, "theta3_fraction", kContext)];
    default:
      return 0.0;
  }
}

double GetEffect(const FingerEffects& e, const EffectParameter& p, const Automaton& finger) {
  switch (p.cause) {
    case Cause::kBacklash:
      return e.backlash;
    case Cause::kMotorOffset:
      return e.motor_offset;
    case Cause::kJointRange:
      return e.joint_max[p.index] ? *e.joint_max[p.index] : NeutralValue(p, finger);
    case Cause::kSensorBias:
      return e.sensor_bias[p.index];
    case Cause::kCompliance:
      return e.compliance[p.index];
    case Cause::kTheta3Law:
      return e.theta3_fraction ? *e.theta3_fraction : NeutralValue(p, finger);
  }
  return 0.0;
}

void SetEffect(FingerEffects& e, const EffectParameter& p, double value) {
  switch (p.cause) {
    case Cause::kBacklash:
      e.backlash = value;
      break;
    case Cause::kMotorOffset:
      e.motor_offset = value;
      break;
    case Cause::kJointRange:
      e.joint_max[p.index] = value;
      break;
    case Cause::kSensorBias:
      e.sensor_bias[p.index] = value;
      break;
    case Cause::kCompliance:
      e.compliance[p.index] = value;
      break;
    case Cause::kTheta3Law:
      e.theta3_fraction = value;
      break;
  }
}

std::vector<double> DrivePositions(std::span<const double> g, double backlash, double offset) {
  if (!std::isfinite(backlash) || backlash < 0.0) {
    Fail("the drive positions", "backlash must be >= 0");
  }
  if (!std::isfinite(offset)) Fail("the drive positions", "the offset must be finite");
  std::vector<double> q(g.size());
  double last = 0.0;
  for (size_t k = 0; k < g.size(); ++k) {
    if (!std::isfinite(g[k])) Fail("the drive positions", "a motor position is not finite");
    const double lo = g[k] - offset;
    last = std::clamp(std::clamp(last, lo, lo + backlash), 0.0, kMotorMax);
    q[k] = last;
  }
  return q;
}

void CheckDynamicEffects(const FingerEffects& effects) {
  constexpr std::string_view kContext = "the finger's effects";
  if (effects.theta3_fraction) {
    const double f = *effects.theta3_fraction;
    if (!(f > 0.0 && f < 1.0)) Fail(kContext, "theta3_fraction must lie in (0, 1)");
  }
  for (const double k : effects.compliance) {
    if (!std::isfinite(k) || k < 0.0) Fail(kContext, "compliance must be finite and >= 0");
  }
}

Automaton ApplyDynamicEffects(const Automaton& finger, const FingerEffects& effects) {
  constexpr std::string_view kContext = "the finger's effects";
  CheckDynamicEffects(effects);
  const bool compliant = effects.compliance[0] != 0.0 || effects.compliance[1] != 0.0;
  Automaton out = compliant ? CopySymbols(finger) : finger;
  for (int j = 0; j < 3; ++j) {
    if (effects.joint_max[j]) {
      out.SetParameter(std::string(kJointNames[j]) + "_max", *effects.joint_max[j]);
    }
  }
  if (effects.theta3_fraction) {
    const double f = *effects.theta3_fraction;
    if (!(f > 0.0 && f < 1.0)) Fail(kContext, "theta3_fraction must lie in (0, 1)");
    out.SetParameter("theta3_fraction", f);
  }
  if (!compliant) return out;
  std::array<std::optional<Expression>, 2> rate;
  for (int i = 0; i < 2; ++i) {
    const double k = effects.compliance[i];
    if (k == 0.0) continue;
    if (!std::isfinite(k) || k < 0.0) Fail(kContext, "compliance must be finite and >= 0");
    const std::string name = "compliance_link" + std::to_string(i + 1);
    const int slot = out.AddParameter(name, Expression::Constant(k), "deg/count");
    rate[i] = Expression::Symbol(name, slot) * Sym(finger, "u", kContext);
  }
  for (const Mode& m : finger.modes()) {
    Mode copy = m;
    for (int i = 0; i < 2; ++i) {
      const int c = SlotOf(finger, "c" + std::to_string(i + 1), kContext);
      if (rate[i] && m.DiscreteValueOf(c) == 1) {
        SetFlow(copy, SlotOf(finger, kJointNames[i], kContext), rate[i]);
      }
    }
    out.AddMode(std::move(copy));
  }
  for (const Transition& t : finger.transitions()) out.AddTransition(t);
  for (const InitialState& s : finger.initial_states()) out.AddInitialState(s);
  for (const Property& p : finger.properties()) out.AddProperty(p);
  if (finger.scenario()) out.SetScenario(*finger.scenario());
  return out;
}

namespace {

// The motor side of the play in the extended model: the finger model's drive input u and
// position g, the parameters motor_offset and backlash, and the motor position g_motor.
struct Play {
  Expression u, g;
  int g_slot;
  Expression offset, backlash;
  int motor_slot;
  Expression motor;
};

// Adds the play's parameters (motor_offset; backlash, ranging over [0, backlash]) and the
// variable g_motor to `out`.
Play AddPlay(Automaton& out, const Automaton& dyn, const FingerEffects& effects,
             std::string_view context) {
  const Expression u = Sym(dyn, "u", context);
  const Expression g = Sym(dyn, "g", context);
  const int g_slot = SlotOf(dyn, "g", context);
  const int d_slot =
      out.AddParameter("motor_offset", Expression::Constant(effects.motor_offset), "count");
  const int b_slot = out.AddParameter(
      "backlash", Expression::Constant(effects.backlash), "count",
      Range{Expression::Constant(0.0), Expression::Constant(std::max(effects.backlash, 0.0))});
  const Expression d = Expression::Symbol("motor_offset", d_slot);
  const Expression b = Expression::Symbol("backlash", b_slot);
  const int gm_slot = out.AddVariable("g_motor", "count");
  return {u, g, g_slot, d, b, gm_slot, Expression::Symbol("g_motor", gm_slot)};
}

// A measured angle of the output map: theta_j_measured = theta_j + theta_j_bias.
struct Measured {
  int source;  // slot of theta_j
  int slot;    // slot of theta_j_measured
  Expression bias;
};

// Adds the output map to `out`: for each joint with a sensor bias, the parameter theta_j_bias
// and the variable theta_j_measured.
std::vector<Measured> AddMeasuredAngles(Automaton& out, const Automaton& dyn,
                                        const FingerEffects& effects, std::string_view context) {
  std::vector<Measured> measured;
  for (int j = 0; j < 3; ++j) {
    if (effects.sensor_bias[j] == 0.0) continue;
    const std::string name = std::string(kJointNames[j]) + "_bias";
    const int p = out.AddParameter(name, Expression::Constant(effects.sensor_bias[j]), "deg");
    const int v = out.AddVariable(std::string(kJointNames[j]) + "_measured", "deg");
    measured.push_back({SlotOf(dyn, kJointNames[j], context), v, Expression::Symbol(name, p)});
  }
  return measured;
}

// The three copies of a finger mode: the drive engaged closing, slack, engaged opening.
constexpr std::array<const char*, 3> kCopy = {"_closing", "_slack", "_opening"};
using ModeCopies = std::array<ModeId, 3>;

// Adds three copies of each mode of `dyn` to `out`, in order (mode m's at index m): slack
// freezes the finger; in every copy the measured angles follow their joints and the motor moves
// with the drive when engaged (stalling with it in phase 4) and with u when slack.
std::vector<ModeCopies> AddModeCopies(Automaton& out, const Automaton& dyn,
                                      const std::vector<Measured>& measured, const Play& play) {
  std::vector<ModeCopies> ids;
  for (const Mode& m : dyn.modes()) {
    ModeCopies three;
    for (int c = 0; c < 3; ++c) {
      Mode copy = m;
      copy.name = m.name + kCopy[c];
      if (c == 1) copy.flows.clear();  // slack: the finger is frozen
      for (const Measured& x : measured) SetFlow(copy, x.slot, copy.FlowOf(x.source));
      SetFlow(copy, play.motor_slot,
              c == 1 ? std::optional<Expression>(play.u) : m.FlowOf(play.g_slot));
      three[c] = out.AddMode(std::move(copy));
    }
    ids.push_back(three);
  }
  return ids;
}

// Adds the play's transitions between the copies of every mode: reversing or reaching an end of
// the motor range makes the drive slack; it engages again closing (opening) once the motor has
// taken up the play.
void AddPlayTransitions(Automaton& out, const Automaton& dyn, const std::vector<ModeCopies>& ids,
                        const Play& play) {
  const Expression zero = Expression::Constant(0.0);
  const Expression top = Expression::Constant(kMotorMax);
  // A finger stopped at an end of the motor range engages again only from 1e-6 counts inside it
  // (a strict `g > 0` would hold at a rounding-level g and chatter with the stop).
  const Expression zero_in = Expression::Constant(1e-6);
  const Expression top_in = Expression::Constant(kMotorMax - 1e-6);
  const Expression &u = play.u, &g = play.g, &gm = play.motor, &d = play.offset, &b = play.backlash;
  auto add = [&](const std::string& name, ModeId from, ModeId to, std::vector<Comparison> guard) {
    Transition t;
    t.name = name;
    t.source = from;
    t.target = to;
    t.guard.comparisons = std::move(guard);
    out.AddTransition(std::move(t));
  };
  for (int m = 0; m < dyn.num_modes(); ++m) {
    const std::string& name = dyn.modes()[m].name;
    const auto& [closing, slack, opening] = ids[m];
    add("reverse_" + name + "_closing", closing, slack, {Compare(u, Relation::kLess, zero)});
    add("stop_" + name + "_closing", closing, slack,
        {Compare(g, Relation::kGreaterEqual, top), Compare(u, Relation::kGreater, zero)});
    add("engage_" + name + "_closing", slack, closing,
        {Compare(gm - d, Relation::kGreaterEqual, g), Compare(g, Relation::kLessEqual, top_in),
         Compare(u, Relation::kGreater, zero)});
    add("engage_" + name + "_opening", slack, opening,
        {Compare(gm - d + b, Relation::kLessEqual, g), Compare(g, Relation::kGreaterEqual, zero_in),
         Compare(u, Relation::kLess, zero)});
    add("reverse_" + name + "_opening", opening, slack, {Compare(u, Relation::kGreater, zero)});
    add("stop_" + name + "_opening", opening, slack,
        {Compare(g, Relation::kLessEqual, zero), Compare(u, Relation::kLess, zero)});
  }
}

// Adds each transition of `dyn` within the closing and within the opening copies; a reset of a
// joint resets its measured angle too, with the bias.
void AddFingerTransitions(Automaton& out, const Automaton& dyn, const std::vector<ModeCopies>& ids,
                          const std::vector<Measured>& measured) {
  for (const Transition& t : dyn.transitions()) {
    for (int c : {0, 2}) {
      Transition copy = t;
      copy.name = t.name + kCopy[c];
      copy.source = ids[t.source.value()][c];
      copy.target = ids[t.target.value()][c];
      for (const Measured& x : measured) {
        for (const Reset& r : t.resets) {
          if (r.slot == x.source) SetReset(copy, x.slot, r.value + x.bias);
        }
      }
      out.AddTransition(std::move(copy));
    }
  }
}

// Adds to `copy` (an initial state of the extended model made from `s`) the initial range of
// each measured angle: its joint's (as `copy` sets it) plus the bias.
void AddMeasuredInitialValues(InitialState& copy, const InitialState& s,
                              const std::vector<Measured>& measured) {
  for (const Measured& x : measured) {
    for (const InitialValue& v : s.values) {
      if (v.slot != x.source) continue;
      const InitialValue* from = &v;
      for (const InitialValue& w : copy.values) {
        if (w.slot == x.source) from = &w;
      }
      copy.values.push_back(
          InitialValue{x.slot, {from->range.lo + x.bias, from->range.hi + x.bias}, from->is_point});
    }
  }
}

// Adds the initial states: each of `dyn`'s with the motor at 0 and the finger where the drive
// map puts it (engaged closing, or slack), in `initial_finger`'s mode and values when the play
// has already moved it (q0 > 0).
void AddInitialStates(Automaton& out, const Automaton& dyn, const std::vector<ModeCopies>& ids,
                      const std::vector<Measured>& measured, const Play& play,
                      const FingerEffects& effects,
                      const std::optional<FingerInitialState>& initial_finger,
                      std::string_view context) {
  const double q0 = DrivePositions(std::span<const double>(std::array<double, 1>{0.0}),
                                   effects.backlash, effects.motor_offset)[0];
  const bool engaged = q0 == -effects.motor_offset;
  const Expression zero = Expression::Constant(0.0);
  for (const InitialState& s : dyn.initial_states()) {
    InitialState copy = s;
    int copy_index = engaged ? 0 : 1;
    if (initial_finger && q0 > 0.0) {
      const auto mode = dyn.FindMode(initial_finger->mode);
      if (!mode) Fail(context, "no finger mode '" + initial_finger->mode + "'");
      copy.mode = ids[mode->value()][copy_index];
      for (const auto& [name, value] : initial_finger->values) {
        const int slot = SlotOf(dyn, name, context);
        for (InitialValue& v : copy.values) {
          if (v.slot == slot)
            v = InitialValue{
                slot, {Expression::Constant(value), Expression::Constant(value)}, true};
        }
      }
    } else {
      if (q0 > 0.0) Fail(context, "motor_offset < 0 needs the finger's initial state");
      copy.mode = ids[s.mode.value()][copy_index];
    }
    copy.values.push_back(InitialValue{play.motor_slot, {zero, zero}, true});
    AddMeasuredInitialValues(copy, s, measured);
    std::sort(copy.values.begin(), copy.values.end(),
              [](const InitialValue& x, const InitialValue& y) { return x.slot < y.slot; });
    out.AddInitialState(std::move(copy));
  }
}

}  // namespace

Automaton ExtendFingerModel(const Automaton& finger, const FingerEffects& effects,
                            const std::optional<FingerInitialState>& initial_finger) {
  constexpr std::string_view kContext = "extending the finger model";
  const Automaton dyn = ApplyDynamicEffects(finger, effects);
  if (!std::isfinite(effects.backlash) || effects.backlash < 0.0) {
    Fail(kContext, "backlash must be finite and >= 0");
  }
  Automaton out = CopySymbols(dyn);
  const Play play = AddPlay(out, dyn, effects, kContext);
  const std::vector<Measured> measured = AddMeasuredAngles(out, dyn, effects, kContext);
  const std::vector<ModeCopies> ids = AddModeCopies(out, dyn, measured, play);
  // The play's transitions first: they take priority over the finger's at the same instant.
  AddPlayTransitions(out, dyn, ids, play);
  AddFingerTransitions(out, dyn, ids, measured);
  AddInitialStates(out, dyn, ids, measured, play, effects, initial_finger, kContext);
  for (const Property& p : dyn.properties()) out.AddProperty(p);
  // The finger's default scenario drives the motor (u) the same way: the model runs as written.
  if (dyn.scenario()) out.SetScenario(*dyn.scenario());
  return out;
}

}  // namespace hybrid
