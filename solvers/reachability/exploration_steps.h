#pragma once

#include <optional>
#include <vector>

#include "solvers/reachability/convex_polyhedron.h"
#include "solvers/reachability/linear_hybrid_system.h"
#include "solvers/reachability/reach_meter.h"

namespace hybrid {

/// The bounding box of a symbolic state, each bound (ConvexPolyhedron::Bounds, within one ulp of
/// the true one) widened by one ulp either way: the true infimum of dimension i lies in
/// [lo_down[i], lo_up[i]], the true supremum in [hi_down[i], hi_up[i]].
struct Box {
  std::vector<double> lo_down, lo_up, hi_down, hi_up;
};

/// The Box of `set`.
Box BoxOf(const ConvexPolyhedron& set);

/// Whether `outer` may contain `inner` as far as their boxes tell: false only when it certainly
/// does not (a bound of `inner` beyond the same bound of `outer`).
bool MayContain(const Box& outer, const Box& inner);

/// Whether no point of `box` satisfies `guard`, as far as interval arithmetic on the box tells
/// with a relative margin of 1e-9 (false whenever in doubt): lets an exploration skip an edge
/// without a polyhedron operation.
bool CertainlyMisses(const Box& box, const std::vector<LinearConstraint>& guard);

/// The time-elapse successor of `set` in `loc`, kept inside its elapse invariant and `extra`
/// (none if null), charged to `meter`. `set` (entry states, inside the invariant) is reachable at
/// once; time elapses only from its states inside the elapse invariant (an urgent guard that holds
/// on entry fires at once). The result is the convex hull of both parts (exact when the entry
/// states all lie inside the elapse invariant, as usual; an over-approximation otherwise). Where
/// the elapse invariant is the invariant (no urgent guard stops time), `set` lies inside it and
/// inside its own time elapse, so neither is tested. Every state a run reaches from `set` by
/// letting time pass in `loc` lies in the result.
ConvexPolyhedron Flow(const LinearLocation& loc, ConvexPolyhedron set,
                      const ConvexPolyhedron* extra, ReachMeter& meter);

/// The states `set` (a copy, charged) reaches through `edge`: those inside its guard, after its
/// resets; nullopt if none is inside the guard.
std::optional<ConvexPolyhedron> Jump(const LinearEdge& edge, ConvexPolyhedron set,
                                     ReachMeter& meter);

/// The entry states of `target` that `set` (reached by a jump into it) gives: the dead
/// variables forgotten (Forgetting), inside the invariant; nullopt if none is.
std::optional<ConvexPolyhedron> Entering(const LinearLocation& target, ConvexPolyhedron set,
                                         ReachMeter& meter);

/// `set` (entry states of `loc`) with the values of the variables dead at `loc`
/// (LinearLocation::dead) forgotten.
ConvexPolyhedron Forgetting(const LinearLocation& loc, ConvexPolyhedron set, ReachMeter& meter);

}  // namespace hybrid
