#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace hybrid {

/// A linear constraint sum_i a[i] x_i + b REL 0 over dimensions x_0 .. x_{n-1}, REL one of <, <=
/// or ==. Coefficients are doubles read as the shortest decimal that gives them back (0.1 is
/// 1/10, as the model wrote it), then handled exactly as rationals.
struct LinearConstraint {
  enum class Kind { kLess, kLessEqual, kEqual };
  std::vector<double> a;
  double b = 0.0;
  Kind kind = Kind::kLessEqual;
};

/// An affine map of the dimensions: sum_i a[i] x_i + b.
struct AffineMap {
  std::vector<double> a;
  double b = 0.0;
};

/// A convex polyhedron of R^n with exact rational arithmetic, closed or not (strict
/// inequalities are kept strict): the Parma Polyhedra Library's C_Polyhedron while every
/// constraint it was given is non-strict, its NNC_Polyhedron from the first strict one (or from
/// an operation with a polyhedron that is one; the conversion is exact), behind a value type (its
/// handles never leave convex_polyhedron.cc). The kind changes the cost only (a closed polyhedron
/// has no epsilon dimension), never the set. Operations are the exact set operations named; none
/// approximates except Widen.
class ConvexPolyhedron {
 public:
  /// R^dims (dims >= 0).
  static ConvexPolyhedron Universe(int dims);
  /// The empty set of R^dims.
  static ConvexPolyhedron Empty(int dims);
  /// The one point {x} of R^x.size(), its coordinates read as LinearConstraint reads
  /// coefficients (throws std::invalid_argument for a non-finite one).
  static ConvexPolyhedron Point(std::span<const double> x);

  ConvexPolyhedron(const ConvexPolyhedron& other);
  ConvexPolyhedron& operator=(const ConvexPolyhedron& other);
  ConvexPolyhedron(ConvexPolyhedron&&) noexcept;
  ConvexPolyhedron& operator=(ConvexPolyhedron&&) noexcept;
  ~ConvexPolyhedron();

  int dims() const;
  /// Intersects with {x : c(x)}; c.a has dims() entries (throws std::invalid_argument otherwise,
  /// or for a non-finite coefficient).
  void AddConstraint(const LinearConstraint& c);
  void Intersect(const ConvexPolyhedron& other);
  bool IsEmpty() const;
  /// Whether other is a subset of this.
  bool Contains(const ConvexPolyhedron& other) const;
  /// Whether the two share a point.
  bool Intersects(const ConvexPolyhedron& other) const;
  /// Intersects(*others[k]) for each k (each of this set's dimension), with the same answers:
  /// where this set is closed, its generators are read once for all of them, and each relation
  /// test of a constraint against them is made in 128-bit integers where every coefficient of
  /// both is below 2^58 in magnitude (exact: each scalar product is below 2^126).
  std::vector<bool> IntersectsEach(std::span<const ConvexPolyhedron* const> others) const;
  /// {x + t r : x in this, r in rates, t >= 0}: the states reached by letting time elapse at any
  /// constant rate of `rates` (a polyhedron of derivatives, same dims).
  void TimeElapse(const ConvexPolyhedron& rates);
  /// {x - t r : x in this, r in rates, t >= 0}: the states from which letting time elapse at a
  /// constant rate of `rates` (same dims) reaches this set (TimeElapse with the rates negated).
  void TimeElapseBackward(const ConvexPolyhedron& rates);
  /// Assigns x_d := f_d(x) for every (d, f_d) of `maps` at once (each f_d reads the state before).
  void Assign(std::span<const std::pair<int, AffineMap>> maps);
  /// {x : Assign(maps) takes x into this}: the pre-image of this set under the simultaneous
  /// assignment, exactly (the old value of an overwritten dimension matters only where some
  /// f_d reads it). Throws std::invalid_argument if `maps` writes a dimension twice.
  void AssignPreimage(std::span<const std::pair<int, AffineMap>> maps);
  /// Forgets everything about dimension d (projects it out and back).
  void Unconstrain(int d);
  /// Adds `count` unconstrained dimensions after the existing ones.
  void AddDimensions(int count);
  /// Keeps the first `dims` dimensions (projection).
  void KeepDimensions(int dims);
  /// This set placed in R^dims: dimension i of this becomes dimension to[i] (distinct, each in
  /// [0, dims); to.size() == this->dims() <= dims, else std::invalid_argument), every other
  /// dimension unconstrained. Exact: {y in R^dims : (y[to[0]], ..., y[to[n-1]]) in this}.
  ConvexPolyhedron Embedded(int dims, std::span<const int> to) const;
  /// The convex hull of this and other.
  void Hull(const ConvexPolyhedron& other);
  /// The constraint hull of this and other (PHAVer's): the constraints of each (minimised; an
  /// equality as its two inequalities) that the other satisfies. It contains both (so their convex
  /// hull: an over-approximation of it, exact where one contains the other) and is made without the
  /// generators' conversion a convex hull needs; its constraints are among theirs, so their
  /// coefficients do not grow.
  void ConstraintHull(const ConvexPolyhedron& other);
  /// The H79 widening of this (which must contain `previous`) with respect to `previous`.
  void Widen(const ConvexPolyhedron& previous);
  /// The supremum of sum_i objective[i] x_i over this (objective has dims() entries), rounded to
  /// a double, or nullopt if this is empty or the objective is unbounded above. With `attained`,
  /// also whether some point of this reaches it (it may not, past a strict inequality).
  std::optional<double> Supremum(std::span<const double> objective, bool* attained = nullptr) const;
  /// Keeps only the points where the objective reaches its supremum over this, exactly, and
  /// returns true; returns false, leaving this unchanged, if this is empty, the objective is
  /// unbounded above, or no point reaches the supremum.
  bool RestrictToMaximum(std::span<const double> objective);
  /// One point of this (non-empty, else throws std::logic_error), exactly, as a one-point
  /// polyhedron: the barycentre of the points and closure points of its minimised generators
  /// plus the sum of its rays, each scaled to a largest coordinate of magnitude 1 (lines are
  /// ignored), which lies in the relative interior of this; replaced by that point rounded to
  /// doubles (read as Point reads them) when the rounded point lies in this too, so that
  /// coordinates stay short along a chain of choices.
  ConvexPolyhedron CentralPoint() const;
  /// Whether this is exactly one point.
  bool IsPoint() const;
  /// The coordinates of one point of this (of its only point when IsPoint()), rounded to
  /// doubles; throws std::logic_error if this is empty.
  std::vector<double> PointCoordinates() const;
  /// Per dimension, the infimum and supremum of x_i over this, each rounded to a double within
  /// one unit in the last place (-inf or +inf where it is unbounded), as (inf, sup) pairs; for an
  /// empty polyhedron, (+inf, -inf). A cheap necessary condition for Contains.
  std::vector<std::pair<double, double>> Bounds() const;
  /// Its minimised constraints, for messages and tests.
  std::vector<LinearConstraint> Constraints() const;
  /// Number of minimised constraints (a size measure).
  int NumConstraints() const;
  /// The bit length of the largest magnitude among the integer coefficients of its minimised
  /// constraints (each scaled to coprime integers, as PPL keeps them): a measure of how far its
  /// facets' coefficients have grown (hulls may lengthen them without end).
  std::size_t LargestCoefficientBits() const;
  /// The bytes its representation in PPL holds beyond the object itself, as it stands
  /// (constraints and generators as far as computed, their coefficients' digits, saturation
  /// matrices): what operations on it read, so a measure of their cost that grows with the
  /// number of constraints and generators, the dimension and the coefficients' length. It
  /// counts what is allocated (a copy, allocated to fit, may measure less than its original), so
  /// it depends on the operations that made this polyhedron (and on the PPL, GMP and C++ library
  /// builds), never on the machine's load or speed: reachability's deterministic budget charges
  /// it. Cheap (linear in the representation); it neither minimises nor converts anything.
  std::size_t RepresentationBytes() const;

 private:
  struct Impl;
  explicit ConvexPolyhedron(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Linear programming with exact rationals (PPL's MIP_Problem): maximises sum_i objective[i] x_i
/// over {x in R^dims : every constraint holds, strict ones read as non-strict}. Returns an
/// optimal point (a feasible one if the objective is unbounded), rounded to doubles, or nullopt
/// if there is none.
std::optional<std::vector<double>> MaximizeLinear(int dims,
                                                  std::span<const LinearConstraint> constraints,
                                                  std::span<const double> objective);

}  // namespace hybrid
