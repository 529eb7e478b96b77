#include "solvers/reachability/group_product.h"

#include <algorithm>
#include <set>
#include <utility>

namespace hybrid {
namespace {

// The components whose modes `p` names (`in` atoms).
void ModesRead(const System& system, const Predicate& p, std::set<int>& components) {
  if (p.kind() == Predicate::Kind::kInMode) {
    if (const auto found = system.FindMode(p.mode())) components.insert(found->first);
    return;
  }
  for (const Predicate& operand : p.operands()) ModesRead(system, operand, components);
}

}  // namespace

GroupProduct::GroupProduct(LinearHybridSystem& full, std::vector<Group> groups, ReachMeter& meter)
    : full_(full), groups_(std::move(groups)), meter_(meter) {
  start_.assign(full_.system().components().size(), -1);
  for (const Group& g : groups_) {
    if (g.states.empty()) {  // a group without a state: no run at all; left to the exploration
      start_.clear();
      return;
    }
    const std::vector<int>& first = g.states.begin()->first;
    for (std::size_t i = 0; i < g.components.size(); ++i) {
      start_[static_cast<std::size_t>(g.components[i])] = first[i];
    }
  }
}

std::vector<int> GroupProduct::GroupsRead(const Property& property) const {
  const System& system = full_.system();
  std::set<int> components;
  ModesRead(system, property.predicate, components);
  std::set<int> slots;
  property.predicate.ForEachComparison([&slots](const Comparison& c) {
    for (const int s : c.lhs.Slots()) slots.insert(s);
    for (const int s : c.rhs.Slots()) slots.insert(s);
  });
  for (int c = 0; c < static_cast<int>(system.components().size()); ++c) {
    for (const int g : system.components()[c].global_slot) {
      const SymbolKind kind = system.symbols()[g].kind;
      if ((kind == SymbolKind::kVariable || kind == SymbolKind::kDiscrete) && slots.count(g)) {
        components.insert(c);
      }
    }
  }
  std::vector<int> out;
  for (int k = 0; k < static_cast<int>(groups_.size()); ++k) {
    const std::vector<int>& comps = groups_[k].components;
    if (std::any_of(comps.begin(), comps.end(), [&](int c) { return components.count(c) > 0; })) {
      out.push_back(k);
    }
  }
  return out;
}

std::optional<bool> GroupProduct::Meets(const Property& property) {
  if (start_.empty()) return std::nullopt;
  const std::vector<int> read = GroupsRead(property);
  const bool negated = property.kind == Property::Kind::kAlways;
  // Every combination of the read groups' locations (an odometer over their maps).
  std::vector<std::map<std::vector<int>, std::vector<ConvexPolyhedron>>::const_iterator> it;
  for (const int k : read) it.push_back(groups_[k].states.begin());
  while (true) {
    std::vector<int> tuple = start_;
    std::vector<const std::vector<ConvexPolyhedron>*> at;
    for (std::size_t j = 0; j < read.size(); ++j) {
      const Group& g = groups_[read[j]];
      for (std::size_t i = 0; i < g.components.size(); ++i) {
        tuple[static_cast<std::size_t>(g.components[i])] = it[j]->first[i];
      }
      at.push_back(&it[j]->second);
    }
    // The share bounds the combinations even where none has bad states (building a location is
    // charged); the slice is checked where there are states to combine.
    if (meter_.ShareExhausted() || meter_.OutOfTime()) return std::nullopt;
    const int before = full_.num_locations();
    const LinearLocation& loc = full_.At(tuple);
    if (full_.num_locations() != before) meter_.Location();
    for (const std::vector<LinearConstraint>& c : full_.States(property.predicate, negated, loc)) {
      const ConvexPolyhedron bad = full_.Polyhedron(c);
      meter_.Op(bad, 2);
      if (OverBound()) return std::nullopt;
      if (bad.IsEmpty()) continue;
      const std::optional<bool> met = Combine(read, at, 0, bad);
      if (!met || *met) return met;
    }
    std::size_t j = 0;  // the next combination
    while (j < read.size() && ++it[j] == groups_[read[j]].states.end()) {
      it[j] = groups_[read[j]].states.begin();
      ++j;
    }
    if (j == read.size()) return false;
  }
}

std::optional<bool> GroupProduct::Combine(
    const std::vector<int>& read, const std::vector<const std::vector<ConvexPolyhedron>*>& at,
    std::size_t k, const ConvexPolyhedron& set) {
  if (k == read.size()) return true;
  for (const ConvexPolyhedron& state : *at[k]) {
    meter_.Op(set, state);
    if (OverBound()) return std::nullopt;
    if (k + 1 == read.size()) {
      if (set.Intersects(state)) return true;
      continue;
    }
    ConvexPolyhedron next = set;
    next.Intersect(state);
    meter_.Op(next, 2);
    if (next.IsEmpty()) continue;
    const std::optional<bool> met = Combine(read, at, k + 1, next);
    if (!met || *met) return met;
  }
  return false;
}

}  // namespace hybrid
