#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/expression.h"

namespace hybrid {

/// Comparison operators of guards, invariants and predicates.
enum class Relation { kLess, kLessEqual, kGreater, kGreaterEqual, kEqual };

/// "<", "<=", ">", ">=", "==".
std::string_view RelationSpelling(Relation r);

/// How a strict comparison (`<`, `>`) is read on its boundary.
enum class Boundary {
  /// Strict stays strict: `r < 0` excludes r = 0 and gets no tolerance.
  kExact,
  /// A strict comparison is read as its closure (`<` as `<=`, `>` as `>=`). Every engine reads
  /// invariants this way, and guards that a moving variable crosses (docs/model_language.md,
  /// "Guards, invariants and when transitions fire"); replays read property atoms this way.
  kClosure,
};

/// The set of residuals r for which `r REL 0` holds within the signed tolerance `tol`: an
/// interval of the real line with open or closed ends (an absent end is infinite).
///
/// This is the one definition of "a comparison holds within tolerance" in the project: the
/// simulator, the replay of traces, the SMT encoding and the sampler all read comparisons
/// through it (numerically with Contains, symbolically by encoding its ends). With tol >= 0 the
/// boundary band |r| <= tol counts as holding; with tol < 0 the comparison must hold with margin
/// -tol:
///   `<=`: r <= tol             `<`: r < min(tol, 0) (exact), r <= tol (closure)
///   `>=`: r >= -tol            `>`: r > max(-tol, 0) (exact), r >= -tol (closure)
///   `==`: -max(tol, 0) <= r <= max(tol, 0).
struct ResidualBand {
  std::optional<double> lower;  ///< absent: no lower end
  bool lower_strict = false;    ///< r > lower rather than r >= lower
  std::optional<double> upper;  ///< absent: no upper end
  bool upper_strict = false;    ///< r < upper rather than r <= upper

  /// The band of `relation` within `tol`, read with `boundary` (see the struct comment).
  static ResidualBand Of(Relation relation, double tol, Boundary boundary = Boundary::kExact);
  /// Whether r lies in the band (false for NaN).
  bool Contains(double r) const;
};

/// The band of a comparison evaluated leniently within the signed tolerance `tol` (a predicate's
/// atom in a replay or a counterexample search): strict comparisons read exactly when tol is 0,
/// in their closure otherwise (strictness is finer than the tolerance can resolve), i.e.
/// ResidualBand::Of(relation, tol, tol == 0 ? kExact : kClosure).
ResidualBand LenientBand(Relation relation, double tol);

/// Whether `r REL 0` holds within tolerance `tol`: ResidualBand::Of(relation, tol,
/// boundary).Contains(r).
bool ResidualHolds(Relation relation, double r, double tol, Boundary boundary = Boundary::kExact);

/// One comparison `lhs rel rhs`.
///
/// Its residual r = lhs - rhs is the function whose zero crossing locates the event: `<` and `<=`
/// become true when r falls through 0 (crossing direction -1), `>` and `>=` when r rises through 0
/// (direction +1), `==` at a crossing in either direction. The strict and non-strict forms cross
/// at the same instant; they differ only on the boundary itself (see Holds).
struct Comparison {
  Expression lhs;
  Relation relation = Relation::kLessEqual;
  Expression rhs;

  /// lhs - rhs.
  Expression Residual() const { return lhs - rhs; }
  /// Whether the comparison holds at `env` within tolerance `tol`, read with `boundary`:
  /// ResidualHolds(relation, lhs - rhs, tol, boundary). With tol >= 0 and kExact: `<=`:
  /// r <= tol; `<`: r < 0 (strict, so a state on the boundary does not satisfy it); `>=`:
  /// r >= -tol; `>`: r > 0; `==`: |r| <= tol.
  bool Holds(std::span<const double> env, double tol = 0.0,
             Boundary boundary = Boundary::kExact) const;
  /// The comparison with a strict relation replaced by its closure (`<` by `<=`, `>` by `>=`).
  Comparison Closure() const;
  std::string ToString() const;
  friend bool operator==(const Comparison&, const Comparison&) = default;
};

/// A conjunction of comparisons: the form of every guard and invariant. The empty conjunction is
/// `true`.
struct Constraint {
  std::vector<Comparison> comparisons;

  bool empty() const { return comparisons.empty(); }
  /// All comparisons hold (see Comparison::Holds); true when empty.
  bool Holds(std::span<const double> env, double tol = 0.0) const;
  /// `a and b and ...`, or `true` when empty.
  std::string ToString() const;
  friend bool operator==(const Constraint&, const Constraint&) = default;
};

}  // namespace hybrid
