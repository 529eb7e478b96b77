#include "solvers/flowpipe/crossing_form.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hybrid::flowpipe_internal {
namespace {

// The values r may take where `r REL 0` holds (closure: guards and invariants).
TightInterval RelationRange(Relation relation) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  switch (relation) {
    case Relation::kLess:
    case Relation::kLessEqual:
      return {-kInf, 0.0};
    case Relation::kGreater:
    case Relation::kGreaterEqual:
      return {0.0, kInf};
    case Relation::kEqual:
      return TightInterval(0.0);
  }
  return TightInterval::Entire();
}

TightInterval Meet(const TightInterval& a, const TightInterval& b) {
  return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)};
}

// Sum of the forms' radii, each relative to that of the same component of `reference`.
double RelativeSize(const std::vector<AffineForm>& forms,
                    const std::vector<AffineForm>& reference) {
  double sum = 0.0;
  for (std::size_t i = 0; i < forms.size(); ++i) {
    const double r = reference[i].RadiusUp();
    sum += r > 0 ? forms[i].RadiusUp() / r : 0.0;
  }
  return sum;
}

}  // namespace

std::optional<Segment> CrossingForm::Window(const Segment& segment,
                                            const std::vector<Residual>& atoms) const {
  constexpr int kWindowPieces = 32;  // a power of two: the pieces' ends are exact
  double lo = 0.0, hi = segment.h;
  for (int round = 0; round < 2; ++round) {
    const double piece = (hi - lo) / kWindowPieces;
    double first = hi, last = lo;
    for (int i = 0; i < kWindowPieces; ++i) {
      // Shared ends, the last one hi: the pieces cover [lo, hi] even if a sum were rounded.
      const double a = lo + i * piece, b = i + 1 == kWindowPieces ? hi : lo + (i + 1) * piece;
      if (model_.HoldsAll(atoms, segment.Restricted(a, b), env_) == Truth::kFalse) continue;
      first = std::min(first, a);
      last = b;
    }
    if (first >= last) return std::nullopt;
    lo = first;
    hi = last;
  }
  return segment.Restricted(lo, hi);
}

std::vector<AffineForm> CrossingForm::OfSegment(const Segment& segment, int& time_symbol) {
  std::size_t m = 0;
  for (const auto& coefficients : segment.series) {
    for (const AffineForm& f : coefficients) m = std::max(m, f.coefficients().size());
  }
  time_symbol = static_cast<int>(m);
  // Halving is exact: s = h/2 + (h/2) e covers [0, h] exactly.
  const AffineForm s = AffineForm::Symbol(segment.h / 2, time_symbol, segment.h / 2);
  const std::size_t n = segment.series[0].size();
  std::vector<AffineForm> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    AffineForm y = segment.series.back()[i];
    for (std::size_t k = segment.series.size() - 1; k-- > 0;) y = y * s + segment.series[k][i];
    out[i] = i < segment.remainder.size() ? y.PlusInterval(segment.remainder[i]) : y;
  }
  return out;
}

TightInterval CrossingForm::AtomRange(const std::vector<Residual>& atoms, std::size_t k,
                                      const std::vector<TightInterval>& box) const {
  TightInterval range = Meet(RelationRange(atoms[k].relation), model_.Value(atoms[k], box, env_));
  for (const Residual& other : atoms) {
    if (other.expression == atoms[k].expression) range = Meet(range, RelationRange(other.relation));
  }
  return range;
}

std::vector<AffineForm> CrossingForm::OnGuard(const std::vector<AffineForm>& y, int time_symbol,
                                              const std::vector<Residual>& atoms,
                                              const std::vector<TightInterval>& box) const {
  const auto m = static_cast<std::size_t>(time_symbol);
  std::vector<AffineForm> best = y;
  double best_size = RelativeSize(y, y);
  for (std::size_t k = 0; k < atoms.size(); ++k) {
    if (!atoms[k].affine) continue;
    const TightInterval rho = AtomRange(atoms, k, box);
    if (!rho.IsFinite() || rho.lo > rho.hi) continue;
    const AffineForm g = model_.FormValue(atoms[k], y, env_);
    const double gt = g.coefficient(m);
    if (gt == 0 || !std::isfinite(g.err())) continue;
    const TightInterval q = TightInterval(1.0) / TightInterval(gt);
    // e = -(g0 + gs.e_s) q + (rho + [-err, err]) q, the last term a fresh symbol in e's place.
    const TightInterval tail = (rho + TightInterval(-g.err(), g.err())) * q;
    if (!tail.IsFinite()) continue;
    const AffineForm e = g.WithoutSymbol(m).WithoutError().Scaled(-q) +
                         AffineForm::Symbol(tail.Mid(), time_symbol, tail.RadiusUp());
    std::vector<AffineForm> candidate(y.size());
    for (std::size_t i = 0; i < y.size(); ++i)
      candidate[i] = y[i].WithoutSymbol(m) + e.Scaled(y[i].coefficient(m));
    const double size = RelativeSize(candidate, y);
    if (size < best_size) {
      best = std::move(candidate);
      best_size = size;
    }
  }
  return best;
}

}  // namespace hybrid::flowpipe_internal
