#include "solvers/flowpipe/segment.h"

#include <algorithm>
#include <cmath>

#include "automaton/internal_assert.h"

namespace hybrid::flowpipe_internal {

namespace {

// An enclosure of sum_i a[i] forms[i] over the symbols' box: the centre and the coefficients of
// the combination are accumulated with their exact rounding errors (fma, TwoSum), whose sum joins
// the error terms; the radius is a sum of non-negative terms bounded by SumUp.
TightInterval CombinationRange(const std::vector<AffineForm>& forms, const std::vector<double>& a,
                               std::vector<double>& g) {
  std::size_t m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] != 0) m = std::max(m, forms[i].coefficients().size());
  }
  g.assign(m, 0.0);
  double c = 0.0, error = 0.0;
  std::size_t terms = 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == 0) continue;
    const AffineForm& f = forms[i];
    const double p = a[i] * f.center();
    const double s = c + p;
    error += std::fabs(std::fma(a[i], f.center(), -p)) + std::fabs(SumError(c, p, s));
    c = s;
    const std::vector<double>& fg = f.coefficients();
    for (std::size_t k = 0; k < fg.size(); ++k) {
      if (fg[k] == 0) continue;
      const double q = a[i] * fg[k];
      const double t = g[k] + q;
      error += std::fabs(std::fma(a[i], fg[k], -q)) + std::fabs(SumError(g[k], q, t));
      g[k] = t;
      terms += 2;
    }
    error += std::fabs(a[i]) * f.err();
    terms += 3;
  }
  if (!std::isfinite(c) || !std::isfinite(error)) return TightInterval::Entire();
  double r = error;
  for (double v : g) r += std::fabs(v);
  r = SumUp(r, terms + m);
  return {SubDown(c, r), AddUp(c, r)};
}

}  // namespace

TightInterval Segment::LinearBound(const std::vector<double>& a) const {
  if (series.empty()) {
    TightInterval sum(0.0);
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] != 0) sum = sum + TightInterval(a[i]) * box[i];
    }
    return sum;
  }
  std::vector<double> scratch;
  TightInterval sum(0.0);
  double hk = 1.0;  // h^k rounded up (exact for the powers of two the engine uses)
  for (std::size_t k = 0; k < series.size(); ++k) {
    const TightInterval range = CombinationRange(series[k], a, scratch);
    // s^k for s in [0, h] is [0, h^k].
    sum = k == 0 ? range : sum + TightInterval(0.0, hk) * range;
    hk = MulUp(hk, h);
  }
  for (std::size_t i = 0; i < a.size() && i < remainder.size(); ++i) {
    if (a[i] != 0) sum = sum + TightInterval(a[i]) * remainder[i];
  }
  return sum;
}

void Segment::ComputeBox(const std::vector<TightInterval>& apriori) {
  const std::size_t n = series.empty() ? box.size() : series[0].size();
  box.assign(n, TightInterval::Entire());
  std::vector<double> unit(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    unit[i] = 1.0;
    TightInterval b = LinearBound(unit);
    unit[i] = 0.0;
    // Both enclose the same states, so they meet (up to the outward rounding of each).
    if (i < apriori.size()) b = {std::max(b.lo, apriori[i].lo), std::min(b.hi, apriori[i].hi)};
    box[i] = b;
  }
}

Segment Segment::Restricted(double lo, double hi) const {
  HYBRID_ASSERT(0 <= lo && lo <= hi && hi <= h && (hi - lo) + lo == hi,
                "a restriction lies within the segment and its length is exact");
  Segment out;
  out.h = hi - lo;
  out.remainder = remainder;
  const std::size_t order = series.size();
  out.series.resize(order);
  for (std::size_t j = 0; j < order; ++j) {
    out.series[j] = series[j];
    if (lo == 0) continue;
    double binomial = 1.0;  // C(k, j), exact for the orders used
    for (std::size_t k = j + 1; k < order; ++k) {
      binomial = binomial * static_cast<double>(k) / static_cast<double>(k - j);
      const TightInterval factor =
          TightInterval(binomial) * Power(TightInterval(lo), static_cast<int>(k - j));
      for (std::size_t i = 0; i < series[k].size(); ++i)
        out.series[j][i] = out.series[j][i] + series[k][i].Scaled(factor);
    }
  }
  out.ComputeBox(box);
  return out;
}

}  // namespace hybrid::flowpipe_internal
