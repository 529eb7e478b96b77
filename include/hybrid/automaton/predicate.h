#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/constraint.h"

namespace hybrid {

/// A Boolean state predicate, the body of a property: comparisons over variables (continuous and
/// discrete), `in MODE` atoms, `true`/`false`, combined with `not`, `and`, `or`.
/// Immutable and cheap to copy (the tree is shared).
class Predicate {
 public:
  enum class Kind { kTrue, kFalse, kComparison, kInMode, kNot, kAnd, kOr };

  /// `true`.
  Predicate();
  static Predicate True();
  static Predicate False();
  /// A comparison; throws std::invalid_argument if the predicate would be deeper than
  /// kMaxTreeDepth (as Not, And and Or do).
  static Predicate Compare(Comparison c);
  /// Holds exactly when the current mode is named `mode` (for a composed system, a qualified
  /// component mode such as `A.c000_l000`).
  static Predicate InMode(std::string mode);
  static Predicate Not(Predicate p);
  static Predicate And(Predicate a, Predicate b);
  static Predicate Or(Predicate a, Predicate b);

  Kind kind() const;
  /// Precondition kind() == kComparison.
  const Comparison& comparison() const;
  /// Precondition kind() == kInMode.
  const std::string& mode() const;
  /// Operands of kNot (one), kAnd and kOr (two).
  std::span<const Predicate> operands() const;
  /// Levels of the tree, counting the expressions of its comparisons: 1 for true, false and `in`
  /// atoms, 1 + the deeper side for a comparison, 1 + the deepest operand otherwise (at most
  /// kMaxTreeDepth). Every recursive walk of a predicate descends at most this deep. Constant time.
  int depth() const;

  /// Truth value at `env` when the current mode(s) are `modes` (names, as in InMode); comparisons
  /// use Comparison::Holds with tolerance `tol`.
  bool Evaluate(std::span<const double> env, std::span<const std::string> modes,
                double tol = 0.0) const;
  /// Truth value evaluated as leniently as `tol` >= 0 allows: a comparison in positive position
  /// holds when its residual lies in LenientBand(relation, tol), one under an odd number of
  /// `not`s when it lies in LenientBand(relation, -tol) (it must hold with margin tol). So
  /// !Lenient(...) means the predicate fails clearly, and a state where Lenient(Not(p), ...) is
  /// false satisfies p clearly. With tol = 0 this is Evaluate(env, modes). Replays of traces and
  /// the SMT encoding's counterexample search read predicates this way.
  bool Lenient(std::span<const double> env, std::span<const std::string> modes, double tol) const;
  /// Truth value as a witness state reads it, clear of rounding by `tol` >= 0: a non-strict
  /// comparison (`<=`, `>=`, `==`) holds within `tol` of its boundary, a strict one (`<`, `>`)
  /// only beyond `tol` from it (its boundary is excluded, so a state within rounding of it is no
  /// witness); `not` flips the truth value. So `reach x < 1` is not met at x = 1 - 1e-15, and
  /// `reach x >= 3` is met at x = 3 - 1e-12. With tol = 0 this is Evaluate(env, modes). Replays
  /// read `reach` targets this way (IsTarget).
  bool Witnessed(std::span<const double> env, std::span<const std::string> modes, double tol) const;
  /// Calls `f` on every comparison.
  void ForEachComparison(const std::function<void(const Comparison&)>& f) const;
  /// Calls `f` on every mode name of an `in` atom.
  void ForEachMode(const std::function<void(const std::string&)>& f) const;

  /// Fully parenthesised where needed: `not` binds tighter than `and`, `and` tighter than `or`.
  std::string ToString() const;
  friend bool operator==(const Predicate& a, const Predicate& b);

 private:
  struct Node;
  explicit Predicate(std::shared_ptr<const Node> node);
  std::shared_ptr<const Node> node_;
};

}  // namespace hybrid
