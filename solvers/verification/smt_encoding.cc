#include "solvers/verification/smt_encoding.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "automaton/internal_assert.h"

namespace hybrid {

std::string FlowClassName(FlowClass c) {
  switch (c) {
    case FlowClass::kStill:
      return "still";
    case FlowClass::kConstantRate:
      return "constant_rate";
    case FlowClass::kSeparable:
      return "separable";
    case FlowClass::kGeneral:
      return "general";
  }
  return "?";
}

namespace {

z3::expr Num(z3::context& ctx, double v) {
  // The shortest fixed-point decimal that round-trips: an exact rational for Z3 (which does not
  // read exponents such as 1e-12).
  char buffer[512];
  const auto r = std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::fixed);
  return ctx.real_val(std::string(buffer, r.ptr).c_str());
}

bool Reads(const Expression& e, int slot) {
  const std::vector<int> s = e.Slots();
  return std::binary_search(s.begin(), s.end(), slot);
}

double ValueOf(const z3::model& m, const z3::expr& e) {
  z3::expr v = m.eval(e, true);
  if (v.is_bool()) return v.is_true() ? 1.0 : 0.0;
  std::string s = v.get_decimal_string(17);
  if (!s.empty() && s.back() == '?') s.pop_back();
  return std::stod(s);
}

// Antiderivative of `phi` (reading only the slot `w` and constants) with respect to w, for sums of
// constant multiples of B^n (B affine in w, n an integer != -1), also as 1 / max(B^n, eps).
// `domain` collects comparisons that must hold at both ends of a segment; `same_sign` affine
// expressions that must keep one strict sign (no pole inside).
struct Integral {
  std::vector<Comparison> domain;
  std::vector<Expression> same_sign;
  // max(B^n, eps) with B = alpha + beta w: where the saturation starts, |B| = eps^(1/n).
  struct Saturation {
    double alpha, beta, edge;
  };
  std::vector<Saturation> saturations;
};

std::optional<Expression> Integrate(const Expression& phi, int w, const std::string& wname,
                                    Integral& side);

// (alpha, beta) with `b` = alpha + beta w, where w is the slot `w`; nullopt unless `b` is affine
// in w alone.
std::optional<std::pair<double, double>> AffineIn(const Expression& b, int w) {
  auto a = b.AsAffine();
  if (!a || a->terms.size() != 1 || a->terms[0].first != w) return std::nullopt;
  return std::make_pair(a->constant, a->terms[0].second);
}

// The antiderivative of B^n (B = `base` affine in w, n != -1): B^(n+1) / ((n+1) beta). A negative
// n records that B must keep one strict sign.
std::optional<Expression> IntegratePower(const Expression& base, int n, int w, Integral& side) {
  auto ab = AffineIn(base, w);
  if (!ab || n == -1) return std::nullopt;
  if (n < 0) side.same_sign.push_back(base);
  const double beta = ab->second;
  Expression up =
      n + 1 == 1 ? base : Expression::Binary(Op::kPow, base, Expression::Constant(n + 1));
  return up / Expression::Constant((n + 1) * beta);
}

// The value of `e` if it is an integer constant of magnitude at most 16.
std::optional<int> IntegerExponent(const Expression& e) {
  if (!e.is_constant()) return std::nullopt;
  const double v = e.constant();
  if (v != std::round(v) || std::abs(v) > 16) return std::nullopt;
  return static_cast<int>(v);
}

// `e` as (base, n) with e = base^n: a power with an integer exponent, or a base affine in w
// itself (n = 1).
std::optional<std::pair<Expression, int>> AsPower(const Expression& e, int w) {
  if (e.op() == Op::kPow) {
    if (auto n = IntegerExponent(e.args()[1])) return std::make_pair(e.args()[0], *n);
    return std::nullopt;
  }
  if (AffineIn(e, w)) return std::make_pair(e, 1);
  return std::nullopt;
}

// Integrate for a quotient `phi` = num / den: a denominator constant in w divides the numerator's
// antiderivative; otherwise the numerator must be constant in w and the denominator a power B^n
// (also as max(B^n, eps), whose saturation is recorded in `side`).
std::optional<Expression> IntegrateQuotient(const Expression& phi, int w, const std::string& wname,
                                            Integral& side) {
  const auto args = phi.args();
  if (!Reads(args[1], w)) {
    auto a = Integrate(args[0], w, wname, side);
    if (a) return *a / args[1];
    return std::nullopt;
  }
  if (Reads(args[0], w)) return std::nullopt;
  Expression den = args[1];
  if (den.op() == Op::kMax && den.args()[1].is_constant() && den.args()[1].constant() > 0 &&
      !Reads(den.args()[1], w)) {
    const double eps = den.args()[1].constant();
    side.domain.push_back({den.args()[0], Relation::kGreaterEqual, den.args()[1]});
    den = den.args()[0];
    auto p = AsPower(den, w);
    auto ab = p ? AffineIn(p->first, w) : std::nullopt;
    if (!p || !ab || p->second <= 0) return std::nullopt;
    side.saturations.push_back({ab->first, ab->second, std::pow(eps, 1.0 / p->second)});
  }
  auto p = AsPower(den, w);
  if (!p) return std::nullopt;
  if (p->second % 2 == 0) side.same_sign.push_back(p->first);
  auto prim = IntegratePower(p->first, -p->second, w, side);
  if (!prim) return std::nullopt;
  return args[0] * *prim;
}

std::optional<Expression> Integrate(const Expression& phi, int w, const std::string& wname,
                                    Integral& side) {
  const Expression W = Expression::Symbol(wname, w);
  if (!Reads(phi, w)) return phi * W;
  const auto args = phi.args();
  switch (phi.op()) {
    case Op::kAdd:
    case Op::kSub: {
      auto a = Integrate(args[0], w, wname, side);
      auto b = Integrate(args[1], w, wname, side);
      if (!a || !b) return std::nullopt;
      return phi.op() == Op::kAdd ? *a + *b : *a - *b;
    }
    case Op::kNeg: {
      auto a = Integrate(args[0], w, wname, side);
      if (!a) return std::nullopt;
      return -*a;
    }
    case Op::kMul:
      if (!Reads(args[0], w)) {
        auto b = Integrate(args[1], w, wname, side);
        if (b) return args[0] * *b;
      } else if (!Reads(args[1], w)) {
        auto a = Integrate(args[0], w, wname, side);
        if (a) return *a * args[1];
      }
      return std::nullopt;
    case Op::kDiv:
      return IntegrateQuotient(phi, w, wname, side);
    default: {
      auto p = AsPower(phi, w);
      if (!p || p->second < 0) return std::nullopt;
      return IntegratePower(p->first, p->second, w, side);
    }
  }
}

// Factors of a product/quotient chain.
void Factor(const Expression& e, bool numerator, std::vector<std::pair<Expression, bool>>& out) {
  if (e.op() == Op::kMul) {
    Factor(e.args()[0], numerator, out);
    Factor(e.args()[1], numerator, out);
  } else if (e.op() == Op::kDiv) {
    Factor(e.args()[0], numerator, out);
    Factor(e.args()[1], !numerator, out);
  } else {
    out.emplace_back(e, numerator);
  }
}

}  // namespace

SmtEncoding::SmtEncoding(z3::context& ctx, const Automaton& automaton)
    : ctx_(ctx), automaton_(automaton) {
  if (automaton.initial_states().empty()) {
    throw std::invalid_argument("automaton '" + automaton.name() +
                                "' has no initial state: nothing to verify");
  }
  const int n = automaton.symbols().size();
  var_index_.assign(n, -1);
  input_index_.assign(n, -1);
  for (const VariableInfo& v : automaton.variables()) {
    var_index_[v.slot] = static_cast<int>(var_slots_.size());
    var_slots_.push_back(v.slot);
  }
  nominal_ = automaton.ParameterEnvironment();
  for (const InputInfo& in : automaton.inputs()) {
    input_index_[in.slot] = static_cast<int>(input_slots_.size());
    input_slots_.push_back(in.slot);
    input_lo_.push_back(automaton.EvaluateConstant(in.bounds.lo, "input bound"));
    input_hi_.push_back(automaton.EvaluateConstant(in.bounds.hi, "input bound"));
  }
  params_.assign(n, std::nullopt);
  uncertain_slot_.assign(n, false);
  for (const auto& [slot, value] : automaton.parameters()) {
    const std::string& name = automaton.symbols()[slot].name;
    if (automaton.ParameterRange(slot)) {
      z3::expr p = ctx_.real_const(ConstantName("p", slot, -1).c_str());
      params_[slot] = p;
      uncertain_slot_[slot] = true;
      uncertain_.emplace_back(name, p);
      continue;
    }
    bool depends = false;
    for (int s : value.Slots()) depends = depends || uncertain_slot_[s];
    if (depends) {
      uncertain_slot_[slot] = true;
      params_[slot] = Translate(value, params_);
    } else {
      params_[slot] = Num(ctx_, nominal_[slot]);
    }
  }
  for (const z3::expr& d : definitions_) parameter_definitions_.push_back(d);
  definitions_.clear();
  outgoing_.assign(automaton.num_modes(), {});
  for (int t = 0; t < automaton.num_transitions(); ++t) {
    outgoing_[automaton.transitions()[t].source.value()].push_back(t);
  }
  Classify();
}

z3::expr SmtEncoding::NominalParameters() {
  z3::expr out = ctx_.bool_val(true);
  for (const auto& [slot, value] : automaton_.parameters()) {
    if (automaton_.ParameterRange(slot)) out = out && *params_[slot] == Num(ctx_, nominal_[slot]);
  }
  return out;
}

z3::expr SmtEncoding::TakeDefinitions() {
  z3::expr out = ctx_.bool_val(true);
  for (const z3::expr& d : definitions_) out = out && d;
  definitions_.clear();
  return out;
}

z3::expr SmtEncoding::Fresh() { return ctx_.real_const(ConstantName("aux", fresh_++, -1).c_str()); }

Expression SmtEncoding::Fold(const Expression& e) const {
  return e
      .Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
        if (automaton_.symbols()[slot].kind == SymbolKind::kParameter && !uncertain_slot_[slot]) {
          return Expression::Constant(nominal_[slot]);
        }
        return std::nullopt;
      })
      .FoldConstants();
}

void SmtEncoding::Classify() {
  const int nv = static_cast<int>(var_slots_.size());
  const int ni = static_cast<int>(input_slots_.size());
  for (const Mode& mode : automaton_.modes()) {
    ModeInfo info;
    info.drift.assign(nv, 0.0);
    info.rate.assign(nv, std::vector<double>(ni, 0.0));
    const Flows flows = MovingFlows(mode, info);
    if (flows.empty()) {
      info.flow_class = FlowClass::kStill;
    } else if (ConstantRates(flows, info)) {
      info.flow_class = FlowClass::kConstantRate;
    } else {
      info.flow_class = FlowClass::kGeneral;
      ClassifySeparable(flows, info);
      if (info.flow_class == FlowClass::kGeneral) ConstantDrifts(flows, info);
    }
    modes_.push_back(std::move(info));
  }
}

SmtEncoding::Flows SmtEncoding::MovingFlows(const Mode& mode, ModeInfo& info) const {
  Flows flows;
  for (const auto& [slot, rhs] : mode.flows) {
    Expression f = Fold(rhs);
    if (f.is_constant() && f.constant() == 0.0) continue;
    flows.emplace_back(var_index_[slot], f);
    info.moving.push_back(var_index_[slot]);
  }
  return flows;
}

bool SmtEncoding::ConstantRates(const Flows& flows, ModeInfo& info) const {
  bool constant_rate = true;
  for (const auto& [v, f] : flows) {
    auto a = f.AsAffine();
    if (!a) {
      constant_rate = false;
      break;
    }
    info.drift[v] = a->constant;
    for (const auto& [slot, coef] : a->terms) {
      if (input_index_[slot] < 0)
        constant_rate = false;
      else
        info.rate[v][input_index_[slot]] = coef;
    }
    if (!constant_rate) break;
  }
  return constant_rate;
}

void SmtEncoding::ConstantDrifts(const Flows& flows, ModeInfo& info) const {
  info.drift.assign(var_slots_.size(), 0.0);
  info.constant_drift.assign(var_slots_.size(), false);
  for (const auto& [v, f] : flows) {
    if (!f.is_constant()) continue;
    info.drift[v] = f.constant();
    info.constant_drift[v] = true;
  }
}

void SmtEncoding::ClassifySeparable(const Flows& flows, ModeInfo& info) const {
  // Separable: one input u, a driver w' = c u, others K(y) phi(w) u.
  std::vector<int> inputs_read;
  for (const auto& [v, f] : flows) {
    for (int s : f.Slots()) {
      if (input_index_[s] >= 0 &&
          std::find(inputs_read.begin(), inputs_read.end(), s) == inputs_read.end()) {
        inputs_read.push_back(s);
      }
    }
  }
  if (inputs_read.size() != 1) return;
  const int u = inputs_read[0];
  for (const auto& [v, f] : flows) {
    auto a = f.AsAffine();
    if (a && a->constant == 0.0 && a->terms.size() == 1 && a->terms[0].first == u) {
      info.driver = v;
      info.driver_rate = a->terms[0].second;
      break;
    }
  }
  std::vector<bool> still(automaton_.symbols().size(), true);
  for (const auto& [v, f] : flows) still[var_slots_[v]] = false;
  bool ok = info.driver >= 0;
  const int w = ok ? var_slots_[info.driver] : -1;
  for (const auto& [v, f] : flows) {
    if (!ok || v == info.driver) continue;
    std::optional<SeparableFlow> sf = Separate(v, f, u, w, still, info.driver);
    if (!sf) {
      ok = false;
      break;
    }
    info.separable.push_back(std::move(*sf));
  }
  if (ok) {
    info.flow_class = FlowClass::kSeparable;
    info.input = input_index_[u];
  }
}

namespace {

// The factor h of a flow f = h * u or u * h of the input slot `u`, or the constant c of f = c u
// (a second driver, e.g. a motor position beside the finger's drive, is separable with phi = 1);
// nullopt for another form. h may still read u.
std::optional<Expression> InputFactor(const Expression& f, int u) {
  std::optional<Expression> h;
  const auto affine = f.AsAffine();
  if (affine && affine->constant == 0.0 && affine->terms.size() == 1 &&
      affine->terms[0].first == u) {
    h = Expression::Constant(affine->terms[0].second);
  } else if (f.op() == Op::kMul) {
    if (f.args()[1].is_symbol() && f.args()[1].slot() == u)
      h = f.args()[0];
    else if (f.args()[0].is_symbol() && f.args()[0].slot() == u)
      h = f.args()[1];
  }
  return h;
}

}  // namespace

std::optional<SmtEncoding::SeparableFlow> SmtEncoding::Separate(int v, const Expression& f, int u,
                                                                int w,
                                                                const std::vector<bool>& still,
                                                                int driver) const {
  const std::optional<Expression> h = InputFactor(f, u);
  if (!h || Reads(*h, u)) return std::nullopt;
  Expression k = Expression::Constant(1.0), phi = Expression::Constant(1.0);
  if (!SplitFactors(*h, w, still, k, phi)) return std::nullopt;
  SeparableFlow sf;
  sf.var = v;
  sf.k = k.FoldConstants();
  phi = phi.FoldConstants();
  sf.sign_phi = SignOnDomain(phi, driver);
  Integral side;
  sf.antiderivative = Integrate(phi, w, automaton_.symbols()[w].name, side);
  sf.domain = side.domain;
  if (side.saturations.size() == 1) {
    const auto& sat = side.saturations[0];
    sf.saturation = {sat.alpha, sat.beta, sat.edge};
  } else if (side.saturations.size() > 1) {
    sf.antiderivative.reset();
  }
  for (const Expression& b : side.same_sign) {
    // Recorded as a comparison `b != 0` is not expressible; keep as b (checked in Flow).
    sf.domain.push_back({b, Relation::kEqual, Expression::Constant(0.0)});
  }
  return sf;
}

bool SmtEncoding::SplitFactors(const Expression& h, int w, const std::vector<bool>& still,
                               Expression& k, Expression& phi) const {
  bool ok = true;
  std::vector<std::pair<Expression, bool>> factors;
  Factor(h, true, factors);
  for (const auto& [e, num] : factors) {
    bool reads_w = false, reads_other = false;
    for (int s : e.Slots()) {
      if (s == w)
        reads_w = true;
      else if (automaton_.symbols()[s].kind == SymbolKind::kVariable && !still[s])
        reads_other = true;
      else if (automaton_.symbols()[s].kind == SymbolKind::kInput)
        reads_other = true;
    }
    if (reads_other) ok = false;
    if (reads_w) {
      for (int s : e.Slots()) {
        if (s != w) ok = false;  // phi may read only w and numbers
      }
      phi = num ? phi * e : phi / e;
    } else {
      k = num ? k * e : k / e;
    }
  }
  return ok;
}

double SmtEncoding::SignOnDomain(const Expression& phi, int driver) const {
  const VariableInfo& wi = automaton_.variables()[driver];
  if (!wi.domain) return 0.0;
  const double lo = wi.domain->lo.Evaluate(nominal_), hi = wi.domain->hi.Evaluate(nominal_);
  std::vector<Interval> env(automaton_.symbols().size(), Interval(0.0, 0.0));
  env[var_slots_[driver]] = Interval(lo, hi);
  const Interval r = phi.EvaluateInterval(env);
  return r.lo() > 0 ? 1.0 : (r.hi() < 0 ? -1.0 : 0.0);
}

std::string SmtEncoding::ConstantName(std::string_view kind, int index, int step) {
  std::string out(kind);
  if (index >= 0) out += "." + std::to_string(index);
  if (step >= 0) out += "@" + std::to_string(step);
  return out;
}

SmtEncoding::StepVars& SmtEncoding::Vars(int k) {
  while (static_cast<int>(steps_.size()) <= k) {
    const int s = static_cast<int>(steps_.size());
    auto real = [&](std::string_view kind, int index) {
      return ctx_.real_const(ConstantName(kind, index, s).c_str());
    };
    auto boolean = [&](std::string_view kind, int index) {
      return ctx_.bool_const(ConstantName(kind, index, s).c_str());
    };
    StepVars v{{}, {}, {}, {}, real("d", -1), boolean("flow", -1), {}, {}};
    for (int m = 0; m < automaton_.num_modes(); ++m) {
      v.mode.push_back(boolean("mode", m));
      v.amo.push_back(boolean("amo", m));
    }
    for (std::size_t i = 0; i < var_slots_.size(); ++i) v.x.push_back(real("x", i));
    for (std::size_t i = 0; i < input_slots_.size(); ++i) {
      v.u.push_back(real("u", i));
      v.v.push_back(real("V", i));
    }
    for (int t = 0; t < automaton_.num_transitions(); ++t) v.jump.push_back(boolean("jump", t));
    steps_.push_back(std::move(v));
  }
  return steps_[k];
}

const std::vector<std::optional<z3::expr>>& SmtEncoding::Env(int k) {
  while (static_cast<int>(envs_.size()) <= k) {
    const int s = static_cast<int>(envs_.size());
    StepVars& v = Vars(s);
    std::vector<std::optional<z3::expr>> env = params_;
    for (std::size_t i = 0; i < var_slots_.size(); ++i) env[var_slots_[i]] = v.x[i];
    for (std::size_t i = 0; i < input_slots_.size(); ++i) env[input_slots_[i]] = v.u[i];
    for (int slot : automaton_.discrete_variables()) env[slot] = Discrete(s, slot);
    envs_.push_back(std::move(env));
  }
  return envs_[k];
}

z3::expr SmtEncoding::Reuse(std::deque<std::optional<Built>>& cache, int k,
                            const std::function<z3::expr()>& build) {
  while (static_cast<int>(cache.size()) <= k) cache.emplace_back();
  if (!cache[k]) {
    // Build with the pending definitions set aside: the cache keeps exactly this formula's.
    std::vector<z3::expr> pending = std::move(definitions_);
    definitions_.clear();
    z3::expr formula = build();
    cache[k] = Built{formula, std::move(definitions_)};
    definitions_ = std::move(pending);
  }
  for (const z3::expr& d : cache[k]->definitions) definitions_.push_back(d);
  return cache[k]->formula;
}

z3::expr SmtEncoding::Discrete(int k, int slot) { return DiscreteIn(k, slot, {}); }

z3::expr SmtEncoding::DiscreteIn(int k, int slot, const std::vector<bool>& modes) {
  StepVars& v = Vars(k);
  const auto value = [&](int m) {
    return Num(ctx_, automaton_.modes()[m].DiscreteValueOf(slot).value_or(0));
  };
  std::vector<int> in;
  for (int m = 0; m < automaton_.num_modes(); ++m) {
    if (modes.empty() || modes[static_cast<std::size_t>(m)]) in.push_back(m);
  }
  if (!modes.empty() && in.size() == 1) return value(in[0]);  // s_k is in that mode
  z3::expr out = Num(ctx_, 0.0);
  for (auto m = in.rbegin(); m != in.rend(); ++m) out = z3::ite(v.mode[*m], value(*m), out);
  return out;
}

z3::expr SmtEncoding::Translate(const Expression& e,
                                const std::vector<std::optional<z3::expr>>& env) {
  std::unordered_map<const void*, z3::expr> memo;
  std::function<z3::expr(const Expression&)> go = [&](const Expression& x) -> z3::expr {
    if (auto it = memo.find(x.node_id()); it != memo.end()) return it->second;
    z3::expr out(ctx_);
    const auto args = x.args();
    switch (x.op()) {
      case Op::kConstant:
        out = Num(ctx_, x.constant());
        break;
      case Op::kSymbol:
        if (!env.at(x.slot())) {
          throw std::logic_error("verification: no value for '" + x.symbol_name() + "'");
        }
        out = *env[x.slot()];
        break;
      case Op::kNeg:
        out = -go(args[0]);
        break;
      case Op::kAdd:
        out = go(args[0]) + go(args[1]);
        break;
      case Op::kSub:
        out = go(args[0]) - go(args[1]);
        break;
      case Op::kMul:
        out = go(args[0]) * go(args[1]);
        break;
      case Op::kDiv: {
        z3::expr num = go(args[0]), den = go(args[1]);
        out = Quotient(num, den);
        break;
      }
      case Op::kPow:
        out = Power(args[0], args[1], go);
        break;
      case Op::kMin: {
        z3::expr a = go(args[0]), b = go(args[1]);
        out = z3::ite(a <= b, a, b);
        break;
      }
      case Op::kMax: {
        z3::expr a = go(args[0]), b = go(args[1]);
        out = z3::ite(a >= b, a, b);
        break;
      }
      case Op::kAbs: {
        z3::expr a = go(args[0]);
        out = z3::ite(a >= 0, a, -a);
        break;
      }
      case Op::kSign: {
        z3::expr a = go(args[0]);
        out = z3::ite(a > 0, Num(ctx_, 1), z3::ite(a < 0, Num(ctx_, -1), Num(ctx_, 0)));
        break;
      }
      default:
        // Transcendental functions: an unconstrained value (a sound over-approximation).
        out = Fresh();
        break;
    }
    memo.emplace(x.node_id(), out);
    return out;
  };
  return go(e);
}

z3::expr SmtEncoding::Quotient(const z3::expr& num, const z3::expr& den) {
  if (den.is_numeral()) return num / den;
  // q = num / den as the polynomial definition den q = num (den != 0), so that the formulas stay
  // polynomial (nlsat); q is unconstrained where den = 0 (undefined).
  z3::expr out = Fresh();
  definitions_.push_back(z3::implies(den != 0, out * den == num));
  return out;
}

z3::expr SmtEncoding::Power(const Expression& base, const Expression& ex,
                            const std::function<z3::expr(const Expression&)>& translate) {
  if (ex.is_constant() && ex.constant() == std::round(ex.constant()) &&
      std::abs(ex.constant()) <= 16) {
    const int n = static_cast<int>(ex.constant());
    z3::expr b = translate(base);
    z3::expr p = Num(ctx_, 1.0);
    for (int i = 0; i < std::abs(n); ++i) p = i == 0 ? b : p * b;
    return n >= 0 ? p : Num(ctx_, 1.0) / p;
  }
  return Fresh();
}

z3::expr SmtEncoding::InBand(const z3::expr& r, const ResidualBand& band) {
  // The plainest formula for each shape of band (`r <= hi`, `lo <= r`, `r == v`, both ends), so
  // that the solver sees what it would for the comparison itself.
  if (band.lower && band.upper && *band.lower == *band.upper && !band.lower_strict &&
      !band.upper_strict) {
    return r == Num(r.ctx(), *band.lower);
  }
  std::optional<z3::expr> out;
  if (band.upper) {
    const z3::expr hi = Num(r.ctx(), *band.upper);
    out = band.upper_strict ? r < hi : r <= hi;
  }
  if (band.lower) {
    const z3::expr lo = Num(r.ctx(), *band.lower);
    const z3::expr lower = band.lower_strict ? r > lo : r >= lo;
    out = out ? (*out && lower) : lower;
  }
  return out ? *out : r.ctx().bool_val(true);
}

z3::expr SmtEncoding::Compare(const Comparison& c, const std::vector<std::optional<z3::expr>>& env,
                              double margin, Boundary boundary) {
  // The band of residuals that satisfy c (include/hybrid/automaton/constraint.h: the one definition
  // of a comparison within tolerance, which the simulator and the replay evaluate numerically).
  const ResidualBand band =
      margin == 0.0 ? ResidualBand::Of(c.relation, 0.0, boundary) : LenientBand(c.relation, margin);
  return InBand(Translate(c.lhs, env) - Translate(c.rhs, env), band);
}

z3::expr SmtEncoding::Conjunction(const Constraint& c,
                                  const std::vector<std::optional<z3::expr>>& env,
                                  Boundary boundary) {
  z3::expr out = ctx_.bool_val(true);
  for (const Comparison& cmp : c.comparisons) out = out && Compare(cmp, env, 0.0, boundary);
  return out;
}

z3::expr SmtEncoding::Initial() {
  StepVars& v = Vars(0);
  z3::expr out = ctx_.bool_val(true);
  for (const auto& [slot, value] : automaton_.parameters()) {
    if (auto range = automaton_.ParameterRange(slot); range && uncertain_slot_[slot]) {
      out = out && Translate(range->lo, params_) <= *params_[slot] &&
            *params_[slot] <= Translate(range->hi, params_);
    }
  }
  z3::expr any = ctx_.bool_val(false);
  for (int j = 0; j < static_cast<int>(automaton_.initial_states().size()); ++j) {
    any = any || InitialState(j);
  }
  return out && any;
}

z3::expr SmtEncoding::InitialState(int index) {
  StepVars& v = Vars(0);
  const hybrid::InitialState& init = automaton_.initial_states()[static_cast<std::size_t>(index)];
  z3::expr one = v.mode[init.mode.value()];
  for (const InitialValue& iv : init.values) {
    const z3::expr& x = v.x[var_index_[iv.slot]];
    if (iv.is_point) {
      one = one && x == Translate(iv.range.lo, params_);
    } else {
      one = one && Translate(iv.range.lo, params_) <= x && x <= Translate(iv.range.hi, params_);
    }
  }
  return one;
}

int SmtEncoding::InitialIndex(const z3::model& model) {
  for (int j = 0; j < static_cast<int>(automaton_.initial_states().size()); ++j) {
    if (model.eval(InitialState(j), true).is_true()) return j;
  }
  return -1;
}

z3::expr SmtEncoding::State(int k) {
  return Reuse(states_, k, [&] { return StateOf(k, nullptr); });
}

z3::expr SmtEncoding::StateIn(int k, const std::vector<bool>& modes) {
  HYBRID_ASSERT(static_cast<int>(modes.size()) == automaton_.num_modes(), "a flag per mode");
  return StateOf(k, &modes);
}

z3::expr SmtEncoding::StateOf(int k, const std::vector<bool>* allowed) {
  StepVars& v = Vars(k);
  const auto& env = Env(k);
  const auto in = [allowed](std::size_t m) { return allowed == nullptr || (*allowed)[m]; };
  // One flat conjunction of plain clauses (which every Z3 tactic accepts; a long chain of
  // binary `&&` is slow for Z3 to free).
  z3::expr_vector clauses(ctx_);
  // Exactly one mode: at least one, and at most one by a ladder over the allowed modes (amo[m]:
  // some allowed mode <= m), linear in their number; the others are out.
  z3::expr_vector modes(ctx_);
  std::optional<std::size_t> previous;
  for (std::size_t m = 0; m < v.mode.size(); ++m) {
    if (!in(m)) {
      clauses.push_back(!v.mode[m]);
      continue;
    }
    modes.push_back(v.mode[m]);
    clauses.push_back(!v.mode[m] || v.amo[m]);
    if (previous) {
      clauses.push_back(!v.amo[*previous] || v.amo[m]);
      clauses.push_back(!v.amo[*previous] || !v.mode[m]);
    }
    previous = m;
  }
  clauses.push_back(z3::mk_or(modes));
  for (const z3::expr& d : parameter_definitions_) clauses.push_back(d);
  // Uncertain parameters stay in their ranges in every state (also in induction steps, which
  // do not start from an initial state).
  for (const auto& [slot, value] : automaton_.parameters()) {
    if (auto range = automaton_.ParameterRange(slot); range && uncertain_slot_[slot]) {
      clauses.push_back(Translate(range->lo, params_) <= *params_[slot]);
      clauses.push_back(*params_[slot] <= Translate(range->hi, params_));
    }
  }
  for (int m = 0; m < automaton_.num_modes(); ++m) {
    const Constraint& inv = automaton_.modes()[m].invariant;
    // Invariants in their closure: the boundary belongs to the mode, as in the simulator.
    if (!inv.empty() && in(static_cast<std::size_t>(m))) {
      clauses.push_back(z3::implies(v.mode[m], Conjunction(inv, env, Boundary::kClosure)));
    }
  }
  for (std::size_t i = 0; i < input_slots_.size(); ++i) {
    clauses.push_back(Num(ctx_, input_lo_[i]) <= v.u[i]);
    clauses.push_back(v.u[i] <= Num(ctx_, input_hi_[i]));
  }
  return z3::mk_and(clauses);
}

z3::expr SmtEncoding::InMode(int k, ModeId m) { return Vars(k).mode.at(m.value()); }

z3::expr SmtEncoding::Holds(const Predicate& p, int k, double tolerance) {
  return HoldsOf(p, k, nullptr, tolerance);
}

z3::expr SmtEncoding::HoldsIn(const Predicate& p, int k, const std::vector<bool>& modes,
                              double tolerance) {
  HYBRID_ASSERT(static_cast<int>(modes.size()) == automaton_.num_modes(), "a flag per mode");
  return HoldsOf(p, k, &modes, tolerance);
}

z3::expr SmtEncoding::HoldsOf(const Predicate& p, int k, const std::vector<bool>* modes,
                              double tolerance) {
  std::vector<std::optional<z3::expr>> restricted;
  if (modes != nullptr) {
    restricted = Env(k);
    for (int slot : automaton_.discrete_variables()) restricted[slot] = DiscreteIn(k, slot, *modes);
  }
  const auto& env = modes != nullptr ? restricted : Env(k);
  std::function<z3::expr(const Predicate&, bool)> go = [&](const Predicate& q,
                                                           bool positive) -> z3::expr {
    switch (q.kind()) {
      case Predicate::Kind::kTrue:
        return ctx_.bool_val(true);
      case Predicate::Kind::kFalse:
        return ctx_.bool_val(false);
      case Predicate::Kind::kComparison:
        return Compare(q.comparison(), env, positive ? tolerance : -tolerance);
      case Predicate::Kind::kInMode: {
        auto m = automaton_.FindMode(q.mode());
        if (!m || (modes != nullptr && !(*modes)[static_cast<std::size_t>(m->value())])) {
          return ctx_.bool_val(false);
        }
        return InMode(k, *m);
      }
      case Predicate::Kind::kNot:
        return !go(q.operands()[0], !positive);
      case Predicate::Kind::kAnd:
        return go(q.operands()[0], positive) && go(q.operands()[1], positive);
      case Predicate::Kind::kOr:
        return go(q.operands()[0], positive) || go(q.operands()[1], positive);
    }
    return ctx_.bool_val(false);
  };
  return go(p, true);
}

z3::expr SmtEncoding::Flow(int k, int mode) {
  StepVars& a = Vars(k);
  StepVars& b = Vars(k + 1);
  const ModeInfo& info = modes_[mode];
  z3::expr out = a.d >= 0;
  std::vector<bool> moving(var_slots_.size(), false);
  for (int v : info.moving) moving[v] = true;
  for (std::size_t v = 0; v < var_slots_.size(); ++v) {
    if (!moving[v]) out = out && b.x[v] == a.x[v];
  }
  const int ni = static_cast<int>(input_slots_.size());
  switch (info.flow_class) {
    case FlowClass::kStill:
      break;
    case FlowClass::kConstantRate:
      ConstantRateFlow(k, info, out);
      break;
    case FlowClass::kSeparable:
      SeparableFlowStep(k, info, out);
      break;
    case FlowClass::kGeneral:
      for (int i = 0; i < ni; ++i) {
        out = out && Num(ctx_, input_lo_[i]) * a.d <= a.v[i] &&
              a.v[i] <= Num(ctx_, input_hi_[i]) * a.d;
      }
      for (int v : info.moving) {
        if (info.constant_drift[v]) {
          out = out && b.x[v] == a.x[v] + Num(ctx_, info.drift[v]) * a.d;
        }
      }
      break;
  }
  return out && NoUrgentGuardOnSegment(k, mode);
}

z3::expr SmtEncoding::InputLink(const StepVars& a, int i) {
  return z3::implies(a.v[i] > 0, a.u[i] > 0) && z3::implies(a.v[i] < 0, a.u[i] < 0) &&
         Num(ctx_, input_lo_[i]) * a.d <= a.v[i] && a.v[i] <= Num(ctx_, input_hi_[i]) * a.d;
}

void SmtEncoding::ConstantRateFlow(int k, const ModeInfo& info, z3::expr& out) {
  StepVars& a = Vars(k);
  StepVars& b = Vars(k + 1);
  const int ni = static_cast<int>(input_slots_.size());
  for (int i = 0; i < ni; ++i) out = out && InputLink(a, i);
  for (int v : info.moving) {
    z3::expr rhs = a.x[v] + Num(ctx_, info.drift[v]) * a.d;
    for (int i = 0; i < ni; ++i) {
      if (info.rate[v][i] != 0.0) rhs = rhs + Num(ctx_, info.rate[v][i]) * a.v[i];
    }
    out = out && b.x[v] == rhs;
  }
}

void SmtEncoding::SeparableFlowStep(int k, const ModeInfo& info, z3::expr& out) {
  StepVars& a = Vars(k);
  StepVars& b = Vars(k + 1);
  const int i = info.input;
  out = out && InputLink(a, i);
  const int w = info.driver;
  out = out && b.x[w] == a.x[w] + Num(ctx_, info.driver_rate) * a.v[i];
  const Segment segment{a, b, Env(k), Env(k + 1)};
  for (const SeparableFlow& sf : info.separable) SeparableVariable(segment, info, sf, out);
}

void SmtEncoding::SeparableVariable(const Segment& segment, const ModeInfo& info,
                                    const SeparableFlow& sf, z3::expr& out) {
  const StepVars& a = segment.a;
  const StepVars& b = segment.b;
  const int w = info.driver;
  const z3::expr K = Translate(sf.k, segment.env0);
  const z3::expr dv = b.x[sf.var] - a.x[sf.var];
  const double s = sf.sign_phi * (info.driver_rate > 0 ? 1.0 : -1.0);
  if (s != 0.0) {
    const z3::expr dw = Num(ctx_, s) * (b.x[w] - a.x[w]);
    out = out && z3::implies(K >= 0 && dw >= 0, dv >= 0) &&
          z3::implies(K >= 0 && dw <= 0, dv <= 0) && z3::implies(K <= 0 && dw >= 0, dv <= 0) &&
          z3::implies(K <= 0 && dw <= 0, dv >= 0);
  }
  if (sf.antiderivative) SeparableLaw(segment, info, sf, K, dv, s, out);
}

void SmtEncoding::SeparableLaw(const Segment& segment, const ModeInfo& info,
                               const SeparableFlow& sf, const z3::expr& K, const z3::expr& dv,
                               double s, z3::expr& out) {
  const auto& env0 = segment.env0;
  const auto& env1 = segment.env1;
  z3::expr ok = ctx_.bool_val(true);
  for (const Comparison& c : sf.domain) {
    if (c.relation == Relation::kEqual) {  // a pole-free factor: one strict sign
      const z3::expr b0 = Translate(c.lhs, env0), b1 = Translate(c.lhs, env1);
      ok = ok && ((b0 > 0 && b1 > 0) || (b0 < 0 && b1 < 0));
    } else {
      ok = ok && Compare(c, env0, 0.0) && Compare(c, env1, 0.0);
    }
  }
  const z3::expr phi0 = Translate(*sf.antiderivative, env0);
  const z3::expr phi1 = Translate(*sf.antiderivative, env1);
  const z3::expr c = Num(ctx_, info.driver_rate);
  out = out && z3::implies(ok, c * dv == K * (phi1 - phi0));
  if (sf.saturation && s != 0.0) SaturationCrossing(segment, info, sf, {K, dv, phi0, phi1, c}, out);
}

void SmtEncoding::SaturationCrossing(const Segment& segment, const ModeInfo& info,
                                     const SeparableFlow& sf, const Law& law, z3::expr& out) {
  const StepVars& a = segment.a;
  const StepVars& b = segment.b;
  const auto& env0 = segment.env0;
  const auto& env1 = segment.env1;
  const int w = info.driver;
  const z3::expr& K = law.k;
  const z3::expr& dv = law.dv;
  const z3::expr& phi0 = law.phi0;
  const z3::expr& phi1 = law.phi1;
  const z3::expr& c = law.c;
  // One end inside the law's domain, the other in the saturation of max(B^n, eps): the exact law
  // holds up to the edge w*, where |B| = eps^(1/n), and v moves on monotonically beyond it.
  const auto [alpha, beta, edge] = *sf.saturation;
  auto in = [&](const std::vector<std::optional<z3::expr>>& env) {
    z3::expr r = ctx_.bool_val(true);
    for (const Comparison& cmp : sf.domain) {
      if (cmp.relation != Relation::kEqual) r = r && Compare(cmp, env, 0.0);
    }
    return r;
  };
  const z3::expr in0 = in(env0), in1 = in(env1);
  for (double side_sign : {1.0, -1.0}) {
    const double w_edge = (side_sign * edge - alpha) / beta;
    std::vector<std::optional<z3::expr>> env_edge = env0;
    env_edge[var_slots_[w]] = Num(ctx_, w_edge);
    const z3::expr phi_edge = Translate(*sf.antiderivative, env_edge);
    const z3::expr b0 = Num(ctx_, alpha) + Num(ctx_, beta) * a.x[w];
    const z3::expr b1 = Num(ctx_, alpha) + Num(ctx_, beta) * b.x[w];
    const z3::expr side0 = side_sign > 0 ? b0 > 0 : b0 < 0;
    const z3::expr side1 = side_sign > 0 ? b1 > 0 : b1 < 0;
    // Leaving the domain: v0 -> v* = v0 + D -> beyond.
    const z3::expr d_out = K * (phi_edge - phi0) / c;
    out = out && z3::implies(in0 && !in1 && side0, z3::implies(d_out >= 0, dv >= d_out) &&
                                                       z3::implies(d_out <= 0, dv <= d_out));
    // Entering it: v0 -> v* -> v1 = v* + D.
    const z3::expr d_in = K * (phi1 - phi_edge) / c;
    out = out && z3::implies(!in0 && in1 && side1, z3::implies(d_in >= 0, dv >= d_in) &&
                                                       z3::implies(d_in <= 0, dv <= d_in));
  }
}

z3::expr SmtEncoding::NoUrgentGuardOnSegment(int k, int mode) {
  const ModeInfo& info = modes_[mode];
  StepVars& a = Vars(k);
  StepVars& b = Vars(k + 1);
  // Parametrisation of the segment for kConstantRate: sigma = V_i (one input, no drift) or d (no
  // input rates): x(sigma) = x_k + dir sigma.
  std::optional<z3::expr> const_sigma;
  std::vector<double> dir(var_slots_.size(), 0.0);
  if (info.flow_class == FlowClass::kConstantRate) {
    if (!StraightSegment(info, a, const_sigma, dir)) return ctx_.bool_val(true);
  } else if (info.flow_class != FlowClass::kSeparable) {
    // kGeneral and kStill: sigma = d for the variables with a constant flow; a guard that reads
    // another moving variable (NaN direction) is not encoded. (kStill moves nothing.)
    const_sigma = a.d;
    for (int v : info.moving) {
      dir[v] = info.constant_drift[v] ? info.drift[v] : std::numeric_limits<double>::quiet_NaN();
    }
  }
  std::vector<bool> moving(var_slots_.size(), false);
  for (int v : info.moving) moving[v] = true;
  const auto& env = Env(k);
  z3::expr out = ctx_.bool_val(true);
  for (int t : outgoing_[mode]) {
    const hybrid::Transition& tr = automaton_.transitions()[t];
    if (tr.urgency != Urgency::kUrgent) continue;
    int sep_var = -1;
    const std::optional<std::vector<GuardAtom>> atoms =
        GuardAtoms(tr, moving, const_sigma, dir, env, sep_var);
    if (!atoms) continue;
    z3::expr sigma_end =
        const_sigma ? *const_sigma : (sep_var >= 0 ? b.x[sep_var] - a.x[sep_var] : Num(ctx_, 0.0));
    out = out && z3::implies(sigma_end > 0, !GuardMeets(*atoms, sigma_end, 1)) &&
          z3::implies(sigma_end < 0, !GuardMeets(*atoms, sigma_end, -1)) &&
          z3::implies(sigma_end == 0, !GuardMeets(*atoms, sigma_end, 0));
  }
  return out;
}

bool SmtEncoding::StraightSegment(const ModeInfo& info, const StepVars& a,
                                  std::optional<z3::expr>& const_sigma,
                                  std::vector<double>& dir) const {
  const int ni = static_cast<int>(input_slots_.size());
  int rated = -1, count = 0;
  bool drift = false;
  for (int v : info.moving) {
    drift = drift || info.drift[v] != 0.0;
    for (int i = 0; i < ni; ++i) {
      if (info.rate[v][i] != 0.0 && rated != i) {
        rated = i;
        ++count;
      }
    }
  }
  if (count == 1 && !drift) {
    const_sigma = a.v[rated];
    for (int v : info.moving) dir[v] = info.rate[v][rated];
  } else if (count == 0 && drift) {
    const_sigma = a.d;
    for (int v : info.moving) dir[v] = info.drift[v];
  } else {
    return false;
  }
  return true;
}

std::optional<std::vector<SmtEncoding::GuardAtom>> SmtEncoding::GuardAtoms(
    const hybrid::Transition& tr, const std::vector<bool>& moving,
    const std::optional<z3::expr>& const_sigma, const std::vector<double>& dir,
    const std::vector<std::optional<z3::expr>>& env, int& sep_var) {
  std::vector<GuardAtom> atoms;
  bool ok = true;
  for (const Comparison& c : tr.guard.comparisons) {
    const Expression r = Fold(c.Residual());
    auto aff = r.AsAffine();
    if (!aff) {
      ok = false;
      break;
    }
    double beta = 0.0;
    z3::expr beta_q = Num(ctx_, 0.0);
    for (const auto& [slot, coef] : aff->terms) {
      const int v = var_index_[slot];
      if (v < 0 || !moving[v]) continue;
      if (const_sigma && std::isnan(dir[v])) {
        ok = false;  // a variable the encoding does not follow along the segment
      } else if (const_sigma) {
        beta += coef * dir[v];
        beta_q = beta_q + Num(ctx_, coef) * Num(ctx_, dir[v]);
      } else {
        if (sep_var >= 0 && sep_var != v) ok = false;
        sep_var = v;
        beta = coef;
        beta_q = Num(ctx_, coef);
      }
    }
    if (!ok) break;
    atoms.push_back({Translate(r, env), beta, beta_q.simplify(), c.relation});
  }
  if (!ok) return std::nullopt;
  return atoms;
}

z3::expr SmtEncoding::GuardMeets(const std::vector<GuardAtom>& atoms, const z3::expr& sigma_end,
                                 int sign) {
  z3::expr fixed = ctx_.bool_val(true);
  std::vector<std::pair<z3::expr, bool>> lower, upper;  // (bound, strict)
  for (const GuardAtom& at : atoms) {
    if (at.beta == 0.0 || sign == 0) {
      fixed = AndHoldsAtStart(fixed, at);
      continue;
    }
    AddSigmaBound(at, lower, upper);
  }
  if (sign == 0) return fixed;
  if (sign > 0) {
    lower.emplace_back(Num(ctx_, 0.0), false);
    upper.emplace_back(sigma_end, true);
  } else {
    lower.emplace_back(sigma_end, true);
    upper.emplace_back(Num(ctx_, 0.0), false);
  }
  z3::expr out2 = fixed;
  for (const auto& [l, ls] : lower) {
    for (const auto& [h, hs] : upper) out2 = out2 && ((ls || hs) ? l < h : l <= h);
  }
  return out2;
}

z3::expr SmtEncoding::AndHoldsAtStart(const z3::expr& fixed, const GuardAtom& at) {
  return fixed && InBand(at.alpha, ResidualBand::Of(at.rel, 0.0));
}

void SmtEncoding::AddSigmaBound(const GuardAtom& at, std::vector<std::pair<z3::expr, bool>>& lower,
                                std::vector<std::pair<z3::expr, bool>>& upper) {
  // alpha + beta sigma in the comparison's band  <=>  sigma between (end - alpha) / beta for
  // each end of the band (ResidualBand, exact), the ends swapping when beta < 0. Exact rational
  // arithmetic: beta is a numeral.
  const ResidualBand band = ResidualBand::Of(at.rel, 0.0);
  const bool up = at.beta > 0;
  if (band.upper) {
    const z3::expr bound = (Num(at.alpha.ctx(), *band.upper) - at.alpha) / at.beta_q;
    (up ? upper : lower).emplace_back(bound, band.upper_strict);
  }
  if (band.lower) {
    const z3::expr bound = (Num(at.alpha.ctx(), *band.lower) - at.alpha) / at.beta_q;
    (up ? lower : upper).emplace_back(bound, band.lower_strict);
  }
}

bool SmtEncoding::ReadsMovingVariable(const Comparison& c, int mode) const {
  const std::vector<int>& moving = modes_[static_cast<std::size_t>(mode)].moving;
  for (const Expression* side : {&c.lhs, &c.rhs}) {
    for (int slot : side->Slots()) {
      if (slot < 0 || slot >= static_cast<int>(var_index_.size())) continue;
      const int v = var_index_[slot];
      if (v >= 0 && std::find(moving.begin(), moving.end(), v) != moving.end()) return true;
    }
  }
  return false;
}

z3::expr SmtEncoding::Jump(int k, int t) {
  const hybrid::Transition& tr = automaton_.transitions()[t];
  StepVars& a = Vars(k);
  StepVars& b = Vars(k + 1);
  const auto& env = Env(k);
  // A strict comparison that reads a variable moving in the source mode (a flow) is taken in its
  // closure (`<` as `<=`, `>` as `>=`): the simulator fires a transition where the guard's
  // residual crosses 0, which for a strict guard is a point where the guard itself is still
  // false (`x > 1` reached by x' = 1 fires at x = 1). Comparisons of inputs, parameters and
  // variables that do not move in the mode only change their truth at input breakpoints and
  // jumps, where they are evaluated as they are: they stay strict. Every jump the simulator
  // takes meets this guard (more jumps: sound for proofs).
  z3::expr out = a.mode[tr.source.value()] && b.mode[tr.target.value()];
  for (const Comparison& c : tr.guard.comparisons) {
    const Boundary boundary =
        ReadsMovingVariable(c, tr.source.value()) ? Boundary::kClosure : Boundary::kExact;
    out = out && Compare(c, env, 0.0, boundary);
  }
  std::vector<bool> reset(var_slots_.size(), false);
  for (const Reset& r : tr.resets) {
    const int v = var_index_[r.slot];
    reset[v] = true;
    out = out && b.x[v] == Translate(r.value, env);
  }
  for (std::size_t v = 0; v < var_slots_.size(); ++v) {
    if (!reset[v]) out = out && b.x[v] == a.x[v];
  }
  return out;
}

z3::expr SmtEncoding::FlowMove(int k, int mode) {
  return Vars(k).flow && Vars(k + 1).mode[mode] && Flow(k, mode);
}

z3::expr SmtEncoding::JumpMove(int k, int t) { return Vars(k).jump[t] && Jump(k, t); }

z3::expr SmtEncoding::TransitionFrom(int k, ModeId m) {
  const int mode = m.value();
  z3::expr_vector options(ctx_);
  options.push_back(FlowMove(k, mode));
  for (int t : outgoing_[mode]) options.push_back(JumpMove(k, t));
  return Vars(k).mode[mode] && z3::mk_or(options);
}

z3::expr SmtEncoding::MoveFrom(int k, ModeId m, std::optional<TransitionId> jump) {
  const int mode = m.value();
  HYBRID_ASSERT(!jump || automaton_.transition(*jump).source == m,
                "a move from a mode is one of its transitions");
  return Vars(k).mode[mode] && (jump ? JumpMove(k, jump->value()) : FlowMove(k, mode));
}

z3::expr SmtEncoding::Transition(int k) {
  return Reuse(transitions_, k, [&] {
    StepVars& a = Vars(k);
    StepVars& b = Vars(k + 1);
    z3::expr_vector flow(ctx_);
    flow.push_back(a.flow);
    for (int m = 0; m < automaton_.num_modes(); ++m) {
      flow.push_back(a.mode[m] == b.mode[m]);
      flow.push_back(z3::implies(a.mode[m], Flow(k, m)));
    }
    z3::expr_vector options(ctx_);
    options.push_back(z3::mk_and(flow));
    for (int t = 0; t < automaton_.num_transitions(); ++t) {
      options.push_back(a.jump[t] && Jump(k, t));
    }
    return z3::mk_or(options);
  });
}

std::vector<SmtEncoding::PathStep> SmtEncoding::ReadPath(const z3::model& model, int n) {
  std::vector<PathStep> out;
  for (int k = 0; k <= n; ++k) {
    StepVars& v = Vars(k);
    PathStep s;
    for (int m = 0; m < automaton_.num_modes(); ++m) {
      if (model.eval(v.mode[m], true).is_true()) {
        s.mode = m;
        break;
      }
    }
    for (const auto& x : v.x) s.x.push_back(ValueOf(model, x));
    for (const auto& u : v.u) s.input.push_back(ValueOf(model, u));
    if (k < n) {
      // Which step was taken: a jump whose selector and constraints hold, else the flow.
      s.flow = model.eval(v.flow, true).is_true();
      if (!s.flow) {
        for (int t : outgoing_[s.mode]) {
          if (model.eval(v.jump[t], true).is_true() && model.eval(Jump(k, t), true).is_true()) {
            s.transition = t;
            break;
          }
        }
        if (s.transition < 0) s.flow = true;
      }
      if (s.flow) ReadFlow(model, v, s);
    }
    out.push_back(std::move(s));
  }
  return out;
}

void SmtEncoding::ReadFlow(const z3::model& model, const StepVars& v, PathStep& s) {
  const ModeInfo& info = modes_[s.mode];
  const int ni = static_cast<int>(input_slots_.size());
  s.duration = ValueOf(model, v.d);
  // The inputs the flow reads, with their integrals V_i over the segment.
  std::vector<int> read;
  bool drift = false;
  if (info.flow_class == FlowClass::kConstantRate) {
    for (int i = 0; i < ni; ++i) {
      bool rated = false;
      for (int x : info.moving) rated = rated || info.rate[x][i] != 0.0;
      if (rated) read.push_back(i);
    }
    for (int x : info.moving) drift = drift || info.drift[x] != 0.0;
  } else if (info.flow_class == FlowClass::kSeparable) {
    read.push_back(info.input);
  }
  // Inputs the flow does not read keep the model's value (the one its guards were evaluated
  // with); so do all inputs of a kGeneral flow, whose endpoints the encoding does not follow.
  if (read.empty()) return;
  if (!drift && read.size() == 1) {
    // The path depends only on V: any speed of V's sign follows it. The model's input (what
    // guards reading the input saw), unless it is so slow that the segment would last absurdly
    // long; then full speed in its direction.
    const int i = read[0];
    const double V = ValueOf(model, v.v[i]);
    double& u = s.input[i];
    if (V == 0.0) {
      u = 0.0;  // nothing moves: the input is off for the segment's duration
      return;
    }
    const double full = V > 0 ? input_hi_[i] : input_lo_[i];
    if (!(u * V > 0) || std::abs(u) < 1e-3 * std::abs(full)) u = full;
    s.duration = V / u;
    return;
  }
  // Drift or several inputs: the segment lasts d and each input is held at its mean V_i / d,
  // which reaches the encoded endpoint exactly (x1 = x0 + r0 d + sum_i r_i V_i).
  for (int i : read) s.input[i] = s.duration > 0 ? ValueOf(model, v.v[i]) / s.duration : 0.0;
}

std::vector<std::pair<std::string, double>> SmtEncoding::ReadParameters(const z3::model& model) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [name, e] : uncertain_) out.emplace_back(name, ValueOf(model, e));
  return out;
}

std::vector<std::string> DescribePath(
    const Automaton& automaton, const std::vector<SmtEncoding::PathStep>& path,
    const std::vector<std::pair<std::string, double>>& parameters) {
  std::vector<std::string> lines;
  std::ostringstream values;
  values << "parameters:";
  for (const auto& [name, v] : parameters) values << " " << name << " = " << v;
  lines.push_back(values.str());
  for (std::size_t k = 0; k < path.size(); ++k) {
    const SmtEncoding::PathStep& s = path[k];
    std::ostringstream line;
    line << "s" << k << " " << automaton.modes()[s.mode].name;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      line << " " << automaton.symbols()[automaton.variables()[i].slot].name << "=" << s.x[i];
    }
    for (double u : s.input) line << " u=" << u;
    if (k + 1 < path.size()) {
      if (s.flow) {
        line << ", then a flow of duration " << s.duration;
      } else {
        line << ", then jump " << automaton.transitions()[s.transition].name;
      }
    }
    lines.push_back(line.str());
  }
  return lines;
}

}  // namespace hybrid
