#include "tests/test_utilities/random_hybrid_automata.h"

#include <algorithm>
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
};

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

RandomMode DrawMode(Rng& rng, const Context& ctx, const std::string& name) {
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

RandomSum DrawReset(Rng& rng, const Context& ctx, int v) {
  const RandomHybridAutomaton& a = *ctx.a;
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
    const double hi = RandomChance(rng, 30) ? std::round((lo + Tenths(rng, 0, 20)) * 10) / 10 : lo;
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
  if (RandomChance(rng, 15)) p.within = Tenths(rng, 5, 200);
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
  for (const RandomMode& m : modes) {
    out << "  mode " << m.name << " {";
    for (const auto& [v, rhs] : m.flows) out << " " << v << "' = " << SumText(rhs) << ";";
    for (const RandomRate& r : m.rates) {
      out << " " << r.variable << "'"
          << (options.explicit_rates ? " = " + DecimalText(r.lo) + " + " +
                                           DecimalText(std::round((r.hi - r.lo) * 10) / 10) +
                                           " * " + RateInput(r.variable)
                                     : " in [" + DecimalText(r.lo) + ", " + DecimalText(r.hi) + "]")
          << ";";
    }
    if (!m.invariant.empty()) out << " inv " << ConjunctionText(m.invariant) << ";";
    out << " }\n";
  }
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
  if (scenario) {
    out << "  scenario {\n    until " << DecimalText(scenario->until) << ";\n";
    for (const auto& [input, points] : scenario->steps) {
      out << "    " << input << " = step(";
      for (std::size_t i = 0; i < points.size(); ++i) {
        out << (i ? ", " : "") << DecimalText(points[i].first) << ": "
            << DecimalText(points[i].second);
      }
      out << ");\n";
    }
    out << "  }\n";
  }
  for (int i = 0; i < static_cast<int>(properties.size()); ++i) {
    out << "  " << PropertyText(i) << "\n";
  }
  out << "}\n";
  return out.str();
}

RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng) {
  RandomHybridAutomaton a;
  Context ctx{&a, {}};
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
    a.modes.push_back({name, {}, {}});  // named first: transitions and predicates pick them
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

bool Holds(const RandomPredicate& p, const std::map<std::string, double>& values,
           std::string_view mode, double tolerance) {
  switch (p.kind) {
    case RandomPredicate::Kind::kComparison: {
      const RandomComparison& c = p.comparison;
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
      }
      return false;
    }
    case RandomPredicate::Kind::kInMode:
      return p.mode == mode;
    case RandomPredicate::Kind::kNot:
      return !Holds(p.operands[0], values, mode, -tolerance);
    case RandomPredicate::Kind::kAnd:
      return Holds(p.operands[0], values, mode, tolerance) &&
             Holds(p.operands[1], values, mode, tolerance);
    case RandomPredicate::Kind::kOr:
      return Holds(p.operands[0], values, mode, tolerance) ||
             Holds(p.operands[1], values, mode, tolerance);
  }
  return false;
}

}  // namespace hybrid::testing
