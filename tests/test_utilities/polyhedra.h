#pragma once

// Planar polyhedra written by hand (shared by the reachability tests).

#include <vector>

#include "solvers/reachability/convex_polyhedron.h"

namespace hybrid::testing {

/// The polyhedron of R^2 where every constraint a0 x + a1 y + b REL 0 holds.
inline ConvexPolyhedron Plane(const std::vector<LinearConstraint>& constraints) {
  ConvexPolyhedron p = ConvexPolyhedron::Universe(2);
  for (const LinearConstraint& c : constraints) p.AddConstraint(c);
  return p;
}

/// The rectangle [x0, x1] x [y0, y1].
inline ConvexPolyhedron Rectangle(double x0, double x1, double y0, double y1) {
  using Kind = LinearConstraint::Kind;
  return Plane({{{-1, 0}, x0, Kind::kLessEqual},
                {{1, 0}, -x1, Kind::kLessEqual},
                {{0, -1}, y0, Kind::kLessEqual},
                {{0, 1}, -y1, Kind::kLessEqual}});
}

/// Whether a and b are the same set.
inline bool SameSet(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  return a.Contains(b) && b.Contains(a);
}

}  // namespace hybrid::testing
