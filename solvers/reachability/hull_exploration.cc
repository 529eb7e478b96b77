#include "solvers/reachability/hull_exploration.h"

#include <algorithm>
#include <cmath>

#include "solvers/reachability/exploration_steps.h"

namespace hybrid {

HullExploration::HullExploration(const System& system, std::vector<const Property*> properties,
                                 const std::vector<int>& read, ReachMeter& meter,
                                 std::function<void(int classes, int queued)> progress,
                                 int growths_before_widening)
    : lhs_(system, false, read),
      properties_(std::move(properties)),
      meter_(meter),
      progress_(std::move(progress)),
      growths_before_widening_(std::max(growths_before_widening, 1)),
      met_(properties_.size(), false) {}

HullExploration::Status HullExploration::Resume(const std::vector<bool>& settled) {
  if (!started_) {
    started_ = true;
    Start();
  }
  while (!abandoned_ && !NothingToProve(settled)) {
    if (queue_.empty()) return Status::kFixpoint;
    if (meter_.Exhausted() || meter_.OutOfTime()) return Status::kOpen;
    const auto it = queue_.begin()->second;
    queue_.erase(queue_.begin());
    Class& c = it->second;
    c.queued = false;
    const std::uint64_t before = meter_.used();
    // F is computed when the class is expanded, once for every growth of E since the last time.
    const LinearLocation& loc = lhs_.At(it->first.first);
    c.flowed = Flow(loc, c.entry, nullptr, meter_);
    CheckProperties(loc, c.flowed);
    if (!NothingToProve(settled)) Expand(it->first, c);
    meter_.Charge((kCostFactor - 1) * (meter_.used() - before));
    if (progress_ && ++expanded_ % 64 == 0) {
      progress_(static_cast<int>(classes_.size()), static_cast<int>(queue_.size()));
    }
  }
  abandoned_ = true;
  return Status::kAbandoned;
}

bool HullExploration::NothingToProve(const std::vector<bool>& settled) const {
  for (std::size_t i = 0; i < met_.size(); ++i) {
    if (!met_[i] && !(i < settled.size() && settled[i])) return false;
  }
  return true;
}

void HullExploration::Start() {
  for (const LinearHybridSystem::Initial& initial : lhs_.InitialSets()) {
    const LinearLocation& loc = Enter(initial.tuple);
    ConvexPolyhedron set = Forgetting(loc, initial.set, meter_);
    set.Intersect(loc.invariant_set);
    meter_.Op(set, 2);
    if (!set.IsEmpty()) Add(initial.tuple, std::move(set));
  }
}

const LinearLocation& HullExploration::Enter(const std::vector<int>& tuple) {
  const int before = lhs_.num_locations();
  const LinearLocation& loc = lhs_.At(tuple);
  if (lhs_.num_locations() != before) meter_.Location();
  return loc;
}

// The dimensions whose rate `loc` fixes to 0 (its rates' bounds, exact for 0).
const std::vector<int>& HullExploration::ConstantDims(const LinearLocation& loc) {
  auto [it, added] = constant_dims_.try_emplace(&loc);
  if (!added) return it->second;
  const std::vector<std::pair<double, double>> rates = loc.rates.Bounds();
  meter_.Op(loc.rates);
  for (int d = 0; d < static_cast<int>(rates.size()); ++d) {
    if (rates[d].first == 0.0 && rates[d].second == 0.0) it->second.push_back(d);
  }
  return it->second;
}

// Adds the entry set `set` (non-empty, inside the invariant of `tuple`'s location) to its class.
void HullExploration::Add(const std::vector<int>& tuple, ConvexPolyhedron set) {
  const LinearLocation& loc = Enter(tuple);
  Key key{tuple, {}};
  const std::vector<int>& constant = ConstantDims(loc);
  if (!constant.empty()) {
    const std::vector<std::pair<double, double>> bounds = set.Bounds();
    meter_.Op(set);
    for (const int d : constant) {
      const auto [lo, hi] = bounds[static_cast<std::size_t>(d)];
      if (lo == hi && std::isfinite(lo)) key.second.emplace_back(d, lo);
    }
  }
  auto it = classes_.find(key);
  if (it == classes_.end()) {
    it = classes_.emplace(std::move(key), Class{std::move(set)}).first;
    it->second.order = static_cast<long long>(classes_.size());
  } else {
    Class& c = it->second;
    meter_.Op(c.entry, set);
    if (c.entry.Contains(set)) return;
    const ConvexPolyhedron previous = c.entry;
    c.entry.Hull(set);
    meter_.Op(c.entry, set);
    if (c.entry.NumConstraints() > kMaxFacetsPerDimension * lhs_.dims()) {
      // Too many facets for its dimension: the constraint hull instead (its constraints are
      // among those of the two sets).
      c.entry = previous;
      c.entry.ConstraintHull(set);
      c.entry.Intersect(loc.invariant_set);  // it may leave the invariant, which both lie in
      meter_.Op(c.entry, set);
      meter_.Op(c.entry);
    }
    if (!c.queued) ++c.growths;
    if (c.growths > growths_before_widening_) {  // each hull contains `previous`
      c.entry.Widen(previous);
      widened_ = true;
      c.entry.Intersect(loc.invariant_set);
      meter_.Op(c.entry, 2);
    }
    meter_.Op(c.entry);
    if (c.entry.LargestCoefficientBits() > kMaxBits) {
      abandoned_ = true;
      too_long_ = true;
      return;
    }
  }
  Class& c = it->second;
  CheckProperties(loc, c.entry);  // E lies in F: a bad state met here is met there
  if (!c.queued) {
    c.queued = true;
    queue_.emplace(c.order, it);
  }
}

// Takes every edge from the class's states F.
void HullExploration::Expand(const Key& key, const Class& c) {
  const LinearLocation& loc = lhs_.At(key.first);
  const Box box = BoxOf(c.flowed);
  meter_.Op(c.flowed);
  for (const LinearEdge& edge : loc.edges) {
    meter_.Boxes(1);
    if (CertainlyMisses(box, edge.guard)) continue;
    std::optional<ConvexPolyhedron> jumped = Jump(edge, c.flowed, meter_);
    if (!jumped) continue;
    const LinearLocation& target = Enter(edge.target);
    std::optional<ConvexPolyhedron> entered = Entering(target, std::move(*jumped), meter_);
    if (!entered) continue;
    Add(edge.target, std::move(*entered));
    if (abandoned_) return;
  }
}

// Marks each property whose bad (target) states at `loc` meet `states`.
void HullExploration::CheckProperties(const LinearLocation& loc, const ConvexPolyhedron& states) {
  for (std::size_t i = 0; i < properties_.size(); ++i) {
    if (met_[i]) continue;
    auto [it, added] = bad_.try_emplace({i, &loc});
    if (added) {
      const Property& property = *properties_[i];
      const bool negated = property.kind == Property::Kind::kAlways;
      for (const auto& conjunction : lhs_.States(property.predicate, negated, loc)) {
        ConvexPolyhedron set = lhs_.Polyhedron(conjunction);
        meter_.Op(set, 2);
        if (!set.IsEmpty()) it->second.push_back(std::move(set));
      }
    }
    std::vector<const ConvexPolyhedron*> sets;
    for (const ConvexPolyhedron& bad : it->second) {
      meter_.Op(bad, states);
      sets.push_back(&bad);
    }
    for (const bool meets : states.IntersectsEach(sets)) met_[i] = met_[i] || meets;
  }
}

}  // namespace hybrid
