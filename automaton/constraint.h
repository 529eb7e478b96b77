#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "automaton/expression.h"

namespace hybrid {

/// Comparison operators of guards, invariants and predicates.
enum class Relation { kLess, kLessEqual, kGreater, kGreaterEqual, kEqual };

/// "<", "<=", ">", ">=", "==".
std::string_view RelationSpelling(Relation r);

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
  /// Whether the comparison holds at `env`, with boundary tolerance `tol` >= 0:
  /// `<=`: r <= tol; `<`: r < 0 (strict, so a state on the boundary does not satisfy it);
  /// `>=`: r >= -tol; `>`: r > 0; `==`: |r| <= tol.
  bool Holds(std::span<const double> env, double tol = 0.0) const;
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
