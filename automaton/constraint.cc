#include "automaton/constraint.h"

#include <cmath>

namespace hybrid {

std::string_view RelationSpelling(Relation r) {
  switch (r) {
    case Relation::kLess:
      return "<";
    case Relation::kLessEqual:
      return "<=";
    case Relation::kGreater:
      return ">";
    case Relation::kGreaterEqual:
      return ">=";
    case Relation::kEqual:
      return "==";
  }
  return "?";
}

bool Comparison::Holds(std::span<const double> env, double tol) const {
  const double r = lhs.Evaluate(env) - rhs.Evaluate(env);
  switch (relation) {
    case Relation::kLess:
      return r < 0.0;
    case Relation::kLessEqual:
      return r <= tol;
    case Relation::kGreater:
      return r > 0.0;
    case Relation::kGreaterEqual:
      return r >= -tol;
    case Relation::kEqual:
      return std::abs(r) <= tol;
  }
  return false;
}

std::string Comparison::ToString() const {
  return lhs.ToString() + " " + std::string(RelationSpelling(relation)) + " " + rhs.ToString();
}

bool Constraint::Holds(std::span<const double> env, double tol) const {
  for (const Comparison& c : comparisons) {
    if (!c.Holds(env, tol)) return false;
  }
  return true;
}

std::string Constraint::ToString() const {
  if (comparisons.empty()) return "true";
  std::string out;
  for (size_t i = 0; i < comparisons.size(); ++i) {
    if (i > 0) out += " and ";
    out += comparisons[i].ToString();
  }
  return out;
}

}  // namespace hybrid
