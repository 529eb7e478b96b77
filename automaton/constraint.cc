#include "hybrid/automaton/constraint.h"

#include <algorithm>
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

ResidualBand ResidualBand::Of(Relation relation, double tol, Boundary boundary) {
  const bool closure = boundary == Boundary::kClosure;
  ResidualBand band;
  switch (relation) {
    case Relation::kLess:
      band.upper = closure ? tol : std::min(tol, 0.0);
      band.upper_strict = !closure;
      break;
    case Relation::kLessEqual:
      band.upper = tol;
      break;
    case Relation::kGreater:
      band.lower = closure ? -tol : std::max(-tol, 0.0);
      band.lower_strict = !closure;
      break;
    case Relation::kGreaterEqual:
      band.lower = -tol;
      break;
    case Relation::kEqual:
      band.lower = -std::max(tol, 0.0);
      band.upper = std::max(tol, 0.0);
      break;
  }
  return band;
}

bool ResidualBand::Contains(double r) const {
  if (std::isnan(r)) return false;
  if (lower && (lower_strict ? !(r > *lower) : !(r >= *lower))) return false;
  if (upper && (upper_strict ? !(r < *upper) : !(r <= *upper))) return false;
  return true;
}

ResidualBand LenientBand(Relation relation, double tol) {
  return ResidualBand::Of(relation, tol, tol == 0.0 ? Boundary::kExact : Boundary::kClosure);
}

bool ResidualHolds(Relation relation, double r, double tol, Boundary boundary) {
  return ResidualBand::Of(relation, tol, boundary).Contains(r);
}

bool Comparison::Holds(std::span<const double> env, double tol, Boundary boundary) const {
  return ResidualHolds(relation, lhs.Evaluate(env) - rhs.Evaluate(env), tol, boundary);
}

Comparison Comparison::Closure() const {
  Comparison c = *this;
  if (c.relation == Relation::kLess) c.relation = Relation::kLessEqual;
  if (c.relation == Relation::kGreater) c.relation = Relation::kGreaterEqual;
  return c;
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
