#pragma once

#include <algorithm>
#include <cmath>

#include "solvers/flowpipe/rounding.h"

namespace hybrid::flowpipe_internal {

/// A closed interval [lo, hi] with directed rounding that is tight where an operation is exact
/// (rounding.h; needs RoundingGuard). Unlike hybrid::Interval, which widens every result by an
/// ulp, [10, 10] + [-1, 0] is [9, 10]: an attained bound stays attained. Infinite bounds are
/// allowed; an empty interval is never made by arithmetic.
struct TightInterval {
  double lo = 0.0;
  double hi = 0.0;

  TightInterval() = default;
  explicit TightInterval(double x) : lo(x), hi(x) {}
  TightInterval(double l, double h) : lo(l), hi(h) {}
  static TightInterval Entire() { return {-kInf, kInf}; }

  bool IsFinite() const { return std::isfinite(lo) && std::isfinite(hi); }
  double Mid() const { return IsFinite() ? lo + (hi - lo) / 2 : 0.0; }
  /// An upper bound of the radius around Mid().
  double RadiusUp() const {
    const double m = Mid();
    return std::max(SubUp(hi, m), SubUp(m, lo));
  }
  double MagnitudeUp() const { return std::max(std::fabs(lo), std::fabs(hi)); }
  bool Contains(double x) const { return lo <= x && x <= hi; }
  bool Contains(const TightInterval& o) const { return lo <= o.lo && o.hi <= hi; }
  bool Meets(const TightInterval& o) const { return lo <= o.hi && o.lo <= hi; }
};

inline TightInterval operator+(const TightInterval& a, const TightInterval& b) {
  return {AddDown(a.lo, b.lo), AddUp(a.hi, b.hi)};
}
inline TightInterval operator-(const TightInterval& a) { return {-a.hi, -a.lo}; }
inline TightInterval operator-(const TightInterval& a, const TightInterval& b) {
  return {SubDown(a.lo, b.hi), SubUp(a.hi, b.lo)};
}
inline TightInterval operator*(const TightInterval& a, const TightInterval& b) {
  // 0 * inf is taken as 0 (an exact zero factor annihilates).
  auto down = [](double x, double y) { return x == 0 || y == 0 ? 0.0 : MulDown(x, y); };
  auto up = [](double x, double y) { return x == 0 || y == 0 ? 0.0 : MulUp(x, y); };
  return {std::min({down(a.lo, b.lo), down(a.lo, b.hi), down(a.hi, b.lo), down(a.hi, b.hi)}),
          std::max({up(a.lo, b.lo), up(a.lo, b.hi), up(a.hi, b.lo), up(a.hi, b.hi)})};
}
/// Entire() when b contains 0.
inline TightInterval operator/(const TightInterval& a, const TightInterval& b) {
  if (b.lo <= 0 && b.hi >= 0) return TightInterval::Entire();
  return {std::min(
              {DivDown(a.lo, b.lo), DivDown(a.lo, b.hi), DivDown(a.hi, b.lo), DivDown(a.hi, b.hi)}),
          std::max({DivUp(a.lo, b.lo), DivUp(a.lo, b.hi), DivUp(a.hi, b.lo), DivUp(a.hi, b.hi)})};
}
/// The interval hull.
inline TightInterval Hull(const TightInterval& a, const TightInterval& b) {
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}
/// a^n for n >= 0 (an even power is non-negative).
inline TightInterval Power(const TightInterval& a, int n) {
  if (n == 0) return TightInterval(1.0);
  if (n % 2 == 0) {
    const double m = std::max(std::fabs(a.lo), std::fabs(a.hi));
    const double l = a.lo <= 0 && a.hi >= 0 ? 0.0 : std::min(std::fabs(a.lo), std::fabs(a.hi));
    TightInterval lo(l), hi(m);
    TightInterval rl(1.0), rh(1.0);
    for (int i = 0; i < n; ++i) {
      rl = rl * lo;
      rh = rh * hi;
    }
    return {rl.lo, rh.hi};
  }
  TightInterval r = a;
  for (int i = 1; i < n; ++i) r = r * a;
  // An odd power is monotone: the ends' powers bound it.
  TightInterval l(a.lo), h(a.hi);
  for (int i = 1; i < n; ++i) {
    l = l * TightInterval(a.lo);
    h = h * TightInterval(a.hi);
  }
  return {std::max(r.lo, l.lo), std::min(r.hi, h.hi)};
}

}  // namespace hybrid::flowpipe_internal
