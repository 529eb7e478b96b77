#include "hybrid/automaton/interval.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "hybrid/automaton/expression.h"  // FormatNumber

namespace hybrid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Widens [lo, hi] by one ulp on each side so that rounding in the caller's arithmetic is covered.
Interval Outward(double lo, double hi) {
  if (std::isnan(lo) || std::isnan(hi)) return Interval::Entire();
  return {std::nextafter(lo, -kInf), std::nextafter(hi, kInf)};
}

// Product that treats 0 * inf as 0, as interval multiplication requires.
double SafeMul(double a, double b) { return (a == 0.0 || b == 0.0) ? 0.0 : a * b; }

// Integer power by the C library; exact for small integers, within an ulp otherwise.
Interval IntegerPower(const Interval& x, int n) {
  if (n == 0) return Interval(1.0);
  if (n < 0) return Interval(1.0) / IntegerPower(x, -n);
  const double a = std::pow(x.lo(), n);
  const double b = std::pow(x.hi(), n);
  if (n % 2 == 1) return Outward(a, b);
  if (x.lo() >= 0.0) return Outward(a, b);
  if (x.hi() <= 0.0) return Outward(b, a);
  return Outward(0.0, std::max(a, b));
}

// True when some point c + 2*pi*k lies in [lo, hi].
bool ContainsPeriodicPoint(double lo, double hi, double c) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  // A generous test: including a spurious extremum only widens the result. The slack grows with
  // the magnitude of the bounds, since the rounding of c + 2*pi*k and the error of kTwoPi itself
  // reach several ulps of |lo| for large arguments (an absolute slack misses extrema there).
  const double slack = 1e-12 + 1e-14 * std::max(std::abs(lo), std::abs(hi));
  const double k = std::ceil((lo - slack - c) / kTwoPi);
  return c + kTwoPi * k <= hi + slack;
}

}  // namespace

Interval::Interval(double x) : lo_(x), hi_(x) {}

Interval::Interval(double lo, double hi) : lo_(lo), hi_(hi) {
  if (std::isnan(lo) || std::isnan(hi) || lo > hi) {
    throw std::invalid_argument("invalid interval [" + FormatNumber(lo) + ", " + FormatNumber(hi) +
                                "]: the lower bound must not exceed the upper one");
  }
}

double Interval::mid() const {
  if (std::isinf(lo_) || std::isinf(hi_))
    return std::isinf(lo_) && std::isinf(hi_) ? 0.0 : (std::isinf(lo_) ? hi_ : lo_);
  return lo_ + 0.5 * (hi_ - lo_);
}

Interval Interval::Entire() { return {-kInf, kInf}; }

Interval operator+(const Interval& a, const Interval& b) {
  return Outward(a.lo_ + b.lo_, a.hi_ + b.hi_);
}

Interval operator-(const Interval& a, const Interval& b) {
  return Outward(a.lo_ - b.hi_, a.hi_ - b.lo_);
}

Interval operator-(const Interval& a) { return {-a.hi_, -a.lo_}; }

Interval operator*(const Interval& a, const Interval& b) {
  const double p[4] = {SafeMul(a.lo_, b.lo_), SafeMul(a.lo_, b.hi_), SafeMul(a.hi_, b.lo_),
                       SafeMul(a.hi_, b.hi_)};
  return Outward(*std::min_element(p, p + 4), *std::max_element(p, p + 4));
}

Interval operator/(const Interval& a, const Interval& b) {
  if (b.Contains(0.0)) return Interval::Entire();
  const double q[4] = {a.lo_ / b.lo_, a.lo_ / b.hi_, a.hi_ / b.lo_, a.hi_ / b.hi_};
  return Outward(*std::min_element(q, q + 4), *std::max_element(q, q + 4));
}

std::string Interval::ToString() const {
  std::ostringstream out;
  out.precision(17);
  out << '[' << lo_ << ", " << hi_ << ']';
  return out.str();
}

Interval Pow(const Interval& base, const Interval& exponent) {
  if (exponent.lo() == exponent.hi() && std::nearbyint(exponent.lo()) == exponent.lo() &&
      std::abs(exponent.lo()) <= 1024) {
    return IntegerPower(base, static_cast<int>(exponent.lo()));
  }
  if (base.lo() > 0.0) return Exp(exponent * Log(base));
  return Interval::Entire();
}

Interval Sqrt(const Interval& x) {
  if (x.hi() < 0.0) return Interval::Entire();
  return Outward(std::max(0.0, std::sqrt(std::max(0.0, x.lo()))), std::sqrt(x.hi()));
}

Interval Exp(const Interval& x) {
  return Outward(std::max(0.0, std::exp(x.lo())), std::exp(x.hi()));
}

Interval Log(const Interval& x) {
  if (x.hi() <= 0.0) return Interval::Entire();
  return Outward(x.lo() <= 0.0 ? -kInf : std::log(x.lo()), std::log(x.hi()));
}

Interval Sin(const Interval& x) {
  if (!std::isfinite(x.lo()) || !std::isfinite(x.hi()) || x.width() >= 2.0 * std::numbers::pi) {
    return {-1.0, 1.0};
  }
  const double a = std::sin(x.lo());
  const double b = std::sin(x.hi());
  double lo = std::min(a, b);
  double hi = std::max(a, b);
  if (ContainsPeriodicPoint(x.lo(), x.hi(), std::numbers::pi / 2)) hi = 1.0;
  if (ContainsPeriodicPoint(x.lo(), x.hi(), -std::numbers::pi / 2)) lo = -1.0;
  const Interval r = Outward(lo, hi);
  return {std::max(-1.0, r.lo()), std::min(1.0, r.hi())};
}

Interval Cos(const Interval& x) {
  if (!std::isfinite(x.lo()) || !std::isfinite(x.hi()) || x.width() >= 2.0 * std::numbers::pi) {
    return {-1.0, 1.0};
  }
  const double a = std::cos(x.lo());
  const double b = std::cos(x.hi());
  double lo = std::min(a, b);
  double hi = std::max(a, b);
  if (ContainsPeriodicPoint(x.lo(), x.hi(), 0.0)) hi = 1.0;
  if (ContainsPeriodicPoint(x.lo(), x.hi(), std::numbers::pi)) lo = -1.0;
  const Interval r = Outward(lo, hi);
  return {std::max(-1.0, r.lo()), std::min(1.0, r.hi())};
}

Interval Tan(const Interval& x) {
  if (!std::isfinite(x.lo()) || !std::isfinite(x.hi()) || x.width() >= std::numbers::pi ||
      ContainsPeriodicPoint(x.lo(), x.hi(), std::numbers::pi / 2) ||
      ContainsPeriodicPoint(x.lo(), x.hi(), -std::numbers::pi / 2)) {
    return Interval::Entire();
  }
  return Outward(std::tan(x.lo()), std::tan(x.hi()));
}

Interval Abs(const Interval& x) {
  if (x.lo() >= 0.0) return x;
  if (x.hi() <= 0.0) return -x;
  return {0.0, std::max(-x.lo(), x.hi())};
}

Interval Min(const Interval& a, const Interval& b) {
  return {std::min(a.lo(), b.lo()), std::min(a.hi(), b.hi())};
}

Interval Max(const Interval& a, const Interval& b) {
  return {std::max(a.lo(), b.lo()), std::max(a.hi(), b.hi())};
}

Interval Atan2(const Interval& y, const Interval& x) {
  constexpr double kPi = std::numbers::pi;
  auto atan_of = [](const Interval& r) { return Outward(std::atan(r.lo()), std::atan(r.hi())); };
  if (x.lo() > 0.0) return atan_of(y / x);                       // right half plane
  if (y.lo() > 0.0) return Interval(kPi / 2) - atan_of(x / y);   // upper half plane
  if (y.hi() < 0.0) return Interval(-kPi / 2) - atan_of(x / y);  // lower half plane
  return Outward(-kPi, kPi);
}

}  // namespace hybrid
