#include "solvers/flowpipe/segment.h"

#include <algorithm>
#include <cmath>

namespace hybrid::flowpipe_internal {

TightInterval Segment::LinearBound(const std::vector<double>& a) const {
  if (series.empty()) {
    TightInterval sum(0.0);
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] != 0) sum = sum + TightInterval(a[i]) * box[i];
    }
    return sum;
  }
  TightInterval sum(0.0);
  double hk = 1.0;  // h^k, exact for the steps the engine takes (powers of two)
  for (std::size_t k = 0; k < series.size(); ++k) {
    AffineForm combination(0.0);
    bool any = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] == 0) continue;
      combination = any ? combination + series[k][i].Scaled(a[i]) : series[k][i].Scaled(a[i]);
      any = true;
    }
    const TightInterval range = combination.Range();
    if (k == 0) {
      sum = range;
    } else {
      // s^k for s in [0, h] is [0, h^k].
      sum = sum + TightInterval(0.0, MulUp(hk, 1.0)) * range;
    }
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
    if (i < apriori.size()) b = {std::max(b.lo, apriori[i].lo), std::min(b.hi, apriori[i].hi)};
    if (b.lo > b.hi) b = i < apriori.size() ? apriori[i] : b;  // cannot happen for sound bounds
    box[i] = b;
  }
}

}  // namespace hybrid::flowpipe_internal
