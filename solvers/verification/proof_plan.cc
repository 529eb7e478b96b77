#include "solvers/verification/proof_plan.h"

#include <algorithm>
#include <functional>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "automaton/internal_assert.h"

namespace hybrid {

namespace {

using ProductJobs = std::map<std::vector<int>, ProofPlan::Product>;

Predicate Remap(const Predicate& p, const std::function<Expression(const Expression&)>& expr,
                const std::function<std::string(const std::string&)>& mode) {
  switch (p.kind()) {
    case Predicate::Kind::kTrue:
    case Predicate::Kind::kFalse:
      return p;
    case Predicate::Kind::kComparison: {
      const Comparison& c = p.comparison();
      return Predicate::Compare({expr(c.lhs), c.relation, expr(c.rhs)});
    }
    case Predicate::Kind::kInMode:
      return Predicate::InMode(mode(p.mode()));
    case Predicate::Kind::kNot:
      return Predicate::Not(Remap(p.operands()[0], expr, mode));
    case Predicate::Kind::kAnd:
      return Predicate::And(Remap(p.operands()[0], expr, mode), Remap(p.operands()[1], expr, mode));
    case Predicate::Kind::kOr:
      return Predicate::Or(Remap(p.operands()[0], expr, mode), Remap(p.operands()[1], expr, mode));
  }
  return p;
}

// Slots and modes a predicate reads.
void Collect(const Predicate& p, std::set<int>& slots, std::set<std::string>& modes) {
  p.ForEachComparison([&](const Comparison& c) {
    for (int s : c.lhs.Slots()) slots.insert(s);
    for (int s : c.rhs.Slots()) slots.insert(s);
  });
  p.ForEachMode([&](const std::string& m) { modes.insert(m); });
}

// Which components write each System slot (continuous variables).
std::vector<std::vector<int>> SlotOwners(const System& system) {
  const auto components = system.components();
  std::vector<std::vector<int>> owners(system.symbols().size());
  for (std::size_t c = 0; c < components.size(); ++c) {
    for (const VariableInfo& v : components[c].automaton.variables()) {
      owners[components[c].global_slot[v.slot]].push_back(static_cast<int>(c));
    }
  }
  return owners;
}

// The components that hold the variables (`slots`) and `modes` property `p` reads, or component 0
// when it reads none. Throws std::invalid_argument for a property that reads an input.
std::set<int> ComponentsRead(const System& system, const Property& p, const std::set<int>& slots,
                             const std::set<std::string>& modes) {
  const auto components = system.components();
  std::set<int> comps;
  for (int s : slots) {
    const SymbolKind kind = system.symbols()[s].kind;
    if (kind == SymbolKind::kInput) {
      throw std::invalid_argument("property '" + p.name + "' reads input '" +
                                  system.symbols()[s].name +
                                  "': properties may read variables, parameters and modes");
    }
    if (kind == SymbolKind::kParameter) continue;
    for (std::size_t c = 0; c < components.size(); ++c) {
      const auto& g = components[c].global_slot;
      if (std::find(g.begin(), g.end(), s) != g.end()) comps.insert(static_cast<int>(c));
    }
  }
  for (const std::string& m : modes) {
    if (auto found = system.FindMode(m)) comps.insert(found->first);
  }
  // A parameter none of those components has (another instance's `A.p`): the first component
  // that declares it joins, so that the job has the parameter (and its range) too.
  for (int s : slots) {
    if (system.symbols()[s].kind != SymbolKind::kParameter) continue;
    auto has = [&](int c) {
      const auto& g = components[static_cast<std::size_t>(c)].global_slot;
      return std::find(g.begin(), g.end(), s) != g.end();
    };
    if (std::any_of(comps.begin(), comps.end(), has)) continue;
    for (int c = 0; c < static_cast<int>(components.size()); ++c) {
      if (has(c)) {
        comps.insert(c);
        break;
      }
    }
  }
  if (comps.empty()) comps.insert(0);
  return comps;
}

// Whether component c alone over-approximates what it does in the system, so that a property
// reading only c may be checked on c alone: no other component has a continuous variable of c,
// and no urgent transition of c synchronises with another component (a partner that is not
// ready lets time pass beyond the point where c alone would have to jump; lazy synchronised
// transitions only lose jumps in the system, which is sound).
bool WritesAlone(const System& system, const std::vector<std::vector<int>>& owners, int c) {
  const Component& comp = system.components()[c];
  for (const VariableInfo& v : comp.automaton.variables()) {
    if (owners[comp.global_slot[v.slot]].size() > 1) return false;
  }
  for (const Transition& t : comp.automaton.transitions()) {
    if (t.urgency != Urgency::kUrgent || t.label.empty()) continue;
    for (int other = 0; other < static_cast<int>(system.components().size()); ++other) {
      if (other != c && system.Alphabet(other).count(t.label)) return false;
    }
  }
  return true;
}

// `p` (System slots) over the slots of a job whose slot i is System slot to_system[i], its mode
// names mapped by `mode`.
Property OverJobSlots(const Property& p, const std::vector<int>& to_system, int system_slots,
                      const std::function<std::string(const std::string&)>& mode) {
  std::vector<int> local(static_cast<std::size_t>(system_slots), -1);
  for (std::size_t s = 0; s < to_system.size(); ++s) local[to_system[s]] = static_cast<int>(s);
  Property q = p;
  q.predicate = Remap(
      p.predicate,
      [&](const Expression& e) {
        return e.Substitute([&](const std::string& name, int slot) -> std::optional<Expression> {
          return Expression::Symbol(name, local.at(slot));
        });
      },
      mode);
  return q;
}

// `p` (System slots and mode names) over component c's own slots and mode names.
Property Localise(const System& system, int c, const Property& p) {
  const Component& comp = system.components()[c];
  return OverJobSlots(p, comp.global_slot, system.symbols().size(), [&](const std::string& m) {
    auto found = system.FindMode(m);
    return found ? comp.automaton.mode(found->second).name : m;
  });
}

// Adds `q`, the local form of property number i (`p`), to component c's job; the same question
// asked twice is answered once (`asked`: goals looked up by their text, then compared).
void AddGoal(int c, const Property& q, int i, const Property& p,
             std::map<std::string, std::vector<int>>& asked, std::vector<ProofJob>& jobs) {
  const std::string key = std::to_string(c) + " " + std::string(KindKeyword(q.kind)) + " " +
                          q.predicate.ToString() + " " +
                          (q.horizon ? FormatNumber(*q.horizon) : std::string("-"));
  for (const int g : asked[key]) {
    ProofGoal& goal = jobs[c].goals[g];
    if (goal.property.kind == q.kind && goal.property.predicate == q.predicate &&
        goal.property.horizon == q.horizon) {
      goal.also.push_back(i);
      return;
    }
  }
  asked[key].push_back(static_cast<int>(jobs[c].goals.size()));
  jobs[c].goals.push_back({q, i, p, {}});
}

// The components of the interaction groups of `comps`, ascending.
std::vector<int> GroupsOf(const std::vector<int>& group, const std::set<int>& comps) {
  std::set<int> representatives;
  for (const int c : comps) representatives.insert(group[c]);
  std::vector<int> out;
  for (std::size_t c = 0; c < group.size(); ++c) {
    if (representatives.count(group[c])) out.push_back(static_cast<int>(c));
  }
  return out;
}

// Makes the product of components `which` into `pj` (automaton and to_system), or records why
// it cannot be made.
void MakeProduct(const System& system, const std::vector<int>& which, int max_product_modes,
                 ProofPlan::Product& pj) {
  const System restricted = system.Restricted(which);
  pj.components = which;
  pj.job.product_components = which;
  try {
    pj.automaton = restricted.Product(max_product_modes, &pj.tuples);
  } catch (const std::invalid_argument& e) {
    pj.failure = std::string(
                     "the property reads several components and their product is too "
                     "large: ") +
                 e.what();
    return;
  }
  for (int s = 0; s < restricted.symbols().size(); ++s) {
    pj.job.to_system.push_back(*system.symbols().Find(restricted.symbols()[s].name));
  }
}

// The disjunction of `atoms[lo, hi)`, as a balanced tree (depth log2 of their number); false for
// none.
Predicate AnyOf(const std::vector<Predicate>& atoms, std::size_t lo, std::size_t hi) {
  if (lo >= hi) return Predicate::False();
  if (hi - lo == 1) return atoms[lo];
  const std::size_t mid = lo + (hi - lo) / 2;
  return Predicate::Or(AnyOf(atoms, lo, mid), AnyOf(atoms, mid, hi));
}

// `p` with every `in A.m` atom (a mode of one component) replaced by the disjunction of the
// product modes of `pj` whose A part is m.
Predicate OverProductModes(const System& system, const ProofPlan::Product& pj, const Predicate& p) {
  switch (p.kind()) {
    case Predicate::Kind::kInMode: {
      const auto found = system.FindMode(p.mode());
      const auto at = found ? std::find(pj.components.begin(), pj.components.end(), found->first)
                            : pj.components.end();
      if (at == pj.components.end()) return Predicate::False();
      const std::size_t i = static_cast<std::size_t>(at - pj.components.begin());
      std::vector<Predicate> atoms;
      for (std::size_t m = 0; m < pj.tuples.size(); ++m) {
        if (pj.tuples[m][i] == found->second.value()) {
          atoms.push_back(Predicate::InMode(pj.automaton->modes()[m].name));
        }
      }
      return AnyOf(atoms, 0, atoms.size());
    }
    case Predicate::Kind::kNot:
      return Predicate::Not(OverProductModes(system, pj, p.operands()[0]));
    case Predicate::Kind::kAnd:
      return Predicate::And(OverProductModes(system, pj, p.operands()[0]),
                            OverProductModes(system, pj, p.operands()[1]));
    case Predicate::Kind::kOr:
      return Predicate::Or(OverProductModes(system, pj, p.operands()[0]),
                           OverProductModes(system, pj, p.operands()[1]));
    default:
      return p;
  }
}

// Adds property number i (`p`) to the job of the product of components `which`, making the
// product on first use (its `in A.m` atoms become disjunctions of product modes); or leaves it
// `unknown` when the product is too large.
void AddProductGoal(const System& system, const Property& p, int i, const std::vector<int>& which,
                    int max_product_modes, std::vector<CheckResult>& results,
                    ProductJobs& products) {
  ProofPlan::Product& pj = products[which];
  if (!pj.automaton && pj.failure.empty()) MakeProduct(system, which, max_product_modes, pj);
  if (!pj.automaton) {
    results[i].verdict = Verdict::kUnknown;
    results[i].reason = pj.failure;
    return;
  }
  // Modes are kept (OverProductModes maps them).
  Property q = OverJobSlots(p, pj.job.to_system, system.symbols().size(),
                            [](const std::string& m) { return m; });
  q.predicate = OverProductModes(system, pj, q.predicate);
  pj.job.goals.push_back({std::move(q), i, p, {}});
}

// Sorts `properties` into jobs: one per component for a property that reads only that
// component's own variables (in its slots and mode names), a product job for the others (the
// product of the interaction groups the property reads), or a verdict right away (`unknown`)
// when neither is possible.
void PlanJobs(const System& system, std::span<const Property> properties, int max_product_modes,
              std::vector<CheckResult>& results, std::vector<ProofJob>& jobs,
              ProductJobs& products) {
  const std::vector<std::vector<int>> owners = SlotOwners(system);
  const std::vector<int> group = system.InteractionGroups();
  std::map<std::string, std::vector<int>> asked;  // goals by their text (see AddGoal)
  for (std::size_t i = 0; i < properties.size(); ++i) {
    const Property& p = properties[i];
    results[i].property = p.name;
    results[i].kind = p.kind;
    results[i].method = "prove";
    std::set<int> slots;
    std::set<std::string> modes;
    Collect(p.predicate, slots, modes);
    const std::set<int> comps = ComponentsRead(system, p, slots, modes);
    if (comps.size() == 1 && WritesAlone(system, owners, *comps.begin())) {
      const int c = *comps.begin();
      AddGoal(c, Localise(system, c, p), static_cast<int>(i), p, asked, jobs);
      continue;
    }
    AddProductGoal(system, p, static_cast<int>(i), GroupsOf(group, comps), max_product_modes,
                   results, products);
  }
}

// The declared invariants of component `c` join its job as lemmas.
void AddLemmas(const System& system, int c, ProofJob& job) {
  const auto components = system.components();
  // The component's own declared invariants serve as lemmas.
  for (const Property& lemma : components[c].automaton.properties()) {
    if (lemma.kind == Property::Kind::kReach) continue;
    bool dup = false;
    for (const ProofGoal& g : job.goals) {
      dup = dup || (g.property.kind == lemma.kind && g.property.predicate == lemma.predicate &&
                    g.property.horizon == lemma.horizon);
    }
    if (dup) continue;
    Property original = lemma;
    original.predicate = Remap(
        lemma.predicate,
        [&](const Expression& e) {
          return e.Substitute([&](const std::string& name, int slot) -> std::optional<Expression> {
            return Expression::Symbol(name, components[c].global_slot[slot]);
          });
        },
        [&](const std::string& m) {
          auto id = components[c].automaton.FindMode(m);
          return id ? system.QualifiedModeName(c, *id) : m;
        });
    job.goals.push_back({lemma, -1, original, {}});
  }
}

// An earlier component, instance of the same automaton, whose job asks the same questions as
// component `c`'s (its proof serves for both), or -1.
int SameInstance(const System& system, const std::vector<ProofJob>& jobs, int c) {
  const auto components = system.components();
  const ProofJob& job = jobs[c];
  int same = -1;
  for (int c0 = 0; c0 < c && same < 0; ++c0) {
    const ProofJob& j0 = jobs[c0];
    if (j0.goals.size() != job.goals.size() || !(components[c0].source == components[c].source)) {
      continue;
    }
    // Compare with the declared (unqualified) names: slots are the same in both instances.
    auto plain = [&](const Predicate& p, const Component& comp) {
      return Remap(
          p,
          [&](const Expression& e) {
            return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
              return Expression::Symbol(comp.source.symbols()[slot].name, slot);
            });
          },
          [&](const std::string& m) {
            auto id = comp.automaton.FindMode(m);
            return id ? comp.source.mode(*id).name : m;
          });
    };
    bool equal = true;
    for (std::size_t g = 0; g < job.goals.size() && equal; ++g) {
      const Property& a = j0.goals[g].property;
      const Property& b = job.goals[g].property;
      equal = a.kind == b.kind && a.horizon == b.horizon &&
              plain(a.predicate, components[c0]) == plain(b.predicate, components[c]);
    }
    if (equal) same = c0;
  }
  return same;
}

// Whether jobs `x` and `y`, over products that correspond slot for slot, ask the same questions
// (compared by slot: their names differ by the instance names).
bool SameQuestions(const ProofJob& x, const ProofJob& y) {
  if (x.goals.size() != y.goals.size()) return false;
  auto by_slot = [](const Predicate& p) {
    return Remap(
        p,
        [](const Expression& e) {
          return e.Substitute([](const std::string&, int slot) -> std::optional<Expression> {
            return Expression::Symbol("s" + std::to_string(slot), slot);
          });
        },
        [](const std::string& m) { return m; });
  };
  for (std::size_t g = 0; g < x.goals.size(); ++g) {
    const Property& a = x.goals[g].property;
    const Property& b = y.goals[g].property;
    if (a.kind != b.kind || a.horizon != b.horizon ||
        !(by_slot(a.predicate) == by_slot(b.predicate))) {
      return false;
    }
  }
  return true;
}

}  // namespace

ProofPlan::ProofPlan(const System& system, std::span<const Property> properties,
                     int max_product_modes, std::vector<CheckResult>& results)
    : jobs_(system.components().size()) {
  HYBRID_ASSERT(results.size() == properties.size(), "one result per property");
  PlanJobs(system, properties, max_product_modes, results, jobs_, products_);
  PlanComponents(system);
  PlanProducts(system);
}

// Each component's job (if asked anything) gets its automaton and lemmas; it is run unless an
// earlier instance of the same automaton asks the same questions (then copied from it).
void ProofPlan::PlanComponents(const System& system) {
  const auto components = system.components();
  std::vector<int> same(components.size(), -1);
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    ProofJob& job = jobs_[c];
    if (job.goals.empty()) continue;
    job.automaton = &components[c].automaton;
    job.component = c;
    job.to_system = components[c].global_slot;
    AddLemmas(system, c, job);
    same[c] = SameInstance(system, jobs_, c);
    if (same[c] < 0) ++runs_;
  }
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    if (jobs_[c].goals.empty()) continue;
    if (same[c] < 0) {
      steps_.push_back({&jobs_[c], nullptr, std::nullopt});
    } else {
      steps_.push_back({&jobs_[c], &jobs_[same[c]], SharedProof::ForInstance(system, same[c], c)});
    }
  }
}

// Each product's job (if asked anything) is run unless an earlier product of instances of the
// same automata, bound alike, asks the same questions; the copies come after every run.
void ProofPlan::PlanProducts(const System& system) {
  std::vector<Step> copies;
  std::set<const ProofJob*> copied;
  for (auto& [which, pj] : products_) {
    if (pj.job.goals.empty()) continue;
    HYBRID_ASSERT(pj.automaton.has_value(), "a product asked something has been made");
    pj.job.automaton = &*pj.automaton;
    for (const auto& [earlier, pe] : products_) {
      if (earlier == which) break;
      if (pe.job.goals.empty() || copied.count(&pe.job)) continue;
      auto how = SharedProof::ForProducts(system, earlier, which);
      if (how && SameQuestions(pe.job, pj.job)) {
        copies.push_back({&pj.job, &pe.job, std::move(how)});
        copied.insert(&pj.job);
        break;
      }
    }
    if (!copied.count(&pj.job)) {
      ++runs_;
      steps_.push_back({&pj.job, nullptr, std::nullopt});
    }
  }
  for (Step& copy : copies) steps_.push_back(std::move(copy));
}

}  // namespace hybrid
