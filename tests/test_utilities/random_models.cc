#include "tests/test_utilities/random_models.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string_view>
#include <utility>

#include "hybrid/automaton/printer.h"

namespace hybrid {

void showValue(const Expression& e, std::ostream& os) { os << e.ToString(); }

void showValue(const Interval& x, std::ostream& os) { os << x.ToString(); }

void showValue(const Automaton& a, std::ostream& os) { os << "\n" << PrintAutomaton(a); }

namespace testing {
namespace {

constexpr int kFullSize = 100;

// Every function below that draws values (operator* on a generator) must run inside
// rc::gen::exec or a property body.

/// A symbol an expression may read.
struct Leaf {
  std::string name;
  int slot;
};

constexpr Op kUnaryOps[] = {Op::kNeg, Op::kSin,  Op::kCos, Op::kTan, Op::kExp,
                            Op::kLog, Op::kSqrt, Op::kAbs, Op::kSign};
constexpr Op kBinaryOps[] = {Op::kAdd, Op::kSub, Op::kMul, Op::kDiv,
                             Op::kPow, Op::kMin, Op::kMax, Op::kAtan2};
constexpr int kNumUnary = static_cast<int>(std::size(kUnaryOps));
constexpr int kNumBinary = static_cast<int>(std::size(kBinaryOps));

/// A uniform integer in [lo, hi), independent of rapidcheck's size (which would otherwise make
/// the first cases of every property trivial); shrinks towards lo.
template <class T>
T Uniform(T lo, T hi) {
  return *rc::gen::resize(kFullSize, rc::gen::inRange<T>(lo, hi));
}

/// True with probability `percent` / 100 (shrinks towards true).
bool Chance(int percent) { return Uniform(0, 100) < percent; }

/// A uniformly chosen element of a non-empty vector.
template <class T>
const T& Pick(const std::vector<T>& items) {
  return items[Uniform<size_t>(0, items.size())];
}

std::vector<Leaf> StandardLeaves() {
  std::vector<Leaf> leaves;
  for (int i = 0; i < static_cast<int>(kSymbolNames.size()); ++i) {
    leaves.push_back({kSymbolNames[i], i});
  }
  return leaves;
}

/// A symbol of `leaves` or a constant; `moderate` constants are at most 10, so that finite
/// differences can resolve the expressions they appear in (sin(1e20 + x) cannot).
Expression RandomLeaf(const std::vector<Leaf>& leaves, bool moderate = false) {
  if (!leaves.empty() && Chance(60)) {
    const Leaf& leaf = Pick(leaves);
    return Expression::Symbol(leaf.name, leaf.slot);
  }
  if (moderate) {
    return Expression::Constant(Chance(50) ? Uniform(0, 11) : Uniform(0, 1001) / 100.0);
  }
  return Expression::Constant(*GenConstant());
}

/// Any operation of the IR, each with the same probability.
Expression RandomExpression(int depth, const std::vector<Leaf>& leaves) {
  if (depth <= 0 || Chance(25)) return RandomLeaf(leaves);
  const int choice = Uniform(0, kNumUnary + kNumBinary);
  if (choice < kNumUnary) {
    return Expression::Unary(kUnaryOps[choice], RandomExpression(depth - 1, leaves));
  }
  Expression lhs = RandomExpression(depth - 1, leaves);
  Expression rhs = RandomExpression(depth - 1, leaves);
  return Expression::Binary(kBinaryOps[choice - kNumUnary], std::move(lhs), std::move(rhs));
}

Expression Num(double v) { return Expression::Constant(v); }

/// Operations smooth on the whole real line (compositions of them are smooth too).
Expression RandomSmoothExpression(int depth, const std::vector<Leaf>& leaves) {
  if (depth <= 0 || Chance(25)) return RandomLeaf(leaves, /*moderate=*/true);
  const auto sub = [&] { return RandomSmoothExpression(depth - 1, leaves); };
  switch (Uniform(0, 14)) {
    case 0:
      return -sub();
    case 1:
      return sub() + sub();
    case 2:
      return sub() - sub();
    case 3:
      return sub() * sub();
    case 4:
      return Expression::Unary(Op::kSin, sub());
    case 5:
      return Expression::Unary(Op::kCos, sub());
    case 6:
      return Expression::Binary(Op::kPow, sub(), Num(2.0));
    case 7:
      return Expression::Binary(Op::kPow, sub(), Num(3.0));
    case 8: {  // exp of a bounded argument
      const Op bounded = Chance(50) ? Op::kSin : Op::kCos;
      return Expression::Unary(Op::kExp, Expression::Unary(bounded, sub()));
    }
    case 9: {  // division by a denominator in [1, 3]
      Expression num = sub();
      return num / (Num(2.0) + Expression::Unary(Op::kCos, sub()));
    }
    case 10:  // sqrt of an argument >= 1
      return Expression::Unary(Op::kSqrt, Num(1.0) + Expression::Binary(Op::kPow, sub(), Num(2.0)));
    case 11:  // log of an argument in [1, 3]
      return Expression::Unary(Op::kLog, Num(2.0) + Expression::Unary(Op::kSin, sub()));
    case 12: {  // atan2 with x in [1, 3], away from the branch cut
      Expression y = sub();
      return Expression::Binary(Op::kAtan2, y, Num(2.0) + Expression::Unary(Op::kCos, sub()));
    }
    default:  // tan of an argument in [-1, 1], away from the poles
      return Expression::Unary(Op::kTan, Expression::Unary(Op::kSin, sub()));
  }
}

// --- automata --------------------------------------------------------------------------------

/// Words of the model language that are not identifiers, and function names (legal as symbol
/// names, avoided anyway).
const std::set<std::string, std::less<>> kReserved = {
    "automaton", "system",     "import", "var",    "discrete", "param",  "input", "mode",
    "inv",       "transition", "guard",  "reset",  "label",    "urgent", "lazy",  "init",
    "scenario",  "until",      "step",   "linear", "property", "always", "never", "reach",
    "within",    "instance",   "share",  "and",    "or",       "not",    "in",    "true",
    "false",     "sin",        "cos",    "tan",    "exp",      "log",    "sqrt",  "abs",
    "sign",      "min",        "max",    "atan2"};

/// Identifiers that look like keywords, functions or numbers but are not (they exercise the
/// parser's word boundaries).
const std::vector<std::string> kTrickyNames = {
    "mode_",  "init1", "in_x",   "inv0", "sinx", "exp_", "not_", "trueish", "e",     "E",
    "e1",     "E10",   "x",      "_",    "_tmp", "orx",  "and1", "within_", "step2", "linear_",
    "guards", "Reset", "labels", "inf",  "nan",  "NaN",  "MODE", "sin_",    "max1",  "theta1_max"};

/// What a name names: each kind is a namespace of its own (a mode may share its name with a
/// variable, a label with a transition, ...).
enum class NameKind { kAutomaton, kSymbol, kMode, kTransition, kLabel, kProperty };

/// Names for everything an automaton declares, unique within their kind.
class NameSource {
 public:
  std::string Fresh(NameKind kind) {
    std::set<std::string>& used = used_[kind];
    std::string name;
    if (!all_.empty() && Chance(10)) {
      name = Pick(all_);  // usually a name of another kind
    } else if (Chance(15)) {
      name = Pick(kTrickyNames);
    } else {
      static constexpr std::string_view kFirst =
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_";
      static constexpr std::string_view kOther =
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_0123456789";
      name.push_back(kFirst[Uniform<size_t>(0, kFirst.size())]);
      const int length = Uniform(0, 8);
      for (int i = 0; i < length; ++i) {
        name.push_back(kOther[Uniform<size_t>(0, kOther.size())]);
      }
    }
    const std::string base = name;
    for (int k = 1; kReserved.count(name) || used.count(name); ++k) {
      name = base + "_" + std::to_string(k);
    }
    used.insert(name);
    all_.push_back(name);
    return name;
  }

 private:
  std::map<NameKind, std::set<std::string>> used_;
  std::vector<std::string> all_;
};

std::string RandomUnit() {
  static const std::vector<std::string> kUnits = {
      "m", "m/s", "m/s^2", "deg", "count", "count/s", "kg.m^2", "1/s", "N*m", "s-1", "rad"};
  return Chance(50) ? "" : Pick(kUnits);
}

/// A finite value of `e` over the parameters of `a` (or nullopt).
std::optional<double> ConstantValue(const Automaton& a, const Expression& e) {
  const double v = e.Evaluate(a.ParameterEnvironment());
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

/// An expression over parameters with a finite value; falls back to a constant.
std::pair<Expression, double> ParameterExpression(const Automaton& a,
                                                  const std::vector<Leaf>& params) {
  Expression e = RandomExpression(Uniform(0, 3), params);
  if (auto v = ConstantValue(a, e)) return {e, *v};
  const double c = *GenConstant();
  const Expression k = Chance(30) ? -Num(c) : Num(c);
  return {k, k.constant()};
}

/// A range [lo, hi] over parameters with lo <= hi; also returns the values of the bounds.
std::pair<Range, std::pair<double, double>> ParameterRange(const Automaton& a,
                                                           const std::vector<Leaf>& params) {
  auto [lo, lo_value] = ParameterExpression(a, params);
  auto [hi, hi_value] = ParameterExpression(a, params);
  if (lo_value > hi_value) {
    std::swap(lo, hi);
    std::swap(lo_value, hi_value);
  }
  return {Range{lo, hi}, {lo_value, hi_value}};
}

/// A range [lo, hi] over `params` containing `v`: each bound an expression over parameters when
/// one on the right side of `v` comes up, otherwise a constant (sometimes `v` itself).
Range RangeAround(const Automaton& a, const std::vector<Leaf>& params, double v) {
  // A constant that parses back to itself: non-negative constants, negated when negative.
  auto constant = [](double c) { return c < 0 ? -Num(-c) : Num(c == 0 ? 0.0 : c); };
  auto [lo, lo_value] = ParameterExpression(a, params);
  if (!(lo_value <= v)) lo = constant(Chance(30) ? v : std::floor(v) - Uniform(0, 4));
  auto [hi, hi_value] = ParameterExpression(a, params);
  if (!(hi_value >= v)) hi = constant(Chance(30) ? v : std::ceil(v) + Uniform(0, 4));
  return Range{lo, hi};
}

Constraint RandomConstraint(const std::vector<Leaf>& leaves) {
  Constraint c;
  const int n = Uniform(0, 4);
  for (int i = 0; i < n; ++i) {
    Expression lhs = RandomExpression(2, leaves);
    const Relation r = *rc::gen::element(Relation::kLess, Relation::kLessEqual, Relation::kGreater,
                                         Relation::kGreaterEqual, Relation::kEqual);
    Expression rhs = RandomExpression(2, leaves);
    c.comparisons.push_back({std::move(lhs), r, std::move(rhs)});
  }
  return c;
}

Predicate RandomPredicate(int depth, const std::vector<Leaf>& leaves,
                          const std::vector<std::string>& modes) {
  if (depth <= 0 || Chance(35)) {
    switch (Uniform(0, 10)) {
      case 0:
        return Predicate::True();
      case 1:
        return Predicate::False();
      case 2:
      case 3:
        return Predicate::InMode(Pick(modes));
      default: {
        Expression lhs = RandomExpression(2, leaves);
        const Relation r =
            *rc::gen::element(Relation::kLess, Relation::kLessEqual, Relation::kGreater,
                              Relation::kGreaterEqual, Relation::kEqual);
        return Predicate::Compare({std::move(lhs), r, RandomExpression(2, leaves)});
      }
    }
  }
  switch (Uniform(0, 3)) {
    case 0:
      return Predicate::Not(RandomPredicate(depth - 1, leaves, modes));
    case 1: {
      Predicate p = RandomPredicate(depth - 1, leaves, modes);
      return Predicate::And(std::move(p), RandomPredicate(depth - 1, leaves, modes));
    }
    default: {
      Predicate p = RandomPredicate(depth - 1, leaves, modes);
      return Predicate::Or(std::move(p), RandomPredicate(depth - 1, leaves, modes));
    }
  }
}

Automaton BuildAutomaton() {
  NameSource names;
  Automaton a(names.Fresh(NameKind::kAutomaton));

  // Declarations in random order (discrete variables necessarily before the modes).
  enum class Decl { kVariable, kDiscrete, kInput, kParameter };
  std::vector<Decl> pending;
  for (int i = Uniform(1, 5); i > 0; --i) pending.push_back(Decl::kVariable);
  for (int i = Uniform(0, 4); i > 0; --i) pending.push_back(Decl::kDiscrete);
  for (int i = Uniform(0, 3); i > 0; --i) pending.push_back(Decl::kInput);
  for (int i = Uniform(0, 5); i > 0; --i) pending.push_back(Decl::kParameter);

  std::vector<Leaf> params;    // parameters
  std::vector<Leaf> readable;  // what properties may read: parameters and state
  std::vector<Leaf> all;       // what flows, guards and resets may read
  std::vector<int> variables;
  std::vector<int> discrete;
  std::vector<std::pair<int, std::pair<double, double>>> inputs;  // slot, bounds
  while (!pending.empty()) {
    const size_t index = Uniform<size_t>(0, pending.size());
    const Decl kind = pending[index];
    pending.erase(pending.begin() + static_cast<std::ptrdiff_t>(index));
    std::string name = names.Fresh(NameKind::kSymbol);
    switch (kind) {
      case Decl::kVariable: {
        std::optional<Range> domain;
        if (Chance(50)) domain = ParameterRange(a, params).first;
        const int slot = a.AddVariable(name, RandomUnit(), domain);
        variables.push_back(slot);
        readable.push_back({name, slot});
        all.push_back({name, slot});
        break;
      }
      case Decl::kDiscrete: {
        const int slot = a.AddDiscreteVariable(name);
        discrete.push_back(slot);
        readable.push_back({name, slot});
        all.push_back({name, slot});
        break;
      }
      case Decl::kInput: {
        auto [bounds, values] = ParameterRange(a, params);
        const int slot = a.AddInput(name, bounds, RandomUnit());
        inputs.emplace_back(slot, values);
        all.push_back({name, slot});
        break;
      }
      case Decl::kParameter: {
        auto [value, nominal] = ParameterExpression(a, params);
        std::optional<Range> range;
        if (Chance(40)) range = RangeAround(a, params, nominal);
        const int slot = a.AddParameter(name, value, RandomUnit(), range);
        params.push_back({name, slot});
        readable.push_back({name, slot});
        all.push_back({name, slot});
        break;
      }
    }
  }

  std::vector<std::string> mode_names;
  for (int i = Uniform(1, 5); i > 0; --i) {
    Mode m;
    m.name = names.Fresh(NameKind::kMode);
    for (int slot : variables) {
      if (Chance(70)) m.flows.emplace_back(slot, RandomExpression(3, all));
    }
    m.invariant = RandomConstraint(all);
    for (int slot : discrete) {
      const int value = Chance(90) ? Uniform(-3, 4) : *rc::gen::element(-1000000, 999999);
      m.discrete_values.emplace_back(slot, value);
    }
    mode_names.push_back(m.name);
    a.AddMode(std::move(m));
  }

  std::vector<std::string> labels = {names.Fresh(NameKind::kLabel), names.Fresh(NameKind::kLabel)};
  for (int i = Uniform(0, 6); i > 0; --i) {
    Transition t;
    t.name = names.Fresh(NameKind::kTransition);
    t.source = ModeId(Uniform(0, a.num_modes()));
    t.target = ModeId(Uniform(0, a.num_modes()));
    t.guard = RandomConstraint(all);
    for (int slot : variables) {
      if (Chance(40)) t.resets.push_back({slot, RandomExpression(2, all)});
    }
    if (Chance(50)) t.label = Pick(labels);
    t.urgency = Chance(50) ? Urgency::kUrgent : Urgency::kLazy;
    a.AddTransition(std::move(t));
  }

  for (int i = Uniform(1, 3); i > 0; --i) {
    InitialState s;
    s.mode = ModeId(Uniform(0, a.num_modes()));
    for (int slot : variables) {
      InitialValue v;
      v.slot = slot;
      v.is_point = Chance(50);
      if (v.is_point) {
        const Expression e = ParameterExpression(a, params).first;
        v.range = {e, e};
      } else {
        v.range = ParameterRange(a, params).first;
      }
      s.values.push_back(std::move(v));
    }
    a.AddInitialState(std::move(s));
  }

  if (Chance(70)) {
    Scenario scenario;
    scenario.until = *rc::gen::element(0.5, 1.0, 2.5, 10.0, 120.0, 530.0, 1e-3);
    for (const auto& [slot, bounds] : inputs) {
      if (!Chance(70)) continue;
      InputSignal signal;
      signal.slot = slot;
      signal.shape = Chance(50) ? InputSignal::Shape::kStep : InputSignal::Shape::kLinear;
      double t = *rc::gen::element(0.0, 0.0, -1.0, 0.5);
      for (int k = Uniform(1, 5); k > 0; --k) {
        const double fraction = *rc::gen::element(0.0, 0.25, 0.5, 0.1, 1.0);
        const double v = bounds.first + fraction * (bounds.second - bounds.first);
        signal.points.emplace_back(t, std::clamp(v, bounds.first, bounds.second));
        t += *rc::gen::element(0.1, 0.25, 1.0, 10.0);
      }
      scenario.inputs.push_back(std::move(signal));
    }
    a.SetScenario(std::move(scenario));
  }

  for (int i = Uniform(0, 4); i > 0; --i) {
    Property p;
    p.name = names.Fresh(NameKind::kProperty);
    p.kind =
        *rc::gen::element(Property::Kind::kAlways, Property::Kind::kNever, Property::Kind::kReach);
    p.predicate = RandomPredicate(3, readable, mode_names);
    if (Chance(40)) p.horizon = *rc::gen::element(1.0, 2.5, 100.0, 0.1);
    a.AddProperty(std::move(p));
  }
  return a;
}

}  // namespace

rc::Gen<double> GenConstant() {
  return rc::gen::exec([]() -> double {
    switch (Uniform(0, 8)) {
      case 0:
      case 1:
      case 2:
        return Uniform(0, 11);
      case 3:
      case 4:
        return Uniform(0, 1000) / 100.0;  // 2.35: not exact in binary
      case 5:
        return Uniform(1, 64) / 8.0;
      case 6:
        return *rc::gen::element(0.1, 0.001, 1.0 / 3.0, 3.141592653589793, 2.5e-8);
      default:
        return *rc::gen::element(1e6, 123456.789, 1e20, 6.02214076e23, 1e-300);
    }
  });
}

rc::Gen<Expression> GenExpression(int depth) {
  return rc::gen::exec([depth] { return RandomExpression(depth, StandardLeaves()); });
}

rc::Gen<Expression> GenSmoothExpression(int depth) {
  return rc::gen::exec([depth] { return RandomSmoothExpression(depth, StandardLeaves()); });
}

rc::Gen<Automaton> GenAutomaton() { return rc::gen::exec(BuildAutomaton); }

rc::Gen<int> GenInt(int lo, int hi) { return rc::gen::resize(kFullSize, rc::gen::inRange(lo, hi)); }

rc::Gen<double> GenReal(double lo, double hi) {
  return rc::gen::map(GenInt(0, (1 << 20) + 1), [lo, hi](int k) {
    const double t = k / static_cast<double>(1 << 20);
    return std::clamp(lo + t * (hi - lo), lo, hi);
  });
}

rc::Gen<Interval> GenInterval(double scale) {
  return rc::gen::exec([scale] {
    const double lo = scale * (Uniform(-1000000, 1000001) / 1e6);
    double width = 0.0;
    switch (Uniform(0, 5)) {
      case 0:
        width = 0.0;
        break;
      case 1:
        width = scale * 1e-9 * Uniform(1, 1000);
        break;
      case 2:
        width = scale * (Uniform(0, 1001) / 1e4);
        break;
      default:
        width = scale * (Uniform(0, 2001) / 1e3);
        break;
    }
    return Interval(lo, lo + width);
  });
}

rc::Gen<double> GenPointIn(const Interval& x) {
  return rc::gen::exec([x] {
    double v = 0.0;
    switch (Uniform(0, 6)) {
      case 0:
        v = x.lo();
        break;
      case 1:
        v = x.hi();
        break;
      case 2:
        v = x.mid();
        break;
      default:
        v = x.lo() + (Uniform(0, 1000001) / 1e6) * (x.hi() - x.lo());
        break;
    }
    return std::clamp(v, x.lo(), x.hi());
  });
}

}  // namespace testing
}  // namespace hybrid
