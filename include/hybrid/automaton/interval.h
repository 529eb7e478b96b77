#pragma once

#include <string>

namespace hybrid {

/// A closed interval [lo, hi] of reals with outward-rounded arithmetic.
///
/// Every operation returns an interval that encloses the exact image of its operands: results are
/// widened by one ulp in each direction (std::nextafter), which over-covers any rounding error of
/// the IEEE operations used. An empty interval is never produced by arithmetic; operations with no
/// finite enclosure (division by an interval containing 0, log of a non-positive bound) return the
/// whole line [-inf, +inf] or a half line. `lo > hi` is a precondition violation (the constructor
/// throws std::invalid_argument).
class Interval {
 public:
  /// The degenerate interval [0, 0].
  Interval() = default;
  /// The degenerate interval [x, x].
  explicit Interval(double x);
  /// [lo, hi]; throws std::invalid_argument if lo > hi or either bound is NaN.
  Interval(double lo, double hi);

  double lo() const { return lo_; }
  double hi() const { return hi_; }
  double width() const { return hi_ - lo_; }
  double mid() const;
  /// True when lo <= x <= hi.
  bool Contains(double x) const { return lo_ <= x && x <= hi_; }
  /// True when this interval contains all of `other`.
  bool Contains(const Interval& other) const { return lo_ <= other.lo_ && other.hi_ <= hi_; }
  /// The whole real line.
  static Interval Entire();

  friend Interval operator+(const Interval& a, const Interval& b);
  friend Interval operator-(const Interval& a, const Interval& b);
  friend Interval operator*(const Interval& a, const Interval& b);
  /// Entire() when b contains 0 (a sound, if coarse, enclosure).
  friend Interval operator/(const Interval& a, const Interval& b);
  friend Interval operator-(const Interval& a);
  friend bool operator==(const Interval& a, const Interval& b) = default;

  std::string ToString() const;

 private:
  double lo_ = 0.0;
  double hi_ = 0.0;
};

/// Interval extensions of the elementary functions; each encloses the exact range of the function
/// over the argument (outward rounded).
Interval Pow(const Interval& base, const Interval& exponent);
Interval Sqrt(const Interval& x);
Interval Exp(const Interval& x);
Interval Log(const Interval& x);
Interval Sin(const Interval& x);
Interval Cos(const Interval& x);
Interval Tan(const Interval& x);
Interval Abs(const Interval& x);
Interval Min(const Interval& a, const Interval& b);
Interval Max(const Interval& a, const Interval& b);
Interval Atan2(const Interval& y, const Interval& x);

}  // namespace hybrid
