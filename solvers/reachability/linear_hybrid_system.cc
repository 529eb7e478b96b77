#include "solvers/reachability/linear_hybrid_system.h"

#include <algorithm>
#include <cmath>

#include "automaton/rectangular_rate.h"
#include "hybrid/automaton/interval.h"
#include "hybrid/checking/trace.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;
using Disjunction = std::vector<std::vector<LinearConstraint>>;

constexpr size_t kMaxDisjuncts = 256;

[[noreturn]] void NotLinear(const std::string& what) {
  throw LinearHybridSystem::NotLinearError(what);
}

// Whether constant comparison b REL 0 holds.
bool ConstantHolds(const LinearConstraint& c) {
  switch (c.kind) {
    case Kind::kLess:
      return c.b < 0;
    case Kind::kLessEqual:
      return c.b <= 0;
    case Kind::kEqual:
      break;
  }
  return c.b == 0;
}

bool IsConstant(const LinearConstraint& c) {
  return std::all_of(c.a.begin(), c.a.end(), [](double v) { return v == 0.0; });
}

LinearConstraint Negated(const LinearConstraint& c, Kind kind) {
  LinearConstraint n = c;
  for (double& v : n.a) v = -v;
  n.b = -n.b;
  n.kind = kind;
  return n;
}

// The union of the pairwise conjunctions of a and b.
Disjunction Cross(const Disjunction& a, const Disjunction& b) {
  Disjunction out;
  for (const auto& x : a) {
    for (const auto& y : b) {
      if (out.size() >= kMaxDisjuncts) NotLinear("a property with too many cases (over 256)");
      auto both = x;
      both.insert(both.end(), y.begin(), y.end());
      out.push_back(std::move(both));
    }
  }
  return out;
}

// Every comparison of `comparisons` in its closure (Comparison::Closure).
std::vector<Comparison> Closed(const std::vector<Comparison>& comparisons) {
  std::vector<Comparison> out;
  out.reserve(comparisons.size());
  for (const Comparison& c : comparisons) out.push_back(c.Closure());
  return out;
}

}  // namespace

// Expressions over System slots turned into affine maps over the dimensions.
struct LinearHybridSystem::Forms {
  const System& system;
  std::vector<int> dim_of_slot;    // -1 for slots that are not dimensions
  std::vector<int> input_of_slot;  // -1 for slots that are not inputs
  std::vector<double> nominal;     // parameter values by System slot
  std::vector<Interval> box;       // parameter ranges, input bounds, by System slot
  int dims = 0;

  // `e` with nominal parameters and the discrete values of `discrete` replaced by numbers.
  Expression Substituted(const Expression& e,
                         const std::vector<std::pair<int, int>>& discrete) const {
    const SymbolTable& symbols = system.symbols();
    return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
      if (symbols[slot].kind == SymbolKind::kParameter && dim_of_slot[slot] < 0) {
        // A parameter derived from uncertain ones is that function of them (a dimension each).
        const Expression resolved = system.ResolvedParameter(slot);
        return resolved.is_constant() ? Expression::Constant(nominal[slot]) : resolved;
      }
      if (symbols[slot].kind == SymbolKind::kDiscrete) {
        for (const auto& [s, v] : discrete) {
          if (s == slot) return Expression::Constant(v);
        }
      }
      return std::nullopt;
    });
  }

  // `e` as an affine map over the dimensions, or nullopt.
  std::optional<AffineMap> Affine(const Expression& e,
                                  const std::vector<std::pair<int, int>>& discrete) const {
    const std::optional<AffineForm> form = Substituted(e, discrete).AsAffine();
    if (!form || !std::isfinite(form->constant)) return std::nullopt;
    AffineMap m{std::vector<double>(static_cast<size_t>(dims), 0.0), form->constant};
    for (const auto& [slot, coefficient] : form->terms) {
      if (dim_of_slot[slot] < 0 || !std::isfinite(coefficient)) return std::nullopt;
      m.a[static_cast<size_t>(dim_of_slot[slot])] += coefficient;
    }
    return m;
  }

  // `c` as lhs - rhs REL 0 (> and >= turned around), or nullopt if not affine.
  std::optional<LinearConstraint> Constraint(
      const Comparison& c, const std::vector<std::pair<int, int>>& discrete) const {
    const std::optional<AffineMap> r = Affine(c.Residual(), discrete);
    if (!r) return std::nullopt;
    LinearConstraint out{r->a, r->b, Kind::kLessEqual};
    switch (c.relation) {
      case Relation::kLess:
        out.kind = Kind::kLess;
        break;
      case Relation::kLessEqual:
        break;
      case Relation::kGreater:
        return Negated(out, Kind::kLess);
      case Relation::kGreaterEqual:
        return Negated(out, Kind::kLessEqual);
      case Relation::kEqual:
        out.kind = Kind::kEqual;
        break;
    }
    return out;
  }

  // The conjunction of `comparisons` in a mode with `discrete` values: constant-true parts
  // dropped; nullopt if a part is constant-false. Throws NotLinearError naming `what`.
  std::optional<std::vector<LinearConstraint>> Conjunction(
      const std::vector<Comparison>& comparisons, const std::vector<std::pair<int, int>>& discrete,
      const std::string& what) const {
    std::vector<LinearConstraint> out;
    for (const Comparison& x : comparisons) {
      const std::optional<LinearConstraint> c = Constraint(x, discrete);
      if (!c) NotLinear(what + ": '" + x.ToString() + "' is not linear");
      if (!IsConstant(*c)) {
        out.push_back(*c);
      } else if (!ConstantHolds(*c)) {
        return std::nullopt;
      }
    }
    return out;
  }

  // The rates of `mode` (ProductModeOf) over the dimensions; sets input_rates and exact.
  ConvexPolyhedron Rates(const Mode& mode, int num_variables, int clock,
                         std::vector<AffineMap>& input_rates, bool& exact) const {
    const int ni = static_cast<int>(
        std::count_if(input_of_slot.begin(), input_of_slot.end(), [](int k) { return k >= 0; }));
    ConvexPolyhedron r = ConvexPolyhedron::Universe(dims + ni);
    std::vector<double> a(static_cast<size_t>(dims + ni), 0.0);
    auto unit = [&](int d) {
      std::vector<double> e = a;
      e[static_cast<size_t>(d)] = 1.0;
      return e;
    };
    input_rates.assign(static_cast<size_t>(num_variables),
                       AffineMap{std::vector<double>(static_cast<size_t>(ni), 0.0), 0.0});
    for (int d = num_variables; d < dims; ++d) {
      r.AddConstraint({unit(d), d == clock ? -1.0 : 0.0, Kind::kEqual});
    }
    for (int s = 0; s < static_cast<int>(input_of_slot.size()); ++s) {
      const int u = input_of_slot[s];
      if (u < 0) continue;
      std::vector<double> below = unit(dims + u);
      for (double& v : below) v = -v;
      r.AddConstraint({below, box[s].lo(), Kind::kLessEqual});            // u >= lo
      r.AddConstraint({unit(dims + u), -box[s].hi(), Kind::kLessEqual});  // u <= hi
    }
    for (int s = 0; s < static_cast<int>(dim_of_slot.size()); ++s) {
      const int d = dim_of_slot[s];
      if (d < 0 || d >= num_variables) continue;
      const std::optional<Expression> flow = mode.FlowOf(s);
      if (!flow) {
        r.AddConstraint({unit(d), 0.0, Kind::kEqual});
        continue;
      }
      const Expression e = Substituted(*flow, mode.discrete_values);
      RateOf(e, d, ni, r, input_rates[static_cast<size_t>(d)], exact, mode.name);
    }
    r.KeepDimensions(dims);
    return r;
  }

  // Constrains rate dimension d of `r` (inputs after the dims) by flow `e`: exactly when `e` is
  // affine in inputs, by its interval over the parameter ranges when it reads uncertain
  // parameters (exact = false). Throws NotLinearError if it reads the state.
  void RateOf(const Expression& e, int d, int ni, ConvexPolyhedron& r, AffineMap& in_inputs,
              bool& exact, const std::string& mode) const {
    const std::optional<AffineForm> form = e.AsAffine();
    bool reads_parameters = false;
    for (const int slot : e.Slots()) {
      const SymbolKind kind = system.symbols()[slot].kind;
      if (kind == SymbolKind::kParameter) {
        reads_parameters = true;
      } else if (kind != SymbolKind::kInput) {
        NotLinear("mode " + mode + ": the flow of '" + system.symbols()[dim_slot(d)].name +
                  "' reads '" + system.symbols()[slot].name + "'");
      }
    }
    std::vector<double> row(static_cast<size_t>(dims + ni), 0.0);
    row[static_cast<size_t>(d)] = 1.0;
    if (form && !reads_parameters) {
      for (const auto& [slot, coefficient] : form->terms) {
        row[static_cast<size_t>(dims + input_of_slot[slot])] = -coefficient;
        in_inputs.a[static_cast<size_t>(input_of_slot[slot])] = coefficient;
      }
      in_inputs.b = form->constant;
      r.AddConstraint({row, -form->constant, Kind::kEqual});
      return;
    }
    // A rectangular rate [lo, hi] reading parameters: [least lo, greatest hi] (tighter than
    // the interval of its flow expression, which forgets that w multiplies hi - lo).
    const std::optional<Range> rectangular = AsRectangularFlow(e);
    const Interval range = rectangular ? Interval(rectangular->lo.EvaluateInterval(box).lo(),
                                                  rectangular->hi.EvaluateInterval(box).hi())
                                       : e.EvaluateInterval(box);
    if (!std::isfinite(range.lo()) || !std::isfinite(range.hi())) {
      NotLinear("mode " + mode + ": the flow of '" + system.symbols()[dim_slot(d)].name +
                "' is unbounded over the parameter ranges");
    }
    exact = false;
    std::vector<double> minus(row.size(), 0.0);
    minus[static_cast<size_t>(d)] = -1.0;
    r.AddConstraint({row, -range.hi(), Kind::kLessEqual});
    r.AddConstraint({minus, range.lo(), Kind::kLessEqual});
  }

  int dim_slot(int d) const {
    for (int s = 0; s < static_cast<int>(dim_of_slot.size()); ++s) {
      if (dim_of_slot[s] == d) return s;
    }
    return 0;
  }
};

std::vector<int> LinearHybridSystem::ReadSlots(const std::vector<const Property*>& properties) {
  std::vector<int> read;
  for (const Property* p : properties) {
    p->predicate.ForEachComparison([&read](const Comparison& c) {
      for (const int s : c.lhs.Slots()) read.push_back(s);
      for (const int s : c.rhs.Slots()) read.push_back(s);
    });
  }
  return read;
}

LinearHybridSystem::LinearHybridSystem(const System& system, bool clock,
                                       const std::vector<const Property*>& observed)
    : LinearHybridSystem(system, clock, ReadSlots(observed)) {}

LinearHybridSystem::LinearHybridSystem(const System& system, bool clock,
                                       const std::vector<int>& read)
    : system_(system), forms_(new Forms{system, {}, {}, {}, {}, 0}) {
  liveness_ = std::make_unique<VariableLiveness>(system, read);
  const SymbolTable& symbols = system.symbols();
  const int n = symbols.size();
  Forms& f = *forms_;
  f.dim_of_slot.assign(static_cast<size_t>(n), -1);
  f.input_of_slot.assign(static_cast<size_t>(n), -1);
  f.nominal.assign(static_cast<size_t>(n), 0.0);
  f.box.assign(static_cast<size_t>(n), Interval(0.0));
  for (int s = 0; s < n; ++s) {
    if (symbols[s].kind != SymbolKind::kVariable) continue;
    f.dim_of_slot[s] = static_cast<int>(names_.size());
    names_.push_back(symbols[s].name);
    slots_.push_back(s);
  }
  num_variables_ = static_cast<int>(names_.size());
  for (const Component& c : system.components()) {
    const std::vector<double> env = c.automaton.ParameterEnvironment();
    for (const auto& [slot, value] : c.automaton.parameters()) {
      f.nominal[c.global_slot[slot]] = env[slot];
      f.box[c.global_slot[slot]] = Interval(env[slot]);
    }
  }
  for (const UncertainParameter& p : UncertainParameters(system)) {
    const int s = *symbols.Find(p.name);
    f.dim_of_slot[s] = static_cast<int>(names_.size());
    f.box[s] = Interval(p.lo, p.hi);
    names_.push_back(p.name);
    slots_.push_back(s);
  }
  for (int s = 0; s < n; ++s) {  // derived parameters: their range over the uncertain ones
    if (symbols[s].kind != SymbolKind::kParameter || f.dim_of_slot[s] >= 0) continue;
    const Expression resolved = system.ResolvedParameter(s);
    if (!resolved.is_constant()) f.box[s] = resolved.EvaluateInterval(f.box);
  }
  for (int s = 0; s < n; ++s) {
    if (symbols[s].kind != SymbolKind::kInput) continue;
    const auto [lo, hi] = system.InputBounds(s);
    f.input_of_slot[s] = static_cast<int>(inputs_.size());
    f.box[s] = Interval(lo, hi);
    inputs_.push_back(s);
    input_bounds_.emplace_back(lo, hi);
  }
  if (clock) {
    clock_ = static_cast<int>(names_.size());
    names_.push_back("time");
  }
  f.dims = dims();
}

LinearHybridSystem::~LinearHybridSystem() = default;

ConvexPolyhedron LinearHybridSystem::Polyhedron(
    const std::vector<LinearConstraint>& conjunction) const {
  ConvexPolyhedron p = ConvexPolyhedron::Universe(dims());
  for (const LinearConstraint& c : conjunction) p.AddConstraint(c);
  return p;
}

const LinearLocation& LinearHybridSystem::At(const std::vector<int>& tuple) {
  if (auto it = locations_.find(tuple); it != locations_.end()) return it->second;
  return locations_.emplace(tuple, Build(tuple)).first->second;
}

LinearLocation LinearHybridSystem::Build(const std::vector<int>& tuple) const {
  const Forms& f = *forms_;
  const Mode mode = system_.ProductModeOf(tuple);
  LinearLocation loc;
  loc.tuple = tuple;
  for (int c = 0; c < static_cast<int>(tuple.size()); ++c) {
    loc.name += (c > 0 ? ", " : "") + system_.QualifiedModeName(c, ModeId(tuple[c]));
  }
  loc.discrete_values = mode.discrete_values;
  // Invariants in their closure: the boundary belongs to the mode (docs/model_language.md).
  const auto invariant =
      f.Conjunction(Closed(mode.invariant.comparisons), mode.discrete_values, "mode " + loc.name);
  // A constant-false invariant: no state; an empty conjunction with a false part stands for it.
  loc.invariant =
      invariant
          ? *invariant
          : std::vector<LinearConstraint>{LinearConstraint{
                std::vector<double>(static_cast<size_t>(dims()), 0.0), 1.0, Kind::kLessEqual}};
  loc.elapse_invariant = loc.invariant;
  loc.rates = f.Rates(mode, num_variables_, clock_, loc.input_rates, loc.exact_rates);
  for (System::Step& step : system_.StepsFrom(tuple)) {
    const std::string what = "transition " + step.transition.name;
    // Guards in their closure: the simulator takes a jump where its guard holds in its closure
    // (a strict guard crossed at its boundary), so runs may jump there.
    const auto guard =
        f.Conjunction(Closed(step.transition.guard.comparisons), mode.discrete_values, what);
    if (!guard) continue;  // never enabled
    const std::vector<LinearConstraint>& closed = *guard;
    LinearEdge edge{std::move(step.target),
                    closed,
                    Polyhedron(closed),
                    {},
                    std::move(step.transition.name),
                    step.transition.urgency,
                    std::move(step.participants)};
    for (const Reset& r : step.transition.resets) {
      const std::optional<AffineMap> value = f.Affine(r.value, mode.discrete_values);
      if (!value)
        NotLinear(what + ": the reset of '" + system_.symbols()[r.slot].name +
                  "' is not linear in the variables and parameters");
      edge.resets.emplace_back(f.dim_of_slot[r.slot], *value);
    }
    // Urgent with one inequality g REL 0: time stops where it starts to hold (g >= 0).
    if (edge.urgency == Urgency::kUrgent && edge.guard.size() == 1 &&
        edge.guard[0].kind != Kind::kEqual) {
      loc.elapse_invariant.push_back(Negated(edge.guard[0], Kind::kLessEqual));
    }
    loc.edges.push_back(std::move(edge));
  }
  loc.invariant_set = Polyhedron(loc.invariant);
  loc.elapse_set = Polyhedron(loc.elapse_invariant);
  for (int c = 0; c < static_cast<int>(tuple.size()); ++c) {
    for (const int s : liveness_->DeadAt(c, tuple[static_cast<size_t>(c)])) {
      loc.dead.push_back(f.dim_of_slot[static_cast<size_t>(s)]);
    }
  }
  return loc;
}

std::vector<LinearHybridSystem::Initial> LinearHybridSystem::InitialSets() const {
  std::vector<Initial> out = {{{}, {}, ConvexPolyhedron::Universe(dims())}};
  std::vector<bool> set(static_cast<size_t>(dims()), false);
  std::vector<std::vector<bool>> assigned = {set};
  for (const Component& c : system_.components()) {
    std::vector<Initial> next;
    std::vector<std::vector<bool>> next_assigned;
    for (size_t i = 0; i < out.size(); ++i) {
      const auto& states = c.automaton.initial_states();
      for (int k = 0; k < static_cast<int>(states.size()); ++k) {
        Initial init = out[i];
        std::vector<bool> done = assigned[i];
        init.tuple.push_back(states[k].mode.value());
        init.init_index.push_back(k);
        for (const InitialValue& iv : states[k].values) {
          const int d = forms_->dim_of_slot[c.global_slot[iv.slot]];
          if (done[static_cast<size_t>(d)]) continue;  // the first component's value
          done[static_cast<size_t>(d)] = true;
          ConstrainInitial(c, iv, d, init.set);
        }
        next.push_back(std::move(init));
        next_assigned.push_back(std::move(done));
      }
    }
    out = std::move(next);
    assigned = std::move(next_assigned);
  }
  for (Initial& init : out) {
    const Forms& f = *forms_;
    for (int d = num_variables_; d < dims(); ++d) {
      std::vector<double> a(static_cast<size_t>(dims()), 0.0);
      a[static_cast<size_t>(d)] = 1.0;
      if (d == clock_) {
        init.set.AddConstraint({a, 0.0, Kind::kEqual});
        continue;
      }
      const Interval range = f.box[f.dim_slot(d)];
      init.set.AddConstraint({a, -range.hi(), Kind::kLessEqual});
      for (double& v : a) v = -v;
      init.set.AddConstraint({a, range.lo(), Kind::kLessEqual});
    }
  }
  return out;
}

void LinearHybridSystem::ConstrainInitial(const Component& c, const InitialValue& iv, int d,
                                          ConvexPolyhedron& set) const {
  const SymbolTable& symbols = system_.symbols();
  auto global = [&](const Expression& e) {
    return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
      const int g = c.global_slot[slot];
      return Expression::Symbol(symbols[g].name, g);
    });
  };
  const std::string what = "the initial value of '" + symbols[slots_[d]].name + "'";
  const std::optional<AffineMap> lo = forms_->Affine(global(iv.range.lo), {});
  const std::optional<AffineMap> hi = forms_->Affine(global(iv.range.hi), {});
  if (!lo || !hi) NotLinear(what + " is not linear in the parameters");
  // x - lo >= 0 and x - hi <= 0 (x == lo for a point).
  AffineMap below = *lo;
  for (double& v : below.a) v = -v;
  below.a[static_cast<size_t>(d)] += 1.0;
  AffineMap above = *hi;
  for (double& v : above.a) v = -v;
  above.a[static_cast<size_t>(d)] += 1.0;
  if (iv.is_point) {
    set.AddConstraint({below.a, -lo->b, Kind::kEqual});
    return;
  }
  set.AddConstraint(Negated({below.a, -lo->b, Kind::kLessEqual}, Kind::kLessEqual));
  set.AddConstraint({above.a, -hi->b, Kind::kLessEqual});
}

std::vector<std::vector<LinearConstraint>> LinearHybridSystem::States(
    const Predicate& predicate, bool negated, const LinearLocation& location) const {
  switch (predicate.kind()) {
    case Predicate::Kind::kTrue:
    case Predicate::Kind::kFalse: {
      const bool holds = (predicate.kind() == Predicate::Kind::kTrue) != negated;
      return holds ? Disjunction{{}} : Disjunction{};
    }
    case Predicate::Kind::kInMode: {
      const auto found = system_.FindMode(predicate.mode());
      const bool in = found && location.tuple[found->first] == found->second.value();
      return in != negated ? Disjunction{{}} : Disjunction{};
    }
    case Predicate::Kind::kComparison: {
      const auto c = forms_->Constraint(predicate.comparison(), location.discrete_values);
      if (!c) NotLinear("'" + predicate.comparison().ToString() + "' is not linear");
      if (!negated) return {{*c}};
      if (c->kind == Kind::kEqual) return {{Negated(*c, Kind::kLess)}, {{c->a, c->b, Kind::kLess}}};
      return {{Negated(*c, c->kind == Kind::kLess ? Kind::kLessEqual : Kind::kLess)}};
    }
    case Predicate::Kind::kNot:
      return States(predicate.operands()[0], !negated, location);
    case Predicate::Kind::kAnd:
    case Predicate::Kind::kOr:
      break;
  }
  // And (Or when negated) crosses the operands' cases; Or (And when negated) joins them.
  const bool cross = (predicate.kind() == Predicate::Kind::kAnd) != negated;
  Disjunction out = cross ? Disjunction{{}} : Disjunction{};
  for (const Predicate& operand : predicate.operands()) {
    const Disjunction part = States(operand, negated, location);
    if (cross) {
      out = Cross(out, part);
    } else {
      out.insert(out.end(), part.begin(), part.end());
      if (out.size() > kMaxDisjuncts) NotLinear("a property with too many cases (over 256)");
    }
  }
  return out;
}

}  // namespace hybrid
