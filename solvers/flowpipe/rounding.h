#pragma once

#include <cfenv>
#include <cmath>
#include <cstddef>
#include <limits>

// Directed rounding for the flowpipe engine, tight where an operation is exact.
//
// Every function returns a bound of the exact real result of one IEEE operation: Up(...) >= the
// exact value, Down(...) <= it. The error of a sum is found exactly with Knuth's TwoSum and that of
// a product or a quotient with a fused multiply-add, which is exact in round-to-nearest (the
// engine runs under RoundingGuard); a result is moved one ulp outward only when the operation
// was inexact, so that 10 + 0 stays 10 and a bound that is attained exactly stays attained (a
// ball dropped from 10 m is proved to stay at or below 10, not below 10 + 2e-15). Near the
// underflow threshold, where the error of a product need not be representable, the result is
// moved outward unconditionally.

namespace hybrid::flowpipe_internal {

/// Sets round-to-nearest for its lifetime and restores the caller's mode: the error-free
/// transformations below need it, and the Parma Polyhedra Library switches the FPU to round
/// upward when it is loaded (docs/dependencies.md).
class RoundingGuard {
 public:
  RoundingGuard() : saved_(std::fegetround()) { std::fesetround(FE_TONEAREST); }
  ~RoundingGuard() { std::fesetround(saved_); }
  RoundingGuard(const RoundingGuard&) = delete;
  RoundingGuard& operator=(const RoundingGuard&) = delete;

 private:
  int saved_;
};

inline constexpr double kInf = std::numeric_limits<double>::infinity();
// Below this magnitude a product's rounding error may not be representable.
inline constexpr double kTiny = 1e-290;

inline double NextUp(double x) { return std::nextafter(x, kInf); }
inline double NextDown(double x) { return std::nextafter(x, -kInf); }

// The exact error of a + b = s + e (TwoSum; NaN or inf when the sum overflows).
inline double SumError(double a, double b, double s) {
  const double bb = s - a;
  return (a - (s - bb)) + (b - bb);
}

inline double AddUp(double a, double b) {
  const double s = a + b;
  if (std::isinf(s))
    return std::isinf(a) || std::isinf(b) || s > 0 ? s : -std::numeric_limits<double>::max();
  return SumError(a, b, s) > 0 ? NextUp(s) : s;
}
inline double AddDown(double a, double b) {
  const double s = a + b;
  if (std::isinf(s))
    return std::isinf(a) || std::isinf(b) || s < 0 ? s : std::numeric_limits<double>::max();
  return SumError(a, b, s) < 0 ? NextDown(s) : s;
}
inline double SubUp(double a, double b) { return AddUp(a, -b); }
inline double SubDown(double a, double b) { return AddDown(a, -b); }

inline double MulUp(double a, double b) {
  const double p = a * b;
  if (std::isinf(p) || std::isnan(p))
    return std::isnan(p)
               ? kInf
               : (p > 0 || std::isinf(a) || std::isinf(b) ? p
                                                          : -std::numeric_limits<double>::max());
  if (std::fabs(p) < kTiny && a != 0 && b != 0) return NextUp(p);
  return std::fma(a, b, -p) > 0 ? NextUp(p) : p;
}
inline double MulDown(double a, double b) {
  const double p = a * b;
  if (std::isinf(p) || std::isnan(p))
    return std::isnan(p)
               ? -kInf
               : (p < 0 || std::isinf(a) || std::isinf(b) ? p : std::numeric_limits<double>::max());
  if (std::fabs(p) < kTiny && a != 0 && b != 0) return NextDown(p);
  return std::fma(a, b, -p) < 0 ? NextDown(p) : p;
}

// a / b for b != 0: q exact when fma(q, b, -a) == 0; a/b > q iff (a - q b) / b > 0.
inline double DivUp(double a, double b) {
  const double q = a / b;
  if (!std::isfinite(q)) return std::isnan(q) ? kInf : q;
  if (std::fabs(q) < kTiny && a != 0) return NextUp(q);
  const double r = -std::fma(q, b, -a);  // a - q b, exactly
  return (r > 0) == (b > 0) && r != 0 ? NextUp(q) : q;
}
inline double DivDown(double a, double b) {
  const double q = a / b;
  if (!std::isfinite(q)) return std::isnan(q) ? -kInf : q;
  if (std::fabs(q) < kTiny && a != 0) return NextDown(q);
  const double r = -std::fma(q, b, -a);
  return (r < 0) == (b > 0) && r != 0 ? NextDown(q) : q;
}

// An upper bound of a sum of `terms` non-negative numbers from their sum `s` computed in
// round-to-nearest in any order: each addition errs by at most 2^-53 of its result, so the
// computed sum is within (terms - 1) 2^-53 / (1 - (terms - 1) 2^-53) of the exact one (Higham,
// Accuracy and Stability of Numerical Algorithms, 4.2); 2^-52 per term covers it for any
// realistic count, and one step up covers the rounding of this product.
inline double SumUp(double s, std::size_t terms) {
  if (s == 0 || !std::isfinite(s)) return s;
  return NextUp(s * (1.0 + static_cast<double>(terms + 1) * 0x1p-52)) + 1e-300;
}

// |a - b| rounded up.
inline double AbsDiffUp(double a, double b) { return a >= b ? SubUp(a, b) : SubUp(b, a); }

}  // namespace hybrid::flowpipe_internal
