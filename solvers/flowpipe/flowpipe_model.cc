#include "solvers/flowpipe/flowpipe_model.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "hybrid/automaton/interval.h"
#include "hybrid/checking/trace.h"

namespace hybrid::flowpipe_internal {
namespace {

TightInterval FromInterval(const Interval& x) { return {x.lo(), x.hi()}; }
Interval ToInterval(const TightInterval& x) {
  if (std::isnan(x.lo) || std::isnan(x.hi)) return Interval::Entire();
  return Interval(x.lo, x.hi);
}

// sign(x) over an interval.
TightInterval SignOf(const TightInterval& x) {
  if (x.lo > 0) return TightInterval(1.0);
  if (x.hi < 0) return TightInterval(-1.0);
  return {x.lo < 0 ? -1.0 : 0.0, x.hi > 0 ? 1.0 : 0.0};
}

Truth Not(Truth t) {
  return t == Truth::kTrue ? Truth::kFalse : t == Truth::kFalse ? Truth::kTrue : Truth::kMaybe;
}

}  // namespace

TightInterval EvaluateTight(const Expression& e, const std::vector<TightInterval>& env) {
  switch (e.op()) {
    case Op::kConstant:
      return TightInterval(e.constant());
    case Op::kSymbol:
      return env.at(static_cast<std::size_t>(e.slot()));
    case Op::kNeg:
      return -EvaluateTight(e.args()[0], env);
    case Op::kAdd:
      return EvaluateTight(e.args()[0], env) + EvaluateTight(e.args()[1], env);
    case Op::kSub:
      return EvaluateTight(e.args()[0], env) - EvaluateTight(e.args()[1], env);
    case Op::kMul:
      return EvaluateTight(e.args()[0], env) * EvaluateTight(e.args()[1], env);
    case Op::kDiv:
      return EvaluateTight(e.args()[0], env) / EvaluateTight(e.args()[1], env);
    case Op::kSign:
      return SignOf(EvaluateTight(e.args()[0], env));
    case Op::kPow: {
      const Expression& p = e.args()[1];
      if (p.is_constant() && p.constant() >= 0 && p.constant() <= 64 &&
          p.constant() == std::floor(p.constant())) {
        return Power(EvaluateTight(e.args()[0], env), static_cast<int>(p.constant()));
      }
      break;
    }
    default:
      break;
  }
  std::vector<Interval> args;
  for (const Expression& a : e.args()) args.push_back(ToInterval(EvaluateTight(a, env)));
  switch (e.op()) {
    case Op::kSin:
      return FromInterval(Sin(args[0]));
    case Op::kCos:
      return FromInterval(Cos(args[0]));
    case Op::kTan:
      return FromInterval(Tan(args[0]));
    case Op::kExp:
      return FromInterval(Exp(args[0]));
    case Op::kLog:
      return FromInterval(Log(args[0]));
    case Op::kSqrt:
      return FromInterval(Sqrt(args[0]));
    case Op::kAbs:
      return FromInterval(Abs(args[0]));
    case Op::kPow:
      return FromInterval(Pow(args[0], args[1]));
    case Op::kMin:
      return FromInterval(Min(args[0], args[1]));
    case Op::kMax:
      return FromInterval(Max(args[0], args[1]));
    case Op::kAtan2:
      return FromInterval(Atan2(args[0], args[1]));
    default:
      return TightInterval::Entire();
  }
}

FlowpipeModel::FlowpipeModel(const System& system) : system_(system) {
  const SymbolTable& symbols = system_.symbols();
  const auto n = static_cast<std::size_t>(symbols.size());
  slots_.state.assign(n, -1);
  slots_.input.assign(n, -1);
  base_env_.assign(n, TightInterval::Entire());
  for (int s : symbols.SlotsOfKind(SymbolKind::kVariable)) {
    slots_.state[static_cast<std::size_t>(s)] = static_cast<int>(component_slot_.size());
    component_slot_.push_back(s);
  }
  num_variables_ = static_cast<int>(component_slot_.size());
  for (const UncertainParameter& p : UncertainParameters(system_)) {
    const int s = *symbols.Find(p.name);
    slots_.state[static_cast<std::size_t>(s)] = static_cast<int>(component_slot_.size());
    component_slot_.push_back(s);
    base_env_[static_cast<std::size_t>(s)] = {p.lo, p.hi};
  }
  for (int s : symbols.SlotsOfKind(SymbolKind::kInput)) {
    slots_.input[static_cast<std::size_t>(s)] = static_cast<int>(input_slot_.size());
    input_slot_.push_back(s);
    const auto [lo, hi] = system_.InputBounds(s);
    base_env_[static_cast<std::size_t>(s)] = {lo, hi};
    input_box_.push_back({lo, hi});
  }
  for (int s : symbols.SlotsOfKind(SymbolKind::kParameter)) {
    if (slots_.state[static_cast<std::size_t>(s)] >= 0) continue;
    base_env_[static_cast<std::size_t>(s)] =
        EvaluateTight(Resolve(system_.ResolvedParameter(s)), base_env_);
  }
  for (int s : symbols.SlotsOfKind(SymbolKind::kDiscrete))
    base_env_[static_cast<std::size_t>(s)] = TightInterval(0.0);
}

const std::string& FlowpipeModel::ComponentName(int i) const {
  return system_.symbols()[component_slot_[static_cast<std::size_t>(i)]].name;
}

Expression FlowpipeModel::Resolve(const Expression& e) const {
  const SymbolTable& symbols = system_.symbols();
  return e
      .Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
        if (symbols[slot].kind != SymbolKind::kParameter) return std::nullopt;
        if (slots_.state[static_cast<std::size_t>(slot)] >= 0) return std::nullopt;  // uncertain
        return system_.ResolvedParameter(slot);
      })
      .FoldConstants();
}

namespace {

// An affine form with interval coefficients (ExactAffine).
struct IntervalAffine {
  TightInterval constant{0.0};
  std::map<int, TightInterval> terms;

  bool IsConstant() const { return terms.empty(); }
  IntervalAffine Scaled(const TightInterval& k) const {
    IntervalAffine out{constant * k, {}};
    for (const auto& [slot, a] : terms) out.terms[slot] = a * k;
    return out;
  }
  IntervalAffine Plus(const IntervalAffine& b, double sign) const {
    IntervalAffine out = *this;
    out.constant = out.constant + TightInterval(sign) * b.constant;
    for (const auto& [slot, a] : b.terms) {
      auto [it, fresh] = out.terms.emplace(slot, TightInterval(0.0));
      it->second = it->second + TightInterval(sign) * a;
    }
    return out;
  }
};

// e as an affine form whose coefficients are computed in interval arithmetic; nullopt when e is
// not affine (the cases Expression::AsAffine recognises).
std::optional<IntervalAffine> IntervalAffineOf(const Expression& e) {
  if (e.is_constant()) return IntervalAffine{TightInterval(e.constant()), {}};
  if (e.is_symbol()) return IntervalAffine{TightInterval(0.0), {{e.slot(), TightInterval(1.0)}}};
  std::vector<IntervalAffine> parts;
  for (const Expression& a : e.args()) {
    std::optional<IntervalAffine> p = IntervalAffineOf(a);
    if (!p) return std::nullopt;
    parts.push_back(std::move(*p));
  }
  switch (e.op()) {
    case Op::kNeg:
      return parts[0].Scaled(TightInterval(-1.0));
    case Op::kAdd:
      return parts[0].Plus(parts[1], 1.0);
    case Op::kSub:
      return parts[0].Plus(parts[1], -1.0);
    case Op::kMul:
      if (parts[0].IsConstant()) return parts[1].Scaled(parts[0].constant);
      if (parts[1].IsConstant()) return parts[0].Scaled(parts[1].constant);
      return std::nullopt;
    case Op::kDiv:
      if (parts[1].IsConstant()) return parts[0].Scaled(TightInterval(1.0) / parts[1].constant);
      return std::nullopt;
    case Op::kPow:
      if (e.args()[1].is_constant() && e.args()[1].constant() == 1.0) return parts[0];
      return std::nullopt;
    default:
      return std::nullopt;
  }
}

// Expression::AsAffine of e when its coefficients are the exact coefficients of e (the engine
// reads them as exact), nullopt otherwise: a coefficient such as the 1/3 of (x + y) / 3 is
// rounded, and then e is read by interval evaluation only.
std::optional<hybrid::AffineForm> ExactAffine(const Expression& e) {
  std::optional<hybrid::AffineForm> a = e.AsAffine();
  if (!a) return a;
  const std::optional<IntervalAffine> exact = IntervalAffineOf(e);
  if (!exact || exact->constant.lo != a->constant || exact->constant.hi != a->constant)
    return std::nullopt;
  std::size_t nonzero = 0;
  for (const auto& [slot, k] : exact->terms) {
    if (k.lo == 0 && k.hi == 0) continue;
    ++nonzero;
    const auto it = std::find_if(a->terms.begin(), a->terms.end(),
                                 [&](const auto& term) { return term.first == slot; });
    if (it == a->terms.end() || k.lo != it->second || k.hi != it->second) return std::nullopt;
  }
  if (nonzero != a->terms.size()) return std::nullopt;
  return a;
}

}  // namespace

Residual FlowpipeModel::Compile(const Comparison& c) const {
  Residual r;
  r.expression = Resolve(c.Residual());
  r.relation = c.relation;
  r.affine = ExactAffine(r.expression);
  return r;
}

int FlowpipeModel::ModeIndex(const std::vector<int>& tuple) {
  if (auto it = mode_index_.find(tuple); it != mode_index_.end()) return it->second;
  auto mode = std::make_unique<CompiledMode>();
  mode->tuple = tuple;
  const hybrid::Mode m = system_.ProductModeOf(tuple);
  for (std::size_t c = 0; c < tuple.size(); ++c) {
    mode->names.push_back(system_.QualifiedModeName(static_cast<int>(c), ModeId(tuple[c])));
    mode->name += (c ? ", " : "") + mode->names.back();
  }
  mode->env = base_env_;
  for (const auto& [slot, value] : m.discrete_values) {
    mode->env[static_cast<std::size_t>(slot)] = TightInterval(static_cast<double>(value));
  }
  // Flows: parameters resolved, discrete variables replaced by this mode's values.
  std::vector<std::optional<Expression>> flows(component_slot_.size());
  for (int i = 0; i < num_variables_; ++i) {
    std::optional<Expression> f = m.FlowOf(component_slot_[static_cast<std::size_t>(i)]);
    if (!f) continue;
    flows[static_cast<std::size_t>(i)] =
        Resolve(*f)
            .Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
              if (system_.symbols()[slot].kind != SymbolKind::kDiscrete) return std::nullopt;
              return Expression::Constant(mode->env[static_cast<std::size_t>(slot)].lo);
            })
            .FoldConstants();
  }
  mode->tape = TaylorTape::Compile(flows, slots_, num_inputs(), &mode->unsupported);
  for (const Comparison& c : m.invariant.comparisons) mode->invariant.push_back(Compile(c));
  modes_.push_back(std::move(mode));
  const int index = static_cast<int>(modes_.size()) - 1;
  mode_index_[tuple] = index;
  return index;
}

void FlowpipeModel::MakeJumps(int index) {
  if (Mode(index).jumps_made) return;
  const std::vector<int> tuple = Mode(index).tuple;
  std::vector<Jump> jumps;
  for (const System::Step& step : system_.StepsFrom(tuple)) {
    Jump j;
    j.name = step.transition.name;
    for (const Comparison& c : step.transition.guard.comparisons) j.guard.push_back(Compile(c));
    j.guard_and_invariant = j.guard;
    for (const Residual& r : Mode(index).invariant) j.guard_and_invariant.push_back(r);
    for (const Reset& r : step.transition.resets) {
      Residual value;
      value.expression = Resolve(r.value);
      value.affine = ExactAffine(value.expression);
      j.resets.push_back({slots_.state[static_cast<std::size_t>(r.slot)], std::move(value)});
    }
    j.urgent = step.transition.urgency == Urgency::kUrgent;
    j.target = ModeIndex(step.target);
    jumps.push_back(std::move(j));
  }
  Mode(index).jumps = std::move(jumps);
  Mode(index).jumps_made = true;
}

std::vector<FlowpipeModel::Initial> FlowpipeModel::Initials() {
  struct Partial {
    std::vector<int> tuple;
    std::vector<TightInterval> box;
  };
  std::vector<TightInterval> start(component_slot_.size(), TightInterval::Entire());
  for (std::size_t i = static_cast<std::size_t>(num_variables_); i < component_slot_.size(); ++i) {
    start[i] = base_env_[static_cast<std::size_t>(component_slot_[i])];
  }
  std::vector<Partial> partial = {{{}, start}};
  for (const Component& c : system_.components()) {
    std::vector<TightInterval> local(c.global_slot.size());
    for (std::size_t l = 0; l < c.global_slot.size(); ++l)
      local[l] = base_env_[static_cast<std::size_t>(c.global_slot[l])];
    std::vector<Partial> next;
    for (const Partial& p : partial) {
      for (const InitialState& init : c.automaton.initial_states()) {
        Partial q = p;
        q.tuple.push_back(init.mode.value());
        for (const InitialValue& v : init.values) {
          const int component =
              slots_
                  .state[static_cast<std::size_t>(c.global_slot[static_cast<std::size_t>(v.slot)])];
          if (component < 0) continue;
          const TightInterval lo = EvaluateTight(v.range.lo, local),
                              hi = EvaluateTight(v.range.hi, local);
          TightInterval& x = q.box[static_cast<std::size_t>(component)];
          x = {std::max(x.lo, lo.lo), std::min(x.hi, hi.hi)};
        }
        next.push_back(std::move(q));
      }
    }
    partial = std::move(next);
  }
  std::vector<Initial> out;
  for (Partial& p : partial) {
    if (std::any_of(p.box.begin(), p.box.end(), [](const TightInterval& x) { return x.lo > x.hi; }))
      continue;
    out.push_back({ModeIndex(p.tuple), std::move(p.box)});
  }
  return out;
}

std::vector<TightInterval> FlowpipeModel::EnvironmentOf(
    const std::vector<TightInterval>& box, const std::vector<TightInterval>& env) const {
  std::vector<TightInterval> out = env;
  for (std::size_t i = 0; i < box.size() && i < component_slot_.size(); ++i)
    out[static_cast<std::size_t>(component_slot_[i])] = box[i];
  return out;
}

TightInterval FlowpipeModel::Value(const Residual& r, const std::vector<TightInterval>& box,
                                   const std::vector<TightInterval>& env) const {
  return EvaluateTight(r.expression, EnvironmentOf(box, env));
}

namespace {

// Whether the form has no symbol: a number with an error interval.
bool IsConstantForm(const AffineForm& f) {
  return std::all_of(f.coefficients().begin(), f.coefficients().end(),
                     [](double g) { return g == 0; });
}

// e in affine arithmetic (FlowpipeModel::FormValue): `state` maps a slot to its state
// component or -1, `x` holds the components' forms, `env` the other slots.
AffineForm EvaluateForm(const Expression& e, const std::vector<int>& state,
                        const std::vector<AffineForm>& x, const std::vector<TightInterval>& env) {
  const auto arg = [&](int i) {
    return EvaluateForm(e.args()[static_cast<std::size_t>(i)], state, x, env);
  };
  switch (e.op()) {
    case Op::kConstant:
      return AffineForm(e.constant());
    case Op::kSymbol: {
      const int i = state[static_cast<std::size_t>(e.slot())];
      return i >= 0 ? x[static_cast<std::size_t>(i)]
                    : AffineForm::OfInterval(env.at(static_cast<std::size_t>(e.slot())));
    }
    case Op::kNeg:
      return -arg(0);
    case Op::kAdd:
      return arg(0) + arg(1);
    case Op::kSub:
      return arg(0) - arg(1);
    case Op::kMul: {
      const AffineForm a = arg(0), b = arg(1);
      if (IsConstantForm(a)) return b.Scaled(a.Range());
      if (IsConstantForm(b)) return a.Scaled(b.Range());
      return a * b;
    }
    case Op::kDiv: {
      const AffineForm a = arg(0), b = arg(1);
      if (IsConstantForm(b)) return a.Scaled(TightInterval(1.0) / b.Range());
      return a / b;
    }
    case Op::kPow: {
      const Expression& p = e.args()[1];
      if (p.is_constant() && p.constant() >= 0 && p.constant() <= 64 &&
          p.constant() == std::floor(p.constant())) {
        const AffineForm a = arg(0);
        AffineForm y(1.0);
        for (int k = 0; k < static_cast<int>(p.constant()); ++k) y = y * a;
        return y;
      }
      break;
    }
    default:
      break;
  }
  // Any other function: its interval value over the ranges of its arguments' forms.
  std::vector<TightInterval> ranges = env;
  for (std::size_t slot = 0; slot < state.size() && slot < ranges.size(); ++slot) {
    if (state[slot] >= 0) ranges[slot] = x[static_cast<std::size_t>(state[slot])].Range();
  }
  return AffineForm::OfInterval(EvaluateTight(e, ranges));
}

}  // namespace

AffineForm FlowpipeModel::FormValue(const Residual& r, const std::vector<AffineForm>& x,
                                    const std::vector<TightInterval>& env) const {
  return EvaluateForm(r.expression, slots_.state, x, env);
}

TightInterval FlowpipeModel::Bound(const Residual& r, const Segment& segment,
                                   const std::vector<TightInterval>& env) const {
  TightInterval value = Value(r, segment.box, env);
  if (!r.affine) return value;
  TightInterval sum(r.affine->constant);
  std::vector<double> a(component_slot_.size(), 0.0);
  for (const auto& [slot, coefficient] : r.affine->terms) {
    const int i = slots_.state[static_cast<std::size_t>(slot)];
    if (i >= 0) {
      a[static_cast<std::size_t>(i)] = coefficient;
    } else {
      sum = sum + TightInterval(coefficient) * env[static_cast<std::size_t>(slot)];
    }
  }
  sum = sum + segment.LinearBound(a);
  return {std::max(sum.lo, value.lo), std::min(sum.hi, value.hi)};
}

Truth FlowpipeModel::Holds(const Residual& r, const Segment& segment,
                           const std::vector<TightInterval>& env, bool closure) const {
  const TightInterval v = Bound(r, segment, env);
  if (std::isnan(v.lo) || std::isnan(v.hi)) return Truth::kMaybe;
  Relation rel = r.relation;
  if (closure)
    rel = rel == Relation::kLess      ? Relation::kLessEqual
          : rel == Relation::kGreater ? Relation::kGreaterEqual
                                      : rel;
  switch (rel) {
    case Relation::kLessEqual:
      return v.hi <= 0 ? Truth::kTrue : v.lo > 0 ? Truth::kFalse : Truth::kMaybe;
    case Relation::kLess:
      return v.hi < 0 ? Truth::kTrue : v.lo >= 0 ? Truth::kFalse : Truth::kMaybe;
    case Relation::kGreaterEqual:
      return v.lo >= 0 ? Truth::kTrue : v.hi < 0 ? Truth::kFalse : Truth::kMaybe;
    case Relation::kGreater:
      return v.lo > 0 ? Truth::kTrue : v.hi <= 0 ? Truth::kFalse : Truth::kMaybe;
    case Relation::kEqual:
      return v.lo == 0 && v.hi == 0 ? Truth::kTrue
             : v.lo > 0 || v.hi < 0 ? Truth::kFalse
                                    : Truth::kMaybe;
  }
  return Truth::kMaybe;
}

Truth FlowpipeModel::HoldsAll(const std::vector<Residual>& conjunction, const Segment& segment,
                              const std::vector<TightInterval>& env) const {
  Truth all = Truth::kTrue;
  for (const Residual& r : conjunction) {
    const Truth t = Holds(r, segment, env, /*closure=*/true);
    if (t == Truth::kFalse) return Truth::kFalse;
    if (t == Truth::kMaybe) all = Truth::kMaybe;
  }
  return all;
}

Truth FlowpipeModel::Evaluate(const Predicate& p, const Segment& segment,
                              const CompiledMode& mode) const {
  switch (p.kind()) {
    case Predicate::Kind::kTrue:
      return Truth::kTrue;
    case Predicate::Kind::kFalse:
      return Truth::kFalse;
    case Predicate::Kind::kInMode:
      return std::find(mode.names.begin(), mode.names.end(), p.mode()) != mode.names.end()
                 ? Truth::kTrue
                 : Truth::kFalse;
    case Predicate::Kind::kComparison:
      return Holds(Compile(p.comparison()), segment, mode.env, /*closure=*/false);
    case Predicate::Kind::kNot:
      return Not(Evaluate(p.operands()[0], segment, mode));
    case Predicate::Kind::kAnd: {
      const Truth a = Evaluate(p.operands()[0], segment, mode);
      if (a == Truth::kFalse) return a;
      return std::min(a, Evaluate(p.operands()[1], segment, mode));
    }
    case Predicate::Kind::kOr: {
      const Truth a = Evaluate(p.operands()[0], segment, mode);
      if (a == Truth::kTrue) return a;
      return std::max(a, Evaluate(p.operands()[1], segment, mode));
    }
  }
  return Truth::kMaybe;
}

bool FlowpipeModel::Contract(const std::vector<Residual>& conjunction,
                             std::vector<TightInterval>& box,
                             const std::vector<TightInterval>& env) const {
  for (int pass = 0; pass < 2; ++pass) {
    for (const Residual& r : conjunction) {
      if (!r.affine) {
        const TightInterval v = Value(r, box, env);
        const bool le = r.relation == Relation::kLess || r.relation == Relation::kLessEqual;
        const bool ge = r.relation == Relation::kGreater || r.relation == Relation::kGreaterEqual;
        if ((le || r.relation == Relation::kEqual) && v.lo > 0) return false;
        if ((ge || r.relation == Relation::kEqual) && v.hi < 0) return false;
        continue;
      }
      // r = c + sum_s a_s x_s: each state term is bounded by the others.
      const auto& terms = r.affine->terms;
      for (std::size_t k = 0; k < terms.size(); ++k) {
        const int i = slots_.state[static_cast<std::size_t>(terms[k].first)];
        if (i < 0) continue;
        TightInterval others(r.affine->constant);
        for (std::size_t l = 0; l < terms.size(); ++l) {
          if (l == k) continue;
          const auto slot = static_cast<std::size_t>(terms[l].first);
          const int j = slots_.state[slot];
          others = others + TightInterval(terms[l].second) *
                                (j >= 0 ? box[static_cast<std::size_t>(j)] : env[slot]);
        }
        const double a = terms[k].second;
        const TightInterval rest = -others;  // a x_i REL rest
        TightInterval& x = box[static_cast<std::size_t>(i)];
        const bool le = r.relation != Relation::kGreater && r.relation != Relation::kGreaterEqual;
        const bool ge = r.relation != Relation::kLess && r.relation != Relation::kLessEqual;
        if (le && std::isfinite(rest.hi)) {  // a x <= rest.hi
          if (a > 0)
            x.hi = std::min(x.hi, DivUp(rest.hi, a));
          else
            x.lo = std::max(x.lo, DivDown(rest.hi, a));
        }
        if (ge && std::isfinite(rest.lo)) {  // a x >= rest.lo
          if (a > 0)
            x.lo = std::max(x.lo, DivDown(rest.lo, a));
          else
            x.hi = std::min(x.hi, DivUp(rest.lo, a));
        }
        if (x.lo > x.hi) return false;
      }
    }
  }
  return true;
}

namespace {

// max over lambda in [0, top] of phi(lambda), phi concave (or close to it), by a golden-section
// search of `iterations` steps; every value of phi is a sound bound, so the best one seen is
// returned.
template <class F>
double BestLowerBound(F phi, double top, int iterations) {
  const double r = 0.6180339887498949;
  double a = 0.0, b = top;
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = phi(c), fd = phi(d);
  double best = std::max(fc, fd);
  for (int i = 0; i < iterations; ++i) {
    if (fc >= fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - r * (b - a);
      fc = phi(c);
      best = std::max(best, fc);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + r * (b - a);
      fd = phi(d);
      best = std::max(best, fd);
    }
  }
  return best;
}

// The lambda >= 0 that maximises, for the zonotope Z of the affine forms `x` (centre c,
// generators g_s, error terms as one generator per component), the dual function
//   phi(lambda) = min over Z of (sign e_i + lambda n).x - lambda d
//              = (l + lambda n).c - lambda d - sum_s |alpha_s + lambda beta_s|,
// alpha_s = l.g_s, beta_s = n.g_s: concave and piecewise linear, so its maximum is at 0 or at a
// breakpoint -alpha_s / beta_s, found by walking the slope. Computed in plain floating point:
// the caller evaluates the bound soundly at the lambda returned (any lambda >= 0 is valid).
double BestMultiplier(const std::vector<AffineForm>& x, const std::vector<double>& n, double d,
                      std::size_t i, double sign) {
  std::size_t m = 0;
  for (const AffineForm& f : x) m = std::max(m, f.coefficients().size());
  std::vector<std::pair<double, double>> generators;  // (alpha, beta)
  double slope = -d;
  for (std::size_t j = 0; j < x.size(); ++j) slope += n[j] * x[j].center();
  for (std::size_t s = 0; s < m; ++s) {
    double alpha = sign * x[i].coefficient(s), beta = 0.0;
    for (std::size_t j = 0; j < x.size(); ++j) beta += n[j] * x[j].coefficient(s);
    generators.push_back({alpha, beta});
  }
  for (std::size_t j = 0; j < x.size(); ++j) {
    generators.push_back({j == i ? sign * x[j].err() : 0.0, n[j] * x[j].err()});
  }
  // Slope just right of 0: each |alpha + lambda beta| contributes -sign(alpha) beta (or -|beta|
  // when alpha = 0).
  std::vector<std::pair<double, double>> breaks;  // (lambda_s, 2 |beta_s|)
  for (const auto& [alpha, beta] : generators) {
    if (beta == 0) continue;
    if (alpha == 0) {
      slope -= std::fabs(beta);
      continue;
    }
    slope -= (alpha > 0 ? 1.0 : -1.0) * beta;
    const double at = -alpha / beta;
    if (at > 0) breaks.push_back({at, 2 * std::fabs(beta)});
  }
  if (slope <= 0) return 0.0;
  std::sort(breaks.begin(), breaks.end());
  for (const auto& [at, drop] : breaks) {
    slope -= drop;
    if (slope <= 0) return at;
  }
  // Still rising: the snapshot misses the halfspace (phi is unbounded); a large multiplier.
  double scale = 0.0;
  for (double v : n) scale = std::max(scale, std::fabs(v));
  return 1e6 / std::max(scale, 1e-300) + (breaks.empty() ? 0.0 : 2 * breaks.back().first);
}

}  // namespace

bool FlowpipeModel::ContractSegment(const std::vector<Residual>& conjunction,
                                    const Segment& segment, std::vector<TightInterval>& box,
                                    const std::vector<TightInterval>& env) const {
  const std::size_t dim = component_slot_.size();
  if (segment.series.empty()) return Contract(conjunction, box, env);
  // The segment's set at its start, middle and end (plain floating point: they only choose the
  // multipliers, each then evaluated soundly over the whole segment).
  std::vector<std::vector<AffineForm>> snapshots = {segment.series[0]};
  for (double fraction : {0.5, 1.0}) {
    if (segment.h == 0) break;
    std::vector<AffineForm> at = segment.series[0];
    double tk = 1.0;
    for (std::size_t k = 1; k < segment.series.size(); ++k) {
      tk *= fraction * segment.h;
      for (std::size_t j = 0; j < at.size(); ++j) at[j] = at[j] + segment.series[k][j].Scaled(tk);
    }
    snapshots.push_back(std::move(at));
  }
  for (const Residual& r : conjunction) {
    if (!r.affine) continue;
    // r = c + a.x + (terms of other slots): as halfspaces n.x <= d (d an upper bound).
    std::vector<double> a(dim, 0.0);
    TightInterval rest(r.affine->constant);
    bool any = false;
    for (const auto& [slot, coefficient] : r.affine->terms) {
      const int i = slots_.state[static_cast<std::size_t>(slot)];
      if (i >= 0) {
        a[static_cast<std::size_t>(i)] = coefficient;
        any = true;
      } else {
        rest = rest + TightInterval(coefficient) * env[static_cast<std::size_t>(slot)];
      }
    }
    if (!any || !rest.IsFinite()) continue;
    std::vector<std::pair<std::vector<double>, double>> halfspaces;
    const bool le = r.relation != Relation::kGreater && r.relation != Relation::kGreaterEqual;
    const bool ge = r.relation != Relation::kLess && r.relation != Relation::kLessEqual;
    if (le) halfspaces.push_back({a, -rest.lo});  // a.x <= -c
    if (ge) {
      std::vector<double> neg(a);
      for (double& v : neg) v = -v;
      halfspaces.push_back({neg, rest.hi});  // -a.x <= c
    }
    double norm_n = 0.0;
    for (double v : a) norm_n = std::max(norm_n, std::fabs(v));
    for (const auto& [n, d] : halfspaces) {
      for (std::size_t i = 0; i < dim; ++i) {
        for (double sign : {1.0, -1.0}) {
          // A lower bound of sign * x_i over segment and n.x <= d.
          auto phi = [&](double lambda) {
            // l = sign e_i + lambda n, computed in floating point; the rounding of each entry,
            // times a bound of |x_j|, is subtracted so that the bound stays sound.
            std::vector<double> l(n.size());
            double slack = 0.0;
            for (std::size_t j = 0; j < n.size(); ++j) {
              const double p = lambda * n[j];
              double error = std::fabs(std::fma(lambda, n[j], -p));
              l[j] = p;
              if (j == i) {
                l[j] = p + sign;
                error = AddUp(error, std::fabs(SumError(p, sign, l[j])));
              }
              if (error > 0) slack = AddUp(slack, MulUp(error, box[j].MagnitudeUp()));
            }
            const TightInterval lx = segment.LinearBound(l);
            const double bound = SubDown(SubDown(lx.lo, MulUp(lambda, d)), slack);
            return std::isfinite(bound) ? bound : -kInf;
          };
          // The snapshots' best multipliers, then a short search around them.
          double lower = phi(0.0), top = 0.0;
          for (const std::vector<AffineForm>& at : snapshots) {
            const double lambda = BestMultiplier(at, n, d, i, sign);
            lower = std::max(lower, phi(lambda));
            top = std::max(top, lambda);
          }
          if (top > 0) lower = std::max(lower, BestLowerBound(phi, 2 * top, 8));
          TightInterval& x = box[i];
          if (sign > 0) {
            x.lo = std::max(x.lo, lower);
          } else {
            x.hi = std::min(x.hi, -lower);
          }
          if (x.lo > x.hi) return false;
        }
      }
    }
  }
  return Contract(conjunction, box, env);
}

}  // namespace hybrid::flowpipe_internal
