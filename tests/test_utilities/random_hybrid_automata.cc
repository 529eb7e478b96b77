#include "tests/test_utilities/random_hybrid_automata.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace hybrid::testing {

const std::vector<std::string>& ShortNamePool() {
  static const std::vector<std::string> pool = {
      "d",   "t",    "s",    "u",    "x",    "y",    "z",     "h",   "p",   "k",   "v",
      "w",   "a",    "b",    "c",    "e",    "g",    "n",     "q",   "r",   "m",   "dt",
      "dx",  "ds",   "du",   "int",  "flow", "rate", "time",  "tau", "d0",  "d1",  "x0",
      "x1",  "u0",   "v0",   "t0",   "s0",   "div",  "pow",   "mod", "rem", "ite", "sum",
      "len", "lo",   "hi",   "jump", "tmp",  "val",  "delta", "dur", "eps", "ok",  "mode_",
      "rc",  "var_", "real", "bool", "let",  "out",  "res",   "aux"};
  return pool;
}

int UniformInt(std::mt19937_64& rng, int lo, int hi) {
  const std::uint64_t span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo) + 1;
  return lo + static_cast<int>(rng() % span);  // the modulo bias is irrelevant for tests
}

double UniformReal(std::mt19937_64& rng, double lo, double hi) {
  const double unit = static_cast<double>(rng() >> 11) * 0x1.0p-53;  // [0, 1)
  return lo + (hi - lo) * unit;
}

bool RandomChance(std::mt19937_64& rng, int percent) { return UniformInt(rng, 0, 99) < percent; }

std::string DecimalText(double x) {
  if (x == 0.0) return "0";  // also -0
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}

std::string RateInput(const std::string& variable) { return "zz_rate_" + variable; }

std::string LazyChoiceInput(int transition) {
  return "zz_lazy_choice_" + std::to_string(transition);
}

namespace {

using Rng = std::mt19937_64;

// A multiple of 0.1 in [lo_tenths / 10, hi_tenths / 10]: k / 10.0 is the double nearest to the
// decimal, which is what the parser reads, so the model text and the test agree exactly.
double Tenths(Rng& rng, int lo_tenths, int hi_tenths) {
  return UniformInt(rng, lo_tenths, hi_tenths) / 10.0;
}

// A non-zero multiple of 0.1 of magnitude in [0.1, max_tenths / 10], either sign.
double NonZeroTenths(Rng& rng, int max_tenths) {
  const double m = Tenths(rng, 1, max_tenths);
  return RandomChance(rng, 50) ? m : -m;
}

template <class T>
const T& Pick(Rng& rng, const std::vector<T>& items) {
  return items[static_cast<std::size_t>(UniformInt(rng, 0, static_cast<int>(items.size()) - 1))];
}

// `count` distinct names of the pool.
std::vector<std::string> DistinctNames(Rng& rng, int count) {
  std::vector<std::string> pool = ShortNamePool();
  std::vector<std::string> out;
  for (int i = 0; i < count; ++i) {
    const int j = UniformInt(rng, i, static_cast<int>(pool.size()) - 1);
    std::swap(pool[i], pool[j]);
    out.push_back(pool[i]);
  }
  return out;
}

// An index drawn with the given weights.
int Weighted(Rng& rng, const std::vector<int>& weights) {
  int total = 0;
  for (int w : weights) total += w;
  int r = UniformInt(rng, 0, total - 1);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    if (r < weights[i]) return static_cast<int>(i);
    r -= weights[i];
  }
  return static_cast<int>(weights.size()) - 1;
}

RandomSum Constant(double c) { return {{{c, {}}}}; }
RandomSum Name(const std::string& n, double coef = 1.0) { return {{{coef, {n}}}}; }

RandomRelation AnyRelation(Rng& rng) { return static_cast<RandomRelation>(UniformInt(rng, 0, 3)); }

// What the generator knows while it draws: the names and where the variables start.
struct Context {
  RandomHybridAutomaton* a = nullptr;
  std::vector<double> base;  // per variable: a typical value (its first initial value)
  RandomAutomatonOptions options = {};
};

// Whether the flows are drawn for the flowpipe engine (RandomDynamics::kAffine).
bool Affine(const Context& ctx) { return ctx.options.dynamics == RandomDynamics::kAffine; }

RandomInput DrawInput(Rng& rng, const std::string& name) {
  const double a = Tenths(rng, 1, 20), b = a + Tenths(rng, 1, 20);
  switch (UniformInt(rng, 0, 5)) {
    case 0:
      return {name, -a, 0.0};
    case 1:
      return {name, 0.0, a};
    case 2:
      return {name, 0.0, 0.0};
    case 3:
      return {name, -a, Tenths(rng, 1, 20)};
    case 4:
      return {name, a, b};
    default:
      return {name, -b, -a};
  }
}

RandomParameter DrawParameter(Rng& rng, const std::string& name) {
  RandomParameter p{name, Tenths(rng, -30, 30), std::nullopt};
  if (RandomChance(rng, 75)) {
    const bool degenerate = RandomChance(rng, 10);
    const double below = degenerate ? 0.0 : Tenths(rng, 0, 20);
    const double above = degenerate ? 0.0 : Tenths(rng, 0, 20);
    // Sums of tenths are not always the nearest double of their decimal: round to the grid.
    p.range = {std::round((p.nominal - below) * 10) / 10,
               std::round((p.nominal + above) * 10) / 10};
  }
  return p;
}

// The right-hand side of variable v's flow, or nullopt for no flow.
std::optional<RandomSum> DrawFlow(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
  const int kind = Weighted(rng, {20, 5, 25, 32, 10, 8});
  if (kind == 0) return std::nullopt;
  if (kind == 1) return Constant(0.0);
  RandomSum sum;
  if (kind == 2 || (kind == 3 && a.inputs.empty()) || (kind == 4 && a.parameters.empty())) {
    sum.terms.push_back({NonZeroTenths(rng, 20), {}});
    return sum;
  }
  if (kind == 3) {  // affine in the inputs
    if (RandomChance(rng, 50)) sum.terms.push_back({NonZeroTenths(rng, 10), {}});
    for (const RandomInput& in : a.inputs) {
      if (sum.terms.empty() || RandomChance(rng, 50)) {
        sum.terms.push_back({RandomChance(rng, 40) ? 1.0 : NonZeroTenths(rng, 20), {in.name}});
      }
    }
    return sum;
  }
  if (kind == 4) {  // parameter coefficients: p, c * p, p * u
    const std::string& p = Pick(rng, a.parameters).name;
    if (!a.inputs.empty() && RandomChance(rng, 50)) {
      sum.terms.push_back({1.0, {p, Pick(rng, a.inputs).name}});
    } else {
      sum.terms.push_back({RandomChance(rng, 50) ? 1.0 : NonZeroTenths(rng, 10), {p}});
    }
    if (RandomChance(rng, 30)) sum.terms.push_back({NonZeroTenths(rng, 10), {}});
    return sum;
  }
  // Affine in the state: relaxation towards a constant (the encoder's coarse class).
  sum.terms.push_back({-Tenths(rng, 1, 10), {a.variables[v].name}});
  sum.terms.push_back({Tenths(rng, -50, 50), {}});
  if (!a.inputs.empty() && RandomChance(rng, 50)) {
    sum.terms.push_back({1.0, {Pick(rng, a.inputs).name}});
  }
  return sum;
}

// A comparison of one variable (sometimes a sum of two, or against a parameter) with a constant
// near the variable's typical value, shifted by up to `spread` tenths.
RandomComparison DrawStateComparison(Rng& rng, const Context& ctx, int spread) {
  const RandomHybridAutomaton& a = *ctx.a;
  const int v = UniformInt(rng, 0, static_cast<int>(a.variables.size()) - 1);
  RandomComparison c{Name(a.variables[v].name), AnyRelation(rng), 0.0};
  double centre = ctx.base[v];
  if (a.variables.size() > 1 && RandomChance(rng, 15)) {
    int w = UniformInt(rng, 0, static_cast<int>(a.variables.size()) - 2);
    if (w >= v) ++w;
    const double sign = RandomChance(rng, 50) ? 1.0 : -1.0;
    c.lhs.terms.push_back({sign, {a.variables[w].name}});
    centre += sign * ctx.base[w];
  } else if (!a.parameters.empty() && RandomChance(rng, 12)) {
    const RandomParameter& p = Pick(rng, a.parameters);
    c.lhs.terms.push_back({-1.0, {p.name}});
    centre -= p.nominal;
  }
  c.rhs = std::round(centre * 10 + UniformInt(rng, -spread, spread)) / 10;
  return c;
}

// An invariant atom that the typical value satisfies: x <= base + m or x >= base - m.
RandomComparison DrawInvariantAtom(Rng& rng, const Context& ctx) {
  const RandomHybridAutomaton& a = *ctx.a;
  const int v = UniformInt(rng, 0, static_cast<int>(a.variables.size()) - 1);
  const bool upper = RandomChance(rng, 50);
  const double margin = Tenths(rng, 5, 100);
  const bool strict = RandomChance(rng, 20);
  const RandomRelation rel =
      upper ? (strict ? RandomRelation::kLess : RandomRelation::kLessEqual)
            : (strict ? RandomRelation::kGreater : RandomRelation::kGreaterEqual);
  const double rhs = std::round((ctx.base[v] + (upper ? margin : -margin)) * 10) / 10;
  return {Name(a.variables[v].name), rel, rhs};
}

// ---- flows affine in the state and polynomial ones (RandomDynamics::kAffine) ----

// A multiple of 0.1 nearest to x.
double RoundTenths(double x) { return std::round(x * 10) / 10; }

// An index of a variable other than v (v must not be the only one).
int OtherVariable(Rng& rng, const Context& ctx, int v) {
  int w = UniformInt(rng, 0, static_cast<int>(ctx.a->variables.size()) - 2);
  return w >= v ? w + 1 : w;
}

// A constant term that puts the equilibrium of `rate * x + c` near the typical value of x (a
// stable rate), or a small drift otherwise; nothing when it comes out as 0.
void AddDrift(Rng& rng, const Context& ctx, int v, double rate, RandomSum& sum) {
  const double c =
      rate < 0 ? RoundTenths(-rate * (ctx.base[v] + Tenths(rng, -40, 40))) : Tenths(rng, -20, 20);
  if (c != 0.0) sum.terms.push_back({c, {}});
}

// Input terms `u`, `-0.6*u`, each input with probability `percent`.
void AddInputs(Rng& rng, const Context& ctx, int percent, RandomSum& sum) {
  for (const RandomInput& in : ctx.a->inputs) {
    if (RandomChance(rng, percent)) {
      sum.terms.push_back({RandomChance(rng, 50) ? 1.0 : NonZeroTenths(rng, 10), {in.name}});
    }
  }
}

// x' = A x + c + B u (+ a parameter term): a stable (most often) or unstable diagonal, cross terms
// to the other variables, a drift, inputs; a parameter as a constant or as a coefficient of x
// (`0.1*p*x`: uncertain parameters range over a few units, so the rate stays below 1).
RandomSum AffineStateFlow(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
  const std::string& x = a.variables[v].name;
  RandomSum sum;
  const int diagonal = Weighted(rng, {70, 18, 12});  // stable, unstable, none
  const double rate = diagonal == 0 ? -Tenths(rng, 1, 10) : diagonal == 1 ? Tenths(rng, 1, 2) : 0.0;
  if (rate != 0.0) sum.terms.push_back({rate, {x}});
  for (int w = 0; w < static_cast<int>(a.variables.size()); ++w) {
    if (w != v && RandomChance(rng, 35)) {
      sum.terms.push_back({NonZeroTenths(rng, 3), {a.variables[w].name}});
    }
  }
  if (RandomChance(rng, 80)) AddDrift(rng, ctx, v, rate, sum);
  AddInputs(rng, ctx, 35, sum);
  if (!a.parameters.empty() && RandomChance(rng, 20)) {
    const std::string& p = Pick(rng, a.parameters).name;
    if (RandomChance(rng, 50)) {
      sum.terms.push_back({0.1, {p, x}});
    } else {
      sum.terms.push_back({RandomChance(rng, 50) ? 1.0 : NonZeroTenths(rng, 10), {p}});
    }
  }
  if (sum.terms.empty()) sum.terms.push_back({NonZeroTenths(rng, 20), {}});
  return sum;
}

// A polynomial flow whose runs stay finite: a stable linear part and a drift, and a cubic
// damping `-0.2*x*x*x`, a damping by another variable `-0.1*x*y*y`, or a square of another
// variable `0.2*y*y` (which grows no faster than y does).
RandomSum PolynomialFlow(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
  const std::string& x = a.variables[v].name;
  RandomSum sum;
  const double rate = -Tenths(rng, 1, 10);
  sum.terms.push_back({rate, {x}});
  const int kind = a.variables.size() < 2 ? 0 : UniformInt(rng, 0, 2);
  if (kind == 0) {
    sum.terms.push_back({-Tenths(rng, 1, 3), {x, x, x}});
  } else {
    const std::string& y = a.variables[OtherVariable(rng, ctx, v)].name;
    if (kind == 1) {
      sum.terms.push_back({-Tenths(rng, 1, 3), {x, y, y}});
    } else {
      sum.terms.push_back({NonZeroTenths(rng, 2), {y, y}});
    }
  }
  if (RandomChance(rng, 70)) AddDrift(rng, ctx, v, rate, sum);
  AddInputs(rng, ctx, 25, sum);
  return sum;
}

// An oscillator over variables v, w: `x' = y; y' = -k*(x - c) + mu*y - g*x*x*y (+ u)`, undamped
// in its linear part (mu = 0), damped (mu < 0) or Van der Pol (mu > 0); the cubic term keeps
// every run bounded.
void AddOscillator(Rng& rng, const Context& ctx, int v, int w, RandomMode& m) {
  const RandomHybridAutomaton& a = *ctx.a;
  const std::string& x = a.variables[v].name;
  const std::string& y = a.variables[w].name;
  m.flows.emplace_back(x, RandomSum{{{RandomChance(rng, 70) ? 1.0 : Tenths(rng, 5, 15), {y}}}});
  RandomSum acc;
  const double k = Tenths(rng, 3, 15);
  acc.terms.push_back({-k, {x}});
  const double centre = RoundTenths(k * (ctx.base[v] + Tenths(rng, -20, 20)));
  if (centre != 0.0) acc.terms.push_back({centre, {}});
  const int damping = Weighted(rng, {30, 40, 30});
  if (damping == 1) acc.terms.push_back({-Tenths(rng, 1, 5), {y}});
  if (damping == 2) acc.terms.push_back({Tenths(rng, 1, 5), {y}});
  acc.terms.push_back({-Tenths(rng, 1, 3), {x, x, y}});
  AddInputs(rng, ctx, 30, acc);
  m.flows.emplace_back(y, acc);
}

// A mode of RandomDynamics::kAffine: sometimes an oscillator over two variables, the other
// variables' flows mostly affine in the state, sometimes polynomial, else the shapes of kMixed.
RandomMode DrawAffineMode(Rng& rng, const Context& ctx, const std::string& name) {
  RandomMode m{name, {}, {}, {}};
  const auto& vars = ctx.a->variables;
  const int nv = static_cast<int>(vars.size());
  std::vector<bool> drawn(nv, false);
  if (nv >= 2 && RandomChance(rng, 20)) {
    const int v = UniformInt(rng, 0, nv - 1);
    const int w = OtherVariable(rng, ctx, v);
    AddOscillator(rng, ctx, v, w, m);
    drawn[v] = drawn[w] = true;
  }
  for (int v = 0; v < nv; ++v) {
    if (drawn[v]) continue;
    switch (Weighted(rng, {6, 4, 8, 10, 6, 54, 12})) {
      case 0:  // no flow
        break;
      case 1:
        m.flows.emplace_back(vars[v].name, Constant(0.0));
        break;
      case 2:
        m.flows.emplace_back(vars[v].name, Constant(NonZeroTenths(rng, 20)));
        break;
      case 3: {  // affine in the inputs only
        RandomSum sum;
        if (RandomChance(rng, 50) || ctx.a->inputs.empty()) {
          sum.terms.push_back({NonZeroTenths(rng, 10), {}});
        }
        AddInputs(rng, ctx, 60, sum);
        m.flows.emplace_back(vars[v].name, sum);
        break;
      }
      case 4: {  // a rectangular rate, sometimes a point
        const double lo = Tenths(rng, -20, 20);
        const double width = RandomChance(rng, 15) ? 0.0 : Tenths(rng, 1, 20);
        m.rates.push_back({vars[v].name, lo, RoundTenths(lo + width)});
        break;
      }
      case 5:
        m.flows.emplace_back(vars[v].name, AffineStateFlow(rng, ctx, v));
        break;
      default:
        m.flows.emplace_back(vars[v].name, PolynomialFlow(rng, ctx, v));
        break;
    }
  }
  const int atoms = Weighted(rng, {35, 45, 20});
  for (int i = 0; i < atoms; ++i) m.invariant.push_back(DrawInvariantAtom(rng, ctx));
  return m;
}

// A mode of RandomDynamics::kSeparable (see there): a driver w' = c u and the other variables
// still or K phi(w) u, with positive coefficients (`-0.4*w*u` would read as a negation, not as a
// product with u); the direction comes from c's sign and the input's bounds.
RandomMode DrawSeparableMode(Rng& rng, const Context& ctx, const std::string& name) {
  RandomMode m{name, {}, {}, {}};
  const auto& vars = ctx.a->variables;
  const auto& params = ctx.a->parameters;
  const int nv = static_cast<int>(vars.size());
  const std::string u = Pick(rng, ctx.a->inputs).name;
  const int w = UniformInt(rng, 0, nv - 1);
  const std::string& driver = vars[w].name;
  m.flows.emplace_back(driver, Name(u, NonZeroTenths(rng, 10)));
  for (int v = 0; v < nv; ++v) {
    if (v == w) continue;
    const double k = Tenths(rng, 1, 10);
    switch (UniformInt(rng, 0, 3)) {
      case 0:  // still
        break;
      case 1:
        m.flows.emplace_back(vars[v].name, RandomSum{{{k, {driver, u}}}});
        break;
      case 2:
        m.flows.emplace_back(vars[v].name, RandomSum{{{k / 2, {driver, driver, u}}}});
        break;
      default: {
        std::vector<std::string> factors = {driver, u};
        if (!params.empty()) factors.insert(factors.begin(), Pick(rng, params).name);
        m.flows.emplace_back(vars[v].name, RandomSum{{{k, factors}}});
        break;
      }
    }
  }
  const int atoms = Weighted(rng, {35, 45, 20});
  for (int i = 0; i < atoms; ++i) m.invariant.push_back(DrawInvariantAtom(rng, ctx));
  return m;
}

RandomMode DrawMode(Rng& rng, const Context& ctx, const std::string& name) {
  if (Affine(ctx)) return DrawAffineMode(rng, ctx, name);
  if (ctx.options.dynamics == RandomDynamics::kSeparable && !ctx.a->inputs.empty() &&
      ctx.a->variables.size() >= 2 && RandomChance(rng, 70)) {
    return DrawSeparableMode(rng, ctx, name);
  }
  RandomMode m{name, {}, {}, {}};
  const auto& vars = ctx.a->variables;
  for (int v = 0; v < static_cast<int>(vars.size()); ++v) {
    if (RandomChance(rng, 12)) {  // a rectangular rate, sometimes a point
      const double lo = Tenths(rng, -20, 20);
      const double width = RandomChance(rng, 15) ? 0.0 : Tenths(rng, 1, 20);
      m.rates.push_back({vars[v].name, lo, std::round((lo + width) * 10) / 10});
      continue;
    }
    if (auto f = DrawFlow(rng, ctx, v)) m.flows.emplace_back(vars[v].name, *f);
  }
  const int atoms = Weighted(rng, {35, 45, 20});
  for (int i = 0; i < atoms; ++i) m.invariant.push_back(DrawInvariantAtom(rng, ctx));
  return m;
}

// The comparison that holds exactly where `c` fails, up to its boundary: the guard that leaves a
// mode through that invariant atom (both hold on the boundary, where the flowpipe engine pins a
// crossing to it).
RandomComparison Complement(const RandomComparison& c) {
  RandomComparison out = c;
  switch (c.relation) {
    case RandomRelation::kLess:
    case RandomRelation::kLessEqual:
      out.relation = RandomRelation::kGreaterEqual;
      break;
    case RandomRelation::kGreater:
    case RandomRelation::kGreaterEqual:
      out.relation = RandomRelation::kLessEqual;
      break;
    case RandomRelation::kEqual:
      break;
  }
  return out;
}

// An affine reset of v (RandomDynamics::kAffine): a v + b w + c for another variable w, as the
// impacts of mechanical models mix velocities.
RandomSum AffineReset(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
  RandomSum s = Name(a.variables[v].name, NonZeroTenths(rng, 12));
  if (a.variables.size() > 1)
    s.terms.push_back({NonZeroTenths(rng, 8), {a.variables[OtherVariable(rng, ctx, v)].name}});
  if (RandomChance(rng, 50)) s.terms.push_back({NonZeroTenths(rng, 20), {}});
  return s;
}

RandomSum DrawReset(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
  if (Affine(ctx) && RandomChance(rng, 35)) return AffineReset(rng, ctx, v);
  switch (Weighted(rng, {35, 25, 15, 15, 10})) {
    case 0:
      return Constant(std::round(ctx.base[v] * 10 + UniformInt(rng, -30, 30)) / 10);
    case 1: {
      RandomSum s = Name(a.variables[v].name);
      s.terms.push_back({NonZeroTenths(rng, 30), {}});
      return s;
    }
    case 2:
      return Name(a.variables[v].name, -1.0);
    case 3:
      return Name(Pick(rng, a.variables).name);
    default:
      if (a.parameters.empty()) return Constant(0.0);
      return Name(Pick(rng, a.parameters).name);
  }
}

RandomTransition DrawTransition(Rng& rng, const Context& ctx, const std::string& name) {
  const RandomHybridAutomaton& a = *ctx.a;
  RandomTransition t;
  t.name = name;
  t.source = Pick(rng, a.modes).name;
  t.target = Pick(rng, a.modes).name;
  const int atoms = Weighted(rng, {15, 60, 25});
  for (int i = 0; i < atoms; ++i) {
    if (!a.inputs.empty() && RandomChance(rng, 10)) {
      const RandomInput& in = Pick(rng, a.inputs);
      const double mid = std::round((in.lo + in.hi) * 5) / 10;
      t.guard.push_back({Name(in.name), AnyRelation(rng), mid});
    } else {
      t.guard.push_back(DrawStateComparison(rng, ctx, 60));
    }
  }
  if (Affine(ctx) && RandomChance(rng, 40)) {
    // Leave the source mode where it ends: a guard on the complement of one of its invariant
    // atoms, so that the crossing lies on the invariant's boundary.
    for (const RandomMode& m : a.modes) {
      if (m.name == t.source && !m.invariant.empty())
        t.guard.insert(t.guard.begin(), Complement(Pick(rng, m.invariant)));
    }
  }
  for (int v = 0; v < static_cast<int>(a.variables.size()); ++v) {
    if (RandomChance(rng, 30)) t.resets.emplace_back(a.variables[v].name, DrawReset(rng, ctx, v));
  }
  t.urgency = static_cast<RandomTransition::Urgency>(Weighted(rng, {45, 15, 40}));
  return t;
}

RandomInit DrawInit(Rng& rng, const Context& ctx, bool first) {
  const RandomHybridAutomaton& a = *ctx.a;
  RandomInit init{Pick(rng, a.modes).name, {}};
  for (int v = 0; v < static_cast<int>(a.variables.size()); ++v) {
    const double lo = first ? ctx.base[v] : Tenths(rng, -50, 50);
    // Small boxes for the flowpipe engine (kAffine), which must enclose every run from them.
    const int width = Affine(ctx) ? 5 : 20;
    const double hi =
        RandomChance(rng, 30) ? std::round((lo + Tenths(rng, 0, width)) * 10) / 10 : lo;
    init.values.push_back({a.variables[v].name, {lo, hi}});
  }
  return init;
}

RandomPredicate Atom(RandomComparison c) {
  RandomPredicate p;
  p.kind = RandomPredicate::Kind::kComparison;
  p.comparison = std::move(c);
  return p;
}

RandomPredicate Compound(RandomPredicate::Kind kind, std::vector<RandomPredicate> operands) {
  RandomPredicate p;
  p.kind = kind;
  p.operands = std::move(operands);
  return p;
}

RandomPredicate DrawPredicate(Rng& rng, const Context& ctx) {
  const auto atom = [&] { return Atom(DrawStateComparison(rng, ctx, 80)); };
  const auto in_mode = [&] {
    RandomPredicate p;
    p.kind = RandomPredicate::Kind::kInMode;
    p.mode = Pick(rng, ctx.a->modes).name;
    return p;
  };
  switch (Weighted(rng, {55, 15, 12, 6, 6, 6})) {
    case 0:
      return atom();
    case 1:
      return Compound(RandomPredicate::Kind::kAnd, {atom(), atom()});
    case 2:
      return Compound(RandomPredicate::Kind::kOr, {atom(), atom()});
    case 3:
      return Compound(RandomPredicate::Kind::kNot, {atom()});
    case 4:
      return in_mode();
    default:
      return Compound(
          RandomChance(rng, 50) ? RandomPredicate::Kind::kAnd : RandomPredicate::Kind::kOr,
          {in_mode(), Compound(RandomPredicate::Kind::kNot, {atom()})});
  }
}

RandomProperty DrawProperty(Rng& rng, const Context& ctx, const std::string& name) {
  RandomProperty p;
  p.name = name;
  p.kind = static_cast<RandomProperty::Kind>(Weighted(rng, {45, 15, 40}));
  p.predicate = DrawPredicate(rng, ctx);
  if (RandomChance(rng, Affine(ctx) ? 30 : 15)) p.within = Tenths(rng, 5, 200);
  return p;
}

// ---- printing ----

std::string TermText(const RandomTerm& t, bool leading) {
  std::string out;
  double c = t.coef;
  if (!leading) {
    out = c < 0 ? " - " : " + ";
    c = std::abs(c);
  }
  std::string product;
  for (const std::string& f : t.factors) product += (product.empty() ? "" : "*") + f;
  if (product.empty()) return out + DecimalText(c);
  if (c == 1.0) return out + product;
  if (c == -1.0) return out + "-" + product;
  return out + DecimalText(c) + "*" + product;
}

std::string SumText(const RandomSum& s) {
  if (s.terms.empty()) return "0";
  std::string out;
  for (std::size_t i = 0; i < s.terms.size(); ++i) out += TermText(s.terms[i], i == 0);
  return out;
}

std::string RelationText(RandomRelation r) {
  switch (r) {
    case RandomRelation::kLess:
      return "<";
    case RandomRelation::kLessEqual:
      return "<=";
    case RandomRelation::kGreater:
      return ">";
    case RandomRelation::kGreaterEqual:
      return ">=";
    case RandomRelation::kEqual:
      return "==";
  }
  return "?";
}

std::string ComparisonText(const RandomComparison& c) {
  return SumText(c.lhs) + " " + RelationText(c.relation) + " " + DecimalText(c.rhs);
}

std::string ConjunctionText(const std::vector<RandomComparison>& cs) {
  if (cs.empty()) return "true";
  std::string out;
  for (const RandomComparison& c : cs) out += (out.empty() ? "" : " and ") + ComparisonText(c);
  return out;
}

std::string PredicateText(const RandomPredicate& p) {
  // Compound operands are parenthesised; comparisons and `in MODE` bind tighter than `not`.
  const auto operand = [](const RandomPredicate& q) {
    const bool simple =
        q.kind == RandomPredicate::Kind::kComparison || q.kind == RandomPredicate::Kind::kInMode;
    return simple ? PredicateText(q) : "(" + PredicateText(q) + ")";
  };
  switch (p.kind) {
    case RandomPredicate::Kind::kComparison:
      return ComparisonText(p.comparison);
    case RandomPredicate::Kind::kInMode:
      return "in " + p.mode;
    case RandomPredicate::Kind::kNot:
      return "not " + operand(p.operands[0]);
    case RandomPredicate::Kind::kAnd:
      return operand(p.operands[0]) + " and " + operand(p.operands[1]);
    case RandomPredicate::Kind::kOr:
      return operand(p.operands[0]) + " or " + operand(p.operands[1]);
  }
  return "?";
}

std::string AssignmentsText(const std::vector<std::pair<std::string, RandomSum>>& resets) {
  std::string out;
  for (const auto& [v, s] : resets) out += (out.empty() ? "" : ", ") + v + " := " + SumText(s);
  return out;
}

// `c` with a strict comparison replaced by a non-strict one 0.001 inside it (`x > 1` becomes
// `x >= 1.001`): an urgent transition fires where its guard holds in its closure, so the copy of a
// lazy transition must not fire where the lazy one's strict guard does not hold.
RandomComparison Tightened(RandomComparison c) {
  if (c.relation == RandomRelation::kGreater) {
    c.relation = RandomRelation::kGreaterEqual;
    c.rhs = std::round(c.rhs * 1000 + 1) / 1000;
  } else if (c.relation == RandomRelation::kLess) {
    c.relation = RandomRelation::kLessEqual;
    c.rhs = std::round(c.rhs * 1000 - 1) / 1000;
  }
  return c;
}

// A transition; `extra_guard` non-empty: the urgent copy of a lazy transition (PrintOptions).
std::string TransitionText(const RandomTransition& t, const std::string& name,
                           const std::string& extra_guard) {
  const bool copy = !extra_guard.empty();
  std::vector<RandomComparison> conjuncts = t.guard;
  if (copy) {
    for (RandomComparison& c : conjuncts) c = Tightened(c);
  }
  std::string guard = ConjunctionText(conjuncts);
  if (!extra_guard.empty()) guard = t.guard.empty() ? extra_guard : guard + " and " + extra_guard;
  std::string out = "  transition " + name + ": " + t.source + " -> " + t.target + " {\n";
  out += "    guard " + guard + ";\n";
  if (!t.resets.empty()) out += "    reset " + AssignmentsText(t.resets) + ";\n";
  if (!t.label.empty()) out += "    label " + t.label + ";\n";
  if (copy || t.urgency == RandomTransition::Urgency::kUrgent) {
    out += "    urgent;\n";
  } else if (t.urgency == RandomTransition::Urgency::kLazy) {
    out += "    lazy;\n";
  }
  return out + "  }\n";
}

std::string Interval(double lo, double hi) {
  return "[" + DecimalText(lo) + ", " + DecimalText(hi) + "]";
}

std::string DeclarationText(const RandomHybridAutomaton& a, int kind, int i) {
  if (kind == 0) {
    const RandomVariable& v = a.variables[i];
    return "  var " + v.name +
           (v.domain ? " in " + Interval(v.domain->first, v.domain->second) : "") + ";\n";
  }
  if (kind == 1) {
    const RandomInput& in = a.inputs[i];
    return "  input " + in.name + " in " + Interval(in.lo, in.hi) + ";\n";
  }
  const RandomParameter& p = a.parameters[i];
  if (p.definition) return "  param " + p.name + " = " + SumText(*p.definition) + ";\n";
  return "  param " + p.name + " = " + DecimalText(p.nominal) +
         (p.range ? " in " + Interval(p.range->first, p.range->second) : "") + ";\n";
}

std::string InitText(const RandomInit& init) {
  std::string out = "  init " + init.mode + " {";
  for (const auto& [v, range] : init.values) {
    out += range.first == range.second
               ? " " + v + " = " + DecimalText(range.first) + ";"
               : " " + v + " in " + Interval(range.first, range.second) + ";";
  }
  return out + " }\n";
}

std::string KindText(RandomProperty::Kind k) {
  switch (k) {
    case RandomProperty::Kind::kAlways:
      return "always";
    case RandomProperty::Kind::kNever:
      return "never";
    case RandomProperty::Kind::kReach:
      return "reach";
  }
  return "?";
}

// A mode: `mode NAME (c = 1) { x' = ...; y' in [lo, hi]; inv ...; }` (explicit rates: see
// PrintOptions).
std::string ModeText(const RandomMode& m, bool explicit_rates) {
  std::ostringstream out;
  out << "  mode " << m.name;
  for (std::size_t i = 0; i < m.discrete_values.size(); ++i) {
    out << (i == 0 ? " (" : ", ") << m.discrete_values[i].first << " = "
        << m.discrete_values[i].second << (i + 1 == m.discrete_values.size() ? ")" : "");
  }
  out << " {";
  for (const auto& [v, rhs] : m.flows) out << " " << v << "' = " << SumText(rhs) << ";";
  for (const RandomRate& r : m.rates) {
    out << " " << r.variable << "'"
        << (explicit_rates ? " = " + DecimalText(r.lo) + " + " +
                                 DecimalText(std::round((r.hi - r.lo) * 10) / 10) + " * " +
                                 RateInput(r.variable)
                           : " in [" + DecimalText(r.lo) + ", " + DecimalText(r.hi) + "]")
        << ";";
  }
  if (!m.invariant.empty()) out << " inv " << ConjunctionText(m.invariant) << ";";
  out << " }\n";
  return out.str();
}

std::string ScenarioText(const RandomScenario& scenario) {
  std::ostringstream out;
  out << "  scenario {\n    until " << DecimalText(scenario.until) << ";\n";
  for (const auto& [input, points] : scenario.steps) {
    out << "    " << input << " = step(";
    for (std::size_t i = 0; i < points.size(); ++i) {
      out << (i ? ", " : "") << DecimalText(points[i].first) << ": "
          << DecimalText(points[i].second);
    }
    out << ");\n";
  }
  out << "  }\n";
  return out.str();
}

}  // namespace

std::string RandomHybridAutomaton::PropertyText(int i) const {
  const RandomProperty& p = properties[i];
  return "property " + p.name + ": " + KindText(p.kind) + " " + PredicateText(p.predicate) +
         (p.within ? " within " + DecimalText(*p.within) : "") + ";";
}

std::string RandomHybridAutomaton::Text(const PrintOptions& options) const {
  std::ostringstream out;
  out << "automaton " << name << " {\n";
  for (const auto& [kind, i] : declaration_order) out << DeclarationText(*this, kind, i);
  std::vector<int> lazy;
  for (int i = 0; i < static_cast<int>(transitions.size()); ++i) {
    if (transitions[i].urgency == RandomTransition::Urgency::kLazy) lazy.push_back(i);
  }
  if (options.lazy_choices) {
    for (int i : lazy) out << "  input " << LazyChoiceInput(i) << " in [0, 1];\n";
  }
  std::set<std::string> rated;
  for (const RandomMode& m : modes) {
    for (const RandomRate& r : m.rates) rated.insert(r.variable);
  }
  if (options.explicit_rates) {
    for (const std::string& v : rated) out << "  input " << RateInput(v) << " in [0, 1];\n";
  }
  for (std::size_t i = 0; i < discretes.size(); ++i) {
    out << (i == 0 ? "  discrete " : ", ") << discretes[i]
        << (i + 1 == discretes.size() ? ";\n" : "");
  }
  for (const RandomMode& m : modes) out << ModeText(m, options.explicit_rates);
  for (const RandomTransition& t : transitions) out << TransitionText(t, t.name, "");
  if (options.lazy_choices) {
    for (int i : lazy) {
      out << TransitionText(transitions[i], "zz_lazy_copy_" + std::to_string(i),
                            LazyChoiceInput(i) + " >= 0.5");
    }
  }
  if (options.first_init < 0 || options.first_init >= static_cast<int>(inits.size())) {
    throw std::invalid_argument("RandomHybridAutomaton::Text: no init " +
                                std::to_string(options.first_init));
  }
  out << InitText(inits[options.first_init]);
  for (int i = 0; i < static_cast<int>(inits.size()); ++i) {
    if (i != options.first_init) out << InitText(inits[i]);
  }
  if (scenario) out << ScenarioText(*scenario);
  for (int i = 0; i < static_cast<int>(properties.size()); ++i) {
    out << "  " << PropertyText(i) << "\n";
  }
  out << "}\n";
  return out.str();
}

RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng) {
  return GenerateRandomAutomaton(rng, RandomAutomatonOptions{});
}

RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng,
                                              const RandomAutomatonOptions& options) {
  RandomHybridAutomaton a;
  Context ctx{&a, {}, options};
  a.name = Pick(rng, ShortNamePool());
  const int nv = UniformInt(rng, 1, 3);
  const int ni = Weighted(rng, {15, 45, 30, 10});
  const int np = Weighted(rng, {40, 40, 20});
  const std::vector<std::string> symbols = DistinctNames(rng, nv + ni + np);
  for (int i = 0; i < nv; ++i) {
    RandomVariable v{symbols[i], std::nullopt};
    // Wide enough for every initial value drawn below (metadata for the simulator and prover).
    if (RandomChance(rng, 30)) v.domain = {Tenths(rng, -1000, -50), Tenths(rng, 70, 1000)};
    a.variables.push_back(v);
    ctx.base.push_back(Tenths(rng, -50, 50));
    a.declaration_order.emplace_back(0, i);
  }
  for (int i = 0; i < ni; ++i) {
    a.inputs.push_back(DrawInput(rng, symbols[nv + i]));
    a.declaration_order.emplace_back(1, i);
  }
  for (int i = 0; i < np; ++i) {
    a.parameters.push_back(DrawParameter(rng, symbols[nv + ni + i]));
    a.declaration_order.emplace_back(2, i);
  }
  // Any order, except that the variables keep theirs (irrelevant to the semantics).
  for (int i = static_cast<int>(a.declaration_order.size()) - 1; i > 0; --i) {
    std::swap(a.declaration_order[i], a.declaration_order[UniformInt(rng, 0, i)]);
  }
  const int nm = Weighted(rng, {30, 45, 25}) + 1;
  for (const std::string& name : DistinctNames(rng, nm)) {
    a.modes.push_back({name, {}, {}, {}});  // named first: transitions and predicates pick them
  }
  for (RandomMode& m : a.modes) m = DrawMode(rng, ctx, m.name);
  const int nt = Weighted(rng, {10, 25, 25, 20, 12, 8});
  for (const std::string& name : DistinctNames(rng, nt)) {
    a.transitions.push_back(DrawTransition(rng, ctx, name));
  }
  a.inits.push_back(DrawInit(rng, ctx, true));
  if (RandomChance(rng, 25)) a.inits.push_back(DrawInit(rng, ctx, false));
  const int nprop = UniformInt(rng, 2, 5);
  for (const std::string& name : DistinctNames(rng, nprop)) {
    a.properties.push_back(DrawProperty(rng, ctx, name));
  }
  return a;
}

double EvaluateSum(const RandomSum& sum, const std::map<std::string, double>& values) {
  double total = 0.0;
  for (const RandomTerm& t : sum.terms) {
    double product = t.coef;
    for (const std::string& f : t.factors) product *= values.at(f);
    total += product;
  }
  return total;
}

namespace {

double Magnitude(const RandomComparison& c, const std::map<std::string, double>& values) {
  double m = std::abs(c.rhs);
  for (const RandomTerm& t : c.lhs.terms) {
    double product = t.coef;
    for (const std::string& f : t.factors) product *= values.at(f);
    m += std::abs(product);
  }
  return m;
}

}  // namespace

namespace {

bool ComparisonHolds(const RandomComparison& c, const std::map<std::string, double>& values,
                     double tolerance) {
  const double r = EvaluateSum(c.lhs, values) - c.rhs;
  const double margin = tolerance * (1.0 + Magnitude(c, values));
  switch (c.relation) {
    case RandomRelation::kLess:
      return r < margin;
    case RandomRelation::kLessEqual:
      return r <= margin;
    case RandomRelation::kGreater:
      return r > -margin;
    case RandomRelation::kGreaterEqual:
      return r >= -margin;
    case RandomRelation::kEqual:  // exactly, when asked for a clear answer (tolerance < 0)
      return std::abs(r) <= std::max(margin, 0.0);
  }
  return false;
}

// Holds, with `in_mode(name)` telling whether the state is in mode `name`.
template <class InMode>
bool HoldsWith(const RandomPredicate& p, const std::map<std::string, double>& values,
               const InMode& in_mode, double tolerance) {
  switch (p.kind) {
    case RandomPredicate::Kind::kComparison:
      return ComparisonHolds(p.comparison, values, tolerance);
    case RandomPredicate::Kind::kInMode:
      return in_mode(p.mode);
    case RandomPredicate::Kind::kNot:
      return !HoldsWith(p.operands[0], values, in_mode, -tolerance);
    case RandomPredicate::Kind::kAnd:
      return HoldsWith(p.operands[0], values, in_mode, tolerance) &&
             HoldsWith(p.operands[1], values, in_mode, tolerance);
    case RandomPredicate::Kind::kOr:
      return HoldsWith(p.operands[0], values, in_mode, tolerance) ||
             HoldsWith(p.operands[1], values, in_mode, tolerance);
  }
  return false;
}

}  // namespace

bool Holds(const RandomPredicate& p, const std::map<std::string, double>& values,
           std::string_view mode, double tolerance) {
  return HoldsWith(
      p, values, [&](const std::string& m) { return m == mode; }, tolerance);
}

bool HoldsInModes(const RandomPredicate& p, const std::map<std::string, double>& values,
                  const std::set<std::string>& modes, double tolerance) {
  return HoldsWith(
      p, values, [&](const std::string& m) { return modes.count(m) > 0; }, tolerance);
}

std::map<std::string, double> EvaluateParameters(const RandomHybridAutomaton& a,
                                                 const std::map<std::string, double>& overrides) {
  std::map<std::string, double> values;
  for (const auto& [kind, i] : a.declaration_order) {
    if (kind != 2) continue;
    const RandomParameter& p = a.parameters[i];
    const auto it = overrides.find(p.name);
    values[p.name] = it != overrides.end() ? it->second
                     : p.definition        ? EvaluateSum(*p.definition, values)
                                           : p.nominal;
  }
  return values;
}

// ---- composed systems ----

std::string ConflictName(RandomConflict conflict) {
  switch (conflict) {
    case RandomConflict::kNone:
      return "none";
    case RandomConflict::kInitialValue:
      return "initial value";
    case RandomConflict::kInputBounds:
      return "input bounds";
    case RandomConflict::kDiscrete:
      return "discrete values";
    case RandomConflict::kResets:
      return "synchronised resets";
  }
  return "?";
}

std::string RandomSystem::SystemName(int instance, const std::string& local) const {
  const RandomInstance& in = instances[instance];
  for (const auto& [from, to] : in.binds) {
    if (from == local) return to;
  }
  if (in.name.empty() || std::find(shared.begin(), shared.end(), local) != shared.end()) {
    return local;
  }
  return in.name + "." + local;
}

std::string RandomSystem::ModeName(int instance, const std::string& mode) const {
  const std::string& n = instances[instance].name;
  return n.empty() ? mode : n + "." + mode;
}

std::string RandomSystem::PropertyText(int i) const {
  const RandomProperty& p = properties[i];
  return "property " + p.name + ": " + KindText(p.kind) + " " + PredicateText(p.predicate) +
         (p.within ? " within " + DecimalText(*p.within) : "") + ";";
}

std::string RandomSystem::Text(const std::vector<PrintOptions>& automaton_options) const {
  std::ostringstream out;
  for (std::size_t k = 0; k < automata.size(); ++k) {
    out << automata[k].Text(k < automaton_options.size() ? automaton_options[k] : PrintOptions{})
        << "\n";
  }
  out << "system " << name << " {\n";
  for (std::size_t i = 0; i < shared.size(); ++i) {
    out << (i == 0 ? "  share " : ", ") << shared[i] << (i + 1 == shared.size() ? ";\n" : "");
  }
  for (const RandomInstance& in : instances) {
    out << "  instance " << (in.name.empty() ? "" : in.name + " = ") << automata[in.automaton].name;
    if (in.binds.empty()) {
      out << ";\n";
      continue;
    }
    out << " {";
    for (const auto& [from, to] : in.binds) out << " " << from << " = " << to << ";";
    out << " }\n";
  }
  if (scenario) out << ScenarioText(*scenario);
  for (int i = 0; i < static_cast<int>(properties.size()); ++i) {
    out << "  " << PropertyText(i) << "\n";
  }
  out << "}\n";
  return out.str();
}

namespace {

enum class Sym { kVariable, kInput, kParameter, kDiscrete, kLabel };
constexpr Sym kSymbolKinds[] = {Sym::kVariable, Sym::kInput, Sym::kParameter, Sym::kDiscrete};

// The names of `a` of kind `kind` (labels: the distinct labels of its transitions).
std::vector<std::string> NamesOf(const RandomHybridAutomaton& a, Sym kind) {
  std::vector<std::string> out;
  switch (kind) {
    case Sym::kVariable:
      for (const RandomVariable& v : a.variables) out.push_back(v.name);
      break;
    case Sym::kInput:
      for (const RandomInput& in : a.inputs) out.push_back(in.name);
      break;
    case Sym::kParameter:
      for (const RandomParameter& p : a.parameters) out.push_back(p.name);
      break;
    case Sym::kDiscrete:
      out = a.discretes;
      break;
    case Sym::kLabel:
      for (const RandomTransition& t : a.transitions) {
        if (!t.label.empty() && std::find(out.begin(), out.end(), t.label) == out.end()) {
          out.push_back(t.label);
        }
      }
      break;
  }
  return out;
}

// The kind of symbol `name` of `a`, if it is one (labels are not symbols).
std::optional<Sym> SymbolKindOf(const RandomHybridAutomaton& a, const std::string& name) {
  for (Sym kind : kSymbolKinds) {
    const std::vector<std::string> names = NamesOf(a, kind);
    if (std::find(names.begin(), names.end(), name) != names.end()) return kind;
  }
  return std::nullopt;
}

// Every symbol and label name of `a`.
std::set<std::string> UsedNames(const RandomHybridAutomaton& a) {
  std::set<std::string> out;
  for (Sym kind : {Sym::kVariable, Sym::kInput, Sym::kParameter, Sym::kDiscrete, Sym::kLabel}) {
    for (const std::string& n : NamesOf(a, kind)) out.insert(n);
  }
  return out;
}

// A name of the pool that is not in `used`; "" if there is none.
std::string FreshName(Rng& rng, const std::set<std::string>& used) {
  std::vector<std::string> free;
  for (const std::string& n : ShortNamePool()) {
    if (used.count(n) == 0) free.push_back(n);
  }
  return free.empty() ? std::string() : Pick(rng, free);
}

void RenameInSum(RandomSum& sum, const std::string& from, const std::string& to) {
  for (RandomTerm& t : sum.terms) {
    for (std::string& f : t.factors) {
      if (f == from) f = to;
    }
  }
}

void RenameInComparisons(std::vector<RandomComparison>& cs, const std::string& from,
                         const std::string& to) {
  for (RandomComparison& c : cs) RenameInSum(c.lhs, from, to);
}

void RenameInAssignments(std::vector<std::pair<std::string, RandomSum>>& assignments,
                         const std::string& from, const std::string& to) {
  for (auto& [v, sum] : assignments) {
    if (v == from) v = to;
    RenameInSum(sum, from, to);
  }
}

// Renames symbol `from` of `a` to `to` everywhere `a` uses it.
void RenameSymbolIn(RandomHybridAutomaton& a, const std::string& from, const std::string& to) {
  for (RandomVariable& v : a.variables) v.name = v.name == from ? to : v.name;
  for (RandomInput& in : a.inputs) in.name = in.name == from ? to : in.name;
  for (RandomParameter& p : a.parameters) {
    p.name = p.name == from ? to : p.name;
    if (p.definition) RenameInSum(*p.definition, from, to);
  }
  for (std::string& d : a.discretes) d = d == from ? to : d;
  for (RandomMode& m : a.modes) {
    RenameInAssignments(m.flows, from, to);
    for (RandomRate& r : m.rates) r.variable = r.variable == from ? to : r.variable;
    RenameInComparisons(m.invariant, from, to);
    for (auto& [d, value] : m.discrete_values) d = d == from ? to : d;
  }
  for (RandomTransition& t : a.transitions) {
    RenameInComparisons(t.guard, from, to);
    RenameInAssignments(t.resets, from, to);
  }
  for (RandomInit& init : a.inits) {
    for (auto& [v, range] : init.values) v = v == from ? to : v;
  }
}

void RenameLabelIn(RandomHybridAutomaton& a, const std::string& from, const std::string& to) {
  for (RandomTransition& t : a.transitions) t.label = t.label == from ? to : t.label;
}

// ---- decorations of a system's automata: discrete variables, labels, derived parameters ----

// The first initial value of variable `v` of `a` (its typical value).
double BaseValue(const RandomHybridAutomaton& a, const std::string& v) {
  for (const auto& [name, range] : a.inits.front().values) {
    if (name == v) return range.first;
  }
  return 0.0;
}

// Makes derived parameter `q` (value `value`) read somewhere: a flow, a guard or a reset.
void UseDerivedParameter(Rng& rng, RandomHybridAutomaton& a, const std::string& q, double value) {
  const int use = Weighted(rng, {35, 30, 15, 20});  // flow, guard, reset, only properties
  std::vector<std::pair<std::string, RandomSum>*> flows;
  for (RandomMode& m : a.modes) {
    for (auto& f : m.flows) flows.push_back(&f);
  }
  if (use == 0 && !flows.empty()) {
    Pick(rng, flows)
        ->second.terms.push_back({RandomChance(rng, 50) ? 1.0 : NonZeroTenths(rng, 10), {q}});
    return;
  }
  if (use == 3 || a.transitions.empty()) return;
  RandomTransition& t =
      a.transitions[UniformInt(rng, 0, static_cast<int>(a.transitions.size()) - 1)];
  const RandomVariable& v = Pick(rng, a.variables);
  if (use == 2 && std::none_of(t.resets.begin(), t.resets.end(),
                               [&](const auto& r) { return r.first == v.name; })) {
    t.resets.emplace_back(v.name, Name(q));
    return;
  }
  RandomComparison c{Name(v.name), AnyRelation(rng), 0.0};
  c.lhs.terms.push_back({-1.0, {q}});
  c.rhs = std::round((BaseValue(a, v.name) - value) * 10 + UniformInt(rng, -30, 30)) / 10;
  t.guard.push_back(c);
}

// Adds derived parameters `param q = c * p [+ d];` for some parameters p of `a`.
void AddDerivedParameters(Rng& rng, RandomHybridAutomaton& a) {
  const int n = static_cast<int>(a.parameters.size());
  for (int i = 0; i < n; ++i) {
    if (!RandomChance(rng, 45)) continue;
    const std::string q = FreshName(rng, UsedNames(a));
    if (q.empty()) return;
    RandomSum definition{
        {{RandomChance(rng, 30) ? 1.0 : NonZeroTenths(rng, 20), {a.parameters[i].name}}}};
    if (RandomChance(rng, 50)) definition.terms.push_back({NonZeroTenths(rng, 20), {}});
    const double value = EvaluateSum(definition, EvaluateParameters(a));
    a.parameters.push_back({q, value, std::nullopt, definition});
    a.declaration_order.emplace_back(2, static_cast<int>(a.parameters.size()) - 1);
    UseDerivedParameter(rng, a, q, value);
  }
}

// Adds 0 to 2 discrete variables, each given a value in -1..2 by every mode.
void AddDiscreteVariables(Rng& rng, RandomHybridAutomaton& a) {
  const int n = Weighted(rng, {45, 35, 20});
  for (int i = 0; i < n; ++i) {
    const std::string d = FreshName(rng, UsedNames(a));
    if (d.empty()) return;
    a.discretes.push_back(d);
    for (int m = 0; m < static_cast<int>(a.modes.size()); ++m) {
      a.modes[m].discrete_values.emplace_back(d,
                                              RandomChance(rng, 40) ? m : UniformInt(rng, -1, 2));
    }
  }
}

// Gives some transitions one of 1 or 2 labels (names that are no symbol of `a`).
void AddLabels(Rng& rng, RandomHybridAutomaton& a) {
  std::vector<std::string> labels;
  for (int i = UniformInt(rng, 1, 2); i > 0; --i) {
    const std::string l = FreshName(rng, UsedNames(a));
    if (!l.empty()) labels.push_back(l);
  }
  if (labels.empty()) return;
  for (RandomTransition& t : a.transitions) {
    if (RandomChance(rng, 40)) t.label = Pick(rng, labels);
  }
}

// A random automaton for a system: no properties, decorated; its name not in `taken`.
RandomHybridAutomaton DrawComponent(Rng& rng, const std::set<std::string>& taken,
                                    const RandomAutomatonOptions& options) {
  RandomHybridAutomaton a = GenerateRandomAutomaton(rng, options);
  a.properties.clear();
  if (taken.count(a.name) != 0) a.name = FreshName(rng, taken);
  AddDerivedParameters(rng, a);
  AddDiscreteVariables(rng, a);
  AddLabels(rng, a);
  return a;
}

}  // namespace

namespace {

// ---- connecting instances: shares and binds ----

bool IsShared(const RandomSystem& s, const std::string& n) {
  return std::find(s.shared.begin(), s.shared.end(), n) != s.shared.end();
}

// Whether some instance binds a name `n` of its automaton.
bool SomeInstanceBinds(const RandomSystem& s, const std::string& n) {
  for (const RandomInstance& in : s.instances) {
    for (const auto& [from, to] : in.binds) {
      if (from == n) return true;
    }
  }
  return false;
}

// Every bind target that is the first of a pair in `moves` becomes the second.
void Redirect(RandomSystem& s, const std::vector<std::pair<std::string, std::string>>& moves) {
  for (RandomInstance& in : s.instances) {
    for (auto& [from, to] : in.binds) {
      for (const auto& [before, after] : moves) {
        if (to == before) {
          to = after;
          break;
        }
      }
    }
  }
}

// Renames symbol or label `from` of automaton `ai` to `to`, keeping what the instances of the
// automaton bind (the bind follows the name) and what other instances bind to them.
void RenameInSystem(RandomSystem& s, int ai, const std::string& from, const std::string& to,
                    bool label) {
  std::vector<std::pair<std::string, std::string>> moves;
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    RandomInstance& in = s.instances[k];
    if (in.automaton != ai) continue;
    auto bound = std::find_if(in.binds.begin(), in.binds.end(),
                              [&](const auto& b) { return b.first == from; });
    if (bound != in.binds.end()) {
      bound->first = to;
    } else if (!IsShared(s, from)) {
      moves.emplace_back(s.SystemName(k, from),
                         IsShared(s, to) || in.name.empty() ? to : in.name + "." + to);
    }
  }
  if (label) {
    RenameLabelIn(s.automata[ai], from, to);
  } else {
    RenameSymbolIn(s.automata[ai], from, to);
  }
  Redirect(s, moves);
}

// Names that a new name of automaton `ai` must avoid: its own and the shared ones.
std::set<std::string> Avoid(const RandomSystem& s, int ai) {
  std::set<std::string> used = UsedNames(s.automata[ai]);
  used.insert(s.shared.begin(), s.shared.end());
  return used;
}

// Shares `v`: every instance whose automaton has a name `v` (not bound) follows it.
void AddShare(RandomSystem& s, const std::string& v) {
  if (IsShared(s, v)) return;
  std::vector<std::pair<std::string, std::string>> moves;
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    if (UsedNames(s.automata[s.instances[k].automaton]).count(v) != 0 && s.SystemName(k, v) != v) {
      moves.emplace_back(s.SystemName(k, v), v);
    }
  }
  s.shared.push_back(v);
  Redirect(s, moves);
}

// A name of kind `kind` of automaton `ai`; for labels, one is made if none exists and the
// automaton has transitions. "" if there is none.
std::string PickName(Rng& rng, RandomSystem& s, int ai, Sym kind) {
  RandomHybridAutomaton& a = s.automata[ai];
  std::vector<std::string> names = NamesOf(a, kind);
  if (names.empty() && kind == Sym::kLabel && !a.transitions.empty()) {
    const std::string l = FreshName(rng, Avoid(s, ai));
    if (l.empty()) return "";
    a.transitions[UniformInt(rng, 0, static_cast<int>(a.transitions.size()) - 1)].label = l;
    names.push_back(l);
  }
  return names.empty() ? std::string() : Pick(rng, names);
}

// Shares a name of kind `kind` between instances i < j (renaming j's to i's).
void ConnectByShare(Rng& rng, RandomSystem& s, int i, int j, Sym kind) {
  const int ai = s.instances[i].automaton, aj = s.instances[j].automaton;
  const std::string v = PickName(rng, s, ai, kind);
  if (v.empty() || SomeInstanceBinds(s, v)) return;
  if (ai != aj) {
    const std::string w = PickName(rng, s, aj, kind);
    if (w.empty()) return;
    if (w != v) {
      if (UsedNames(s.automata[aj]).count(v) != 0) {  // v names something else in aj: move it
        const std::string fresh = FreshName(rng, Avoid(s, aj));
        if (fresh.empty()) return;
        RenameInSystem(s, aj, v, fresh, !SymbolKindOf(s.automata[aj], v).has_value());
      }
      RenameInSystem(s, aj, w, v, kind == Sym::kLabel);
    }
  }
  AddShare(s, v);
}

// Binds a name of kind `kind` of instance j to one of instance i < j.
void ConnectByBind(Rng& rng, RandomSystem& s, int i, int j, Sym kind) {
  const int ai = s.instances[i].automaton, aj = s.instances[j].automaton;
  const std::string v = PickName(rng, s, ai, kind);
  const std::string w = PickName(rng, s, aj, kind);
  if (v.empty() || w.empty() || IsShared(s, w)) return;
  RandomInstance& in = s.instances[j];
  for (const auto& [from, to] : in.binds) {
    if (from == w) return;
  }
  const std::string target = s.SystemName(i, v);
  for (const std::string& z : UsedNames(s.automata[aj])) {
    if (z != w && s.SystemName(j, z) == target) return;  // two names would take one
  }
  in.binds.emplace_back(w, target);
}

void DrawConnections(Rng& rng, RandomSystem& s, bool independent) {
  const Sym kinds[] = {Sym::kVariable, Sym::kInput, Sym::kLabel, Sym::kParameter, Sym::kDiscrete};
  for (int j = 1; j < static_cast<int>(s.instances.size()); ++j) {
    for (int links = Weighted(rng, {15, 35, 30, 20}); links > 0; --links) {
      const int i = UniformInt(rng, 0, j - 1);
      const Sym kind = independent ? kinds[1 + 2 * Weighted(rng, {60, 40})]  // input, parameter
                                   : kinds[Weighted(rng, {40, 20, 30, 6, 4})];
      if (RandomChance(rng, 45)) {
        ConnectByShare(rng, s, i, j, kind);
      } else {
        ConnectByBind(rng, s, i, j, kind);
      }
    }
  }
}

// ---- making the declarations of connected names agree ----

struct Declarer {
  int instance;
  std::string local;
  Sym kind;
};

// The declarers of every system symbol (labels aside), in instance order.
std::map<std::string, std::vector<Declarer>> Declarers(const RandomSystem& s) {
  std::map<std::string, std::vector<Declarer>> out;
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    for (Sym kind : kSymbolKinds) {
      for (const std::string& n : NamesOf(s.automata[s.instances[k].automaton], kind)) {
        out[s.SystemName(k, n)].push_back({k, n, kind});
      }
    }
  }
  return out;
}

// Resolves one system name declared with two kinds (a share or the unqualified instance met a
// name of another kind): renames the later one, or drops its bind. False if there is none.
bool FixOneKindClash(Rng& rng, RandomSystem& s) {
  for (const auto& [name, list] : Declarers(s)) {
    for (const Declarer& d : list) {
      if (d.kind == list.front().kind) continue;
      RandomInstance& in = s.instances[d.instance];
      auto bound = std::find_if(in.binds.begin(), in.binds.end(),
                                [&](const auto& b) { return b.first == d.local; });
      if (bound != in.binds.end()) {
        in.binds.erase(bound);
        return true;
      }
      const std::string fresh = FreshName(rng, Avoid(s, in.automaton));
      if (fresh.empty()) return false;
      RenameInSystem(s, in.automaton, d.local, fresh, false);
      return true;
    }
  }
  return false;
}

// Whether bind (from, to) of instance k is one the IR accepts and the generator means: `from`
// a name of its automaton, not shared, `to` a name of the same kind of an earlier instance that
// no other name of the automaton takes.
bool BindIsValid(const RandomSystem& s, int k, const std::string& from, const std::string& to) {
  const RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
  const std::set<std::string> used = UsedNames(a);
  if (used.count(from) == 0 || IsShared(s, from)) return false;
  const std::optional<Sym> kind = SymbolKindOf(a, from);
  bool found = false;
  for (int e = 0; e < k && !found; ++e) {
    const RandomHybridAutomaton& other = s.automata[s.instances[e].automaton];
    for (const std::string& z : NamesOf(other, kind.value_or(Sym::kLabel))) {
      found = found || s.SystemName(e, z) == to;
    }
  }
  if (!found) return false;
  for (const std::string& z : used) {
    if (z != from && s.SystemName(k, z) == to) return false;
  }
  return true;
}

// Drops binds until every one is valid (BindIsValid).
void DropInvalidBinds(RandomSystem& s) {
  for (bool dropped = true; dropped;) {
    dropped = false;
    for (int k = 0; k < static_cast<int>(s.instances.size()) && !dropped; ++k) {
      auto& binds = s.instances[k].binds;
      for (auto it = binds.begin(); it != binds.end(); ++it) {
        if (!BindIsValid(s, k, it->first, it->second)) {
          binds.erase(it);
          dropped = true;
          break;
        }
      }
    }
  }
}

}  // namespace

namespace {

// One symbol of one automaton.
struct Local {
  int automaton;
  std::string local;
  Sym kind;
  bool operator==(const Local& o) const { return automaton == o.automaton && local == o.local; }
};

// Groups of automaton symbols that must agree: those that name one system symbol declared by
// two or more instances (the same symbol of two instances of one automaton too), closed
// transitively, each in the order of first declaration.
std::vector<std::vector<Local>> AgreementGroups(const RandomSystem& s) {
  std::vector<std::vector<Local>> groups;
  for (const auto& [name, list] : Declarers(s)) {
    if (list.size() < 2) continue;
    std::vector<Local> merged;
    for (const Declarer& d : list)
      merged.push_back({s.instances[d.instance].automaton, d.local, d.kind});
    for (auto g = groups.begin(); g != groups.end();) {
      const bool meets = std::any_of(g->begin(), g->end(), [&](const Local& x) {
        return std::find(merged.begin(), merged.end(), x) != merged.end();
      });
      if (!meets) {
        ++g;
        continue;
      }
      merged.insert(merged.begin(), g->begin(), g->end());
      g = groups.erase(g);
    }
    std::vector<Local> unique;
    for (const Local& x : merged) {
      if (std::find(unique.begin(), unique.end(), x) == unique.end()) unique.push_back(x);
    }
    groups.push_back(unique);
  }
  return groups;
}

// Gives every symbol of `g` the declaration of its first: one initial value (in every init
// declaration), one pair of input bounds, one parameter value and range (no longer derived),
// one discrete value in every mode.
void MakeGroupAgree(RandomSystem& s, const std::vector<Local>& g) {
  const RandomHybridAutomaton first = s.automata[g.front().automaton];
  const std::string& name = g.front().local;
  for (const Local& x : g) {
    RandomHybridAutomaton& a = s.automata[x.automaton];
    if (x.kind == Sym::kVariable) {
      std::pair<double, double> range{0.0, 0.0};
      for (const auto& [v, r] : first.inits.front().values) range = v == name ? r : range;
      for (RandomInit& init : a.inits) {
        for (auto& [v, r] : init.values) r = v == x.local ? range : r;
      }
    } else if (x.kind == Sym::kInput) {
      const RandomInput& in = *std::find_if(first.inputs.begin(), first.inputs.end(),
                                            [&](const RandomInput& i) { return i.name == name; });
      for (RandomInput& i : a.inputs) {
        if (i.name == x.local) i = {x.local, in.lo, in.hi};
      }
    } else if (x.kind == Sym::kParameter) {  // also one automaton twice: `2 * A.p`, `2 * B.p`
      const double value = EvaluateParameters(first).at(name);
      const RandomParameter& p = *std::find_if(first.parameters.begin(), first.parameters.end(),
                                               [&](const auto& q) { return q.name == name; });
      for (RandomParameter& q : a.parameters) {
        if (q.name == x.local) q = {x.local, value, p.range, std::nullopt};
      }
    } else if (x.kind == Sym::kDiscrete) {
      int value = 0;
      for (const auto& [d, v] : first.modes.front().discrete_values) value = d == name ? v : value;
      for (RandomMode& m : a.modes) {
        for (auto& [d, v] : m.discrete_values) v = d == x.local ? value : v;
      }
    }
  }
}

bool GivesFlow(const RandomHybridAutomaton& a, const std::string& v) {
  for (const RandomMode& m : a.modes) {
    for (const auto& [name, rhs] : m.flows) {
      if (name == v) return true;
    }
    for (const RandomRate& r : m.rates) {
      if (r.variable == v) return true;
    }
  }
  return false;
}

void RemoveFlows(RandomHybridAutomaton& a, const std::string& v) {
  for (RandomMode& m : a.modes) {
    m.flows.erase(
        std::remove_if(m.flows.begin(), m.flows.end(), [&](const auto& f) { return f.first == v; }),
        m.flows.end());
    m.rates.erase(std::remove_if(m.rates.begin(), m.rates.end(),
                                 [&](const RandomRate& r) { return r.variable == v; }),
                  m.rates.end());
  }
}

// A variable shared by several instances gets a flow from the first that gives it one only.
void KeepOneFlowOwner(RandomSystem& s) {
  for (const auto& [name, list] : Declarers(s)) {
    if (list.size() < 2 || list.front().kind != Sym::kVariable) continue;
    bool owned = false;
    for (const Declarer& d : list) {
      RandomHybridAutomaton& a = s.automata[s.instances[d.instance].automaton];
      if (!GivesFlow(a, d.local)) continue;
      if (owned) RemoveFlows(a, d.local);
      owned = true;
    }
  }
}

// Removes one reset of a transition that synchronises (one system label) with a transition of
// an earlier instance resetting the same system variable. False if there is none.
bool DropOneSynchronisedReset(RandomSystem& s) {
  for (int k2 = 1; k2 < static_cast<int>(s.instances.size()); ++k2) {
    for (RandomTransition& t2 : s.automata[s.instances[k2].automaton].transitions) {
      if (t2.label.empty() || t2.resets.empty()) continue;
      const std::string label = s.SystemName(k2, t2.label);
      for (int k1 = 0; k1 < k2; ++k1) {
        for (const RandomTransition& t1 : s.automata[s.instances[k1].automaton].transitions) {
          if (t1.label.empty() || s.SystemName(k1, t1.label) != label) continue;
          for (auto r2 = t2.resets.begin(); r2 != t2.resets.end(); ++r2) {
            for (const auto& r1 : t1.resets) {
              if (s.SystemName(k2, r2->first) != s.SystemName(k1, r1.first)) continue;
              t2.resets.erase(r2);
              return true;
            }
          }
        }
      }
    }
  }
  return false;
}

// Makes the system one the IR accepts: one kind per system name, valid binds, agreeing
// declarations, one flow owner, no variable reset twice by one synchronised step.
void MakeConsistent(Rng& rng, RandomSystem& s) {
  for (int i = 0; i < 100 && FixOneKindClash(rng, s); ++i) {
  }
  DropInvalidBinds(s);
  for (const std::vector<Local>& g : AgreementGroups(s)) MakeGroupAgree(s, g);
  for (RandomHybridAutomaton& a : s.automata) {  // derived parameters follow their parameters
    const std::map<std::string, double> values = EvaluateParameters(a);
    for (RandomParameter& p : a.parameters)
      p.nominal = p.definition ? values.at(p.name) : p.nominal;
  }
  KeepOneFlowOwner(s);
  while (DropOneSynchronisedReset(s)) {
  }
}

}  // namespace

namespace {

// ---- conflicts on purpose ----

// Adds to `a` a variable `n` without flow starting at `start` in every init declaration.
void AddVariable(RandomHybridAutomaton& a, const std::string& n, double start) {
  a.variables.push_back({n, std::nullopt});
  a.declaration_order.emplace_back(0, static_cast<int>(a.variables.size()) - 1);
  for (RandomInit& init : a.inits) init.values.push_back({n, {start, start}});
}

// Adds to `a` a lazy self-loop labelled `label` that resets `v` to 1.
void AddResettingLoop(Rng& rng, RandomHybridAutomaton& a, const std::string& label,
                      const std::string& v) {
  std::set<std::string> names;
  for (const RandomTransition& t : a.transitions) names.insert(t.name);
  RandomTransition t;
  t.name = FreshName(rng, names);
  t.source = t.target = a.modes.front().name;
  t.resets.emplace_back(v, Constant(1.0));
  t.urgency = RandomTransition::Urgency::kLazy;
  t.label = label;
  a.transitions.push_back(t);
}

// Adds symbols of `kind`'s conflict: `n1` to `ai` and `n2` to `aj` (label `l1`, `l2` for
// kResets), declared so that they disagree once they are one system name.
void AddConflictingSymbols(Rng& rng, RandomSystem& s, RandomConflict kind, int ai, int aj,
                           const std::array<std::string, 4>& names) {
  RandomHybridAutomaton& a = s.automata[ai];
  RandomHybridAutomaton& b = s.automata[aj];
  switch (kind) {
    case RandomConflict::kInitialValue:
      AddVariable(a, names[0], 0.0);
      AddVariable(b, names[1], Tenths(rng, 1, 20));
      break;
    case RandomConflict::kInputBounds:
      a.inputs.push_back({names[0], 0.0, 1.0});
      a.declaration_order.emplace_back(1, static_cast<int>(a.inputs.size()) - 1);
      b.inputs.push_back({names[1], 0.0, Tenths(rng, 11, 30)});
      b.declaration_order.emplace_back(1, static_cast<int>(b.inputs.size()) - 1);
      break;
    case RandomConflict::kDiscrete:
      a.discretes.push_back(names[0]);
      for (RandomMode& m : a.modes) m.discrete_values.emplace_back(names[0], 0);
      b.discretes.push_back(names[1]);
      for (RandomMode& m : b.modes) m.discrete_values.emplace_back(names[1], UniformInt(rng, 1, 3));
      break;
    case RandomConflict::kResets:
      AddVariable(a, names[0], 0.0);
      AddVariable(b, names[1], 0.0);
      AddResettingLoop(rng, a, names[2], names[0]);
      AddResettingLoop(rng, b, names[3], names[1]);
      break;
    case RandomConflict::kNone:
      break;
  }
}

// Gives `s` a conflict between two instances of different automata (connected by a share or by
// binds), which the IR must refuse at load. False if `s` has no such pair of instances.
bool InjectConflict(Rng& rng, RandomSystem& s) {
  std::vector<std::pair<int, int>> pairs;
  for (int j = 1; j < static_cast<int>(s.instances.size()); ++j) {
    for (int i = 0; i < j; ++i) {
      if (s.instances[i].automaton != s.instances[j].automaton) pairs.emplace_back(i, j);
    }
  }
  if (pairs.empty()) return false;
  const auto [i, j] = Pick(rng, pairs);
  const int ai = s.instances[i].automaton, aj = s.instances[j].automaton;
  const auto kind = static_cast<RandomConflict>(UniformInt(rng, 1, 4));
  const bool share = RandomChance(rng, 50);
  std::set<std::string> avoid(s.shared.begin(), s.shared.end());
  for (const RandomHybridAutomaton& a : s.automata) {
    const std::set<std::string> used = UsedNames(a);
    avoid.insert(used.begin(), used.end());
  }
  std::array<std::string, 4> names;  // n1, n2, l1, l2: one name each when shared
  for (std::string& n : names) {
    n = FreshName(rng, avoid);
    if (n.empty()) return false;
    avoid.insert(n);
  }
  if (share) names[1] = names[0], names[3] = names[2];
  AddConflictingSymbols(rng, s, kind, ai, aj, names);
  if (share) {
    AddShare(s, names[0]);
    if (kind == RandomConflict::kResets) AddShare(s, names[2]);
  } else {
    s.instances[j].binds.emplace_back(names[1], s.SystemName(i, names[0]));
    if (kind == RandomConflict::kResets) {
      s.instances[j].binds.emplace_back(names[3], s.SystemName(i, names[2]));
    }
  }
  s.conflict = kind;
  s.conflict_instances = {i, j};
  s.conflict_via = share ? "share" : "bind";
  s.conflict_message = kind == RandomConflict::kInitialValue  ? "starts at"
                       : kind == RandomConflict::kInputBounds ? "shared input"
                       : kind == RandomConflict::kDiscrete    ? "shared discrete variable"
                                                              : "both reset";
  return true;
}

// ---- properties over system names ----

struct SystemContext {
  std::vector<std::pair<std::string, double>> variables;            // system name, typical value
  std::vector<std::pair<std::string, double>> parameters;           // system name, nominal value
  std::vector<std::pair<std::string, std::vector<int>>> discretes;  // system name, values
  std::vector<std::string> modes;                                   // system names
};

SystemContext ContextOf(const RandomSystem& s) {
  SystemContext ctx;
  std::set<std::string> seen;
  for (const auto& [name, value] : SystemParameterValues(s))
    ctx.parameters.emplace_back(name, value);
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    for (const RandomVariable& v : a.variables) {
      if (seen.insert(s.SystemName(k, v.name)).second) {
        ctx.variables.emplace_back(s.SystemName(k, v.name), BaseValue(a, v.name));
      }
    }
    for (const std::string& d : a.discretes) {
      if (!seen.insert(s.SystemName(k, d)).second) continue;
      std::vector<int> values;
      for (const RandomMode& m : a.modes) {
        for (const auto& [name, value] : m.discrete_values) {
          if (name == d) values.push_back(value);
        }
      }
      ctx.discretes.emplace_back(s.SystemName(k, d), values);
    }
    for (const RandomMode& m : a.modes) ctx.modes.push_back(s.ModeName(k, m.name));
  }
  return ctx;
}

// A comparison of a variable (sometimes plus or minus another, or minus a parameter) with a
// constant near its typical value.
RandomComparison DrawSystemComparison(Rng& rng, const SystemContext& ctx) {
  const auto& [v, base] = Pick(rng, ctx.variables);
  RandomComparison c{Name(v), AnyRelation(rng), 0.0};
  double centre = base;
  if (ctx.variables.size() > 1 && RandomChance(rng, 20)) {
    const auto& [w, other] = Pick(rng, ctx.variables);
    const double sign = RandomChance(rng, 50) ? 1.0 : -1.0;
    c.lhs.terms.push_back({sign, {w}});
    centre += sign * other;
  } else if (!ctx.parameters.empty() && RandomChance(rng, 15)) {
    const auto& [p, value] = Pick(rng, ctx.parameters);
    c.lhs.terms.push_back({-1.0, {p}});
    centre -= value;
  }
  c.rhs = std::round(centre * 10 + UniformInt(rng, -80, 80)) / 10;
  return c;
}

RandomPredicate DrawSystemAtom(Rng& rng, const SystemContext& ctx) {
  if (ctx.discretes.empty() || RandomChance(rng, 70)) {
    return Atom(DrawSystemComparison(rng, ctx));
  }
  const auto& [d, values] = Pick(rng, ctx.discretes);
  const int k = Pick(rng, values) + (RandomChance(rng, 15) ? 1 : 0);
  const RandomRelation rel = RandomChance(rng, 60)   ? RandomRelation::kEqual
                             : RandomChance(rng, 50) ? RandomRelation::kLessEqual
                                                     : RandomRelation::kGreaterEqual;
  return Atom({Name(d), rel, static_cast<double>(k)});
}

RandomPredicate DrawSystemPredicate(Rng& rng, const SystemContext& ctx) {
  using K = RandomPredicate::Kind;
  const auto atom = [&] { return DrawSystemAtom(rng, ctx); };
  const auto in_mode = [&] {
    RandomPredicate p;
    p.kind = K::kInMode;
    p.mode = Pick(rng, ctx.modes);
    return p;
  };
  switch (Weighted(rng, {45, 14, 12, 6, 9, 6, 8})) {
    case 0:
      return atom();
    case 1:
      return Compound(K::kAnd, {atom(), atom()});
    case 2:
      return Compound(K::kOr, {atom(), atom()});
    case 3:
      return Compound(K::kNot, {atom()});
    case 4:
      return in_mode();
    case 5:
      return Compound(RandomChance(rng, 50) ? K::kAnd : K::kOr,
                      {in_mode(), Compound(K::kNot, {atom()})});
    default:  // modes of two instances (or two modes of one)
      return Compound(RandomChance(rng, 70) ? K::kAnd : K::kOr, {in_mode(), in_mode()});
  }
}

void DrawSystemProperties(Rng& rng, RandomSystem& s) {
  const SystemContext ctx = ContextOf(s);
  for (const std::string& name : DistinctNames(rng, UniformInt(rng, 2, 5))) {
    RandomProperty p;
    p.name = name;
    p.kind = static_cast<RandomProperty::Kind>(Weighted(rng, {45, 15, 40}));
    p.predicate = DrawSystemPredicate(rng, ctx);
    if (RandomChance(rng, 15)) p.within = Tenths(rng, 5, 200);
    s.properties.push_back(p);
  }
}

// Draws 1 to 3 instances (sometimes two of one automaton, sometimes one unqualified) and their
// automata.
void DrawInstances(Rng& rng, RandomSystem& s, const RandomSystemOptions& system_options) {
  const RandomAutomatonOptions& options = system_options.automata;
  const int drawn = Weighted(rng, {25, 45, 30}) + 1;
  const int n = system_options.independent_instances ? std::max(drawn, 2) : drawn;
  const std::vector<std::string> names = DistinctNames(rng, n);
  const int unqualified = RandomChance(rng, 15) ? UniformInt(rng, 0, n - 1) : -1;
  for (int k = 0; k < n; ++k) {
    RandomInstance in{k == unqualified ? "" : names[k], 0, {}};
    if (k > 0 && RandomChance(rng, 20)) {
      in.automaton = UniformInt(rng, 0, static_cast<int>(s.automata.size()) - 1);
    } else {
      std::set<std::string> taken;
      for (const RandomHybridAutomaton& a : s.automata) taken.insert(a.name);
      s.automata.push_back(DrawComponent(rng, taken, options));
      in.automaton = static_cast<int>(s.automata.size()) - 1;
    }
    s.instances.push_back(in);
  }
}

}  // namespace

RandomSystem GenerateRandomSystem(std::mt19937_64& rng, const RandomSystemOptions& options) {
  RandomSystem s;
  s.name = Pick(rng, ShortNamePool());
  DrawInstances(rng, s, options);
  DrawConnections(rng, s, options.independent_instances);
  MakeConsistent(rng, s);
  DrawSystemProperties(rng, s);
  if (RandomChance(rng, options.conflict_percent)) InjectConflict(rng, s);
  return s;
}

std::map<std::string, double> SystemParameterValues(
    const RandomSystem& s, const std::map<std::string, double>& overrides) {
  std::map<std::string, double> out;
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    std::map<std::string, double> local;
    for (const RandomParameter& p : a.parameters) {
      const auto it = overrides.find(s.SystemName(k, p.name));
      if (it != overrides.end()) local[p.name] = it->second;
    }
    for (const auto& [name, value] : EvaluateParameters(a, local)) {
      out.emplace(s.SystemName(k, name), value);  // the first instance's for a shared one
    }
  }
  return out;
}

void AddDiscreteValues(const RandomSystem& s, const std::vector<int>& modes,
                       std::map<std::string, double>& values) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const RandomMode& m = s.automata[s.instances[k].automaton].modes.at(modes.at(k));
    for (const auto& [d, v] : m.discrete_values) values[s.SystemName(k, d)] = v;
  }
}

std::set<std::string> ModeNames(const RandomSystem& s, const std::vector<int>& modes) {
  std::set<std::string> out;
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    out.insert(s.ModeName(k, s.automata[s.instances[k].automaton].modes.at(modes.at(k)).name));
  }
  return out;
}

bool InsideInvariants(const RandomSystem& s, const std::vector<int>& modes,
                      const std::map<std::string, double>& values, double tolerance) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    const RandomMode& m = a.modes.at(modes.at(k));
    if (m.invariant.empty()) continue;
    std::map<std::string, double> local;
    for (Sym kind : kSymbolKinds) {
      for (const std::string& n : NamesOf(a, kind)) {
        const auto it = values.find(s.SystemName(k, n));
        if (it != values.end()) local[n] = it->second;
      }
    }
    for (const RandomComparison& c : m.invariant) {
      if (!ComparisonHolds(c, local, tolerance)) return false;
    }
  }
  return true;
}

}  // namespace hybrid::testing
