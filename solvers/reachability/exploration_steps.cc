#include "solvers/reachability/exploration_steps.h"

#include <algorithm>
#include <cmath>

namespace hybrid {

Box BoxOf(const ConvexPolyhedron& set) {
  Box box;
  for (const auto& [lo, hi] : set.Bounds()) {
    box.lo_down.push_back(std::nextafter(lo, -INFINITY));
    box.lo_up.push_back(std::nextafter(lo, INFINITY));
    box.hi_down.push_back(std::nextafter(hi, -INFINITY));
    box.hi_up.push_back(std::nextafter(hi, INFINITY));
  }
  return box;
}

bool MayContain(const Box& outer, const Box& inner) {
  for (size_t i = 0; i < outer.lo_down.size(); ++i) {
    if (outer.lo_down[i] > inner.lo_up[i] || outer.hi_up[i] < inner.hi_down[i]) return false;
  }
  return true;
}

bool CertainlyMisses(const Box& box, const std::vector<LinearConstraint>& guard) {
  for (const LinearConstraint& c : guard) {
    double lo = c.b, hi = c.b, scale = std::abs(c.b);
    for (size_t i = 0; i < c.a.size(); ++i) {
      const double a = c.a[i];
      if (a == 0.0) continue;
      const double from = a > 0 ? box.lo_down[i] : box.hi_up[i];
      const double to = a > 0 ? box.hi_up[i] : box.lo_down[i];
      lo += a * from;
      hi += a * to;
      scale += std::abs(a) * std::max(std::abs(from), std::abs(to));
    }
    if (!std::isfinite(scale)) continue;
    const double margin = 1e-9 * (1.0 + scale);
    if (lo > margin) return true;  // c.a x + c.b > 0 on the whole box
    if (c.kind == LinearConstraint::Kind::kEqual && hi < -margin) return true;
  }
  return false;
}

ConvexPolyhedron Flow(const LinearLocation& loc, ConvexPolyhedron set,
                      const ConvexPolyhedron* extra, ReachMeter& meter) {
  if (extra) {
    set.Intersect(*extra);
    meter.Op(set, 2);
    if (set.IsEmpty()) return set;
  }
  if (loc.elapse_invariant.size() == loc.invariant.size()) {
    set.TimeElapse(loc.rates);
    if (!loc.invariant.empty()) set.Intersect(loc.invariant_set);
    if (extra) set.Intersect(*extra);
    meter.Op(set, 3);
    return set;
  }
  ConvexPolyhedron flowing = set;
  flowing.Intersect(loc.elapse_set);
  meter.Op(flowing, 3);
  if (flowing.IsEmpty()) return set;
  flowing.TimeElapse(loc.rates);
  flowing.Intersect(loc.elapse_set);
  if (extra) flowing.Intersect(*extra);
  meter.Op(flowing, 3);
  if (!flowing.Contains(set)) flowing.Hull(set);
  meter.Op(flowing, set);
  meter.Op(flowing);
  return flowing;
}

ConvexPolyhedron Forgetting(const LinearLocation& loc, ConvexPolyhedron set, ReachMeter& meter) {
  for (const int d : loc.dead) set.Unconstrain(d);
  if (!loc.dead.empty()) meter.Op(set, loc.dead.size());
  return set;
}

std::optional<ConvexPolyhedron> Jump(const LinearEdge& edge, ConvexPolyhedron set,
                                     ReachMeter& meter) {
  meter.Op(set);
  if (!edge.guard.empty()) {
    set.Intersect(edge.guard_set);
    meter.Op(set, 2);
    if (set.IsEmpty()) return std::nullopt;
  }
  set.Assign(edge.resets);
  if (!edge.resets.empty()) meter.Op(set);
  return set;
}

std::optional<ConvexPolyhedron> Entering(const LinearLocation& target, ConvexPolyhedron set,
                                         ReachMeter& meter) {
  set = Forgetting(target, std::move(set), meter);
  if (!target.invariant.empty()) {  // else every state (and `set` is not empty)
    meter.Op(target.invariant_set, set);
    // Already inside it (a reset into it): no constraint to add, no conversion to make.
    if (target.invariant_set.Contains(set)) {
      if (set.IsEmpty()) return std::nullopt;
      return set;
    }
    set.Intersect(target.invariant_set);
    meter.Op(set, 2);
    if (set.IsEmpty()) return std::nullopt;
  }
  return set;
}

}  // namespace hybrid
