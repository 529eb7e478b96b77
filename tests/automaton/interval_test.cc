#include "hybrid/automaton/interval.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "tests/test_utilities/random_models.h"

namespace hybrid {

// gtest printer (found by argument-dependent lookup), local to this test program.
[[maybe_unused]] static void PrintTo(const Interval& x, std::ostream* os) { *os << x.ToString(); }

namespace {

using ::hybrid::testing::GenInt;
using ::hybrid::testing::GenInterval;
using ::hybrid::testing::GenPointIn;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

double Up(double v) { return std::nextafter(v, kInf); }
double Down(double v) { return std::nextafter(v, -kInf); }

/// `r` encloses [lo, hi] and is at most `ulps` ulps wider on each side.
::testing::AssertionResult TightlyEncloses(const Interval& r, double lo, double hi, int ulps = 2) {
  double outer_lo = lo, outer_hi = hi;
  for (int i = 0; i < ulps; ++i) {
    outer_lo = Down(outer_lo);
    outer_hi = Up(outer_hi);
  }
  if (r.lo() <= lo && hi <= r.hi() && outer_lo <= r.lo() && r.hi() <= outer_hi) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << r.ToString() << " is not a tight enclosure of [" << lo << ", " << hi << "]";
}

// --- construction ----------------------------------------------------------------------------

TEST(IntervalTest, Construction) {
  EXPECT_EQ(Interval().lo(), 0.0);
  EXPECT_EQ(Interval().hi(), 0.0);
  EXPECT_EQ(Interval(2.5), Interval(2.5, 2.5));
  const Interval a(-1.0, 3.0);
  EXPECT_EQ(a.lo(), -1.0);
  EXPECT_EQ(a.hi(), 3.0);
  EXPECT_EQ(a.width(), 4.0);
  EXPECT_EQ(a.mid(), 1.0);
  EXPECT_TRUE(a.Contains(-1.0));
  EXPECT_TRUE(a.Contains(3.0));
  EXPECT_FALSE(a.Contains(3.0000001));
  EXPECT_FALSE(a.Contains(std::nan("")));
  EXPECT_TRUE(a.Contains(Interval(0.0, 3.0)));
  EXPECT_FALSE(a.Contains(Interval(0.0, 4.0)));
  EXPECT_EQ(Interval(-kInf, kInf), Interval::Entire());
  EXPECT_TRUE(Interval::Entire().Contains(kInf));
  EXPECT_EQ(Interval::Entire().mid(), 0.0);
  EXPECT_EQ(Interval(1.0, kInf).mid(), 1.0);
  EXPECT_EQ(Interval(1.0, 2.0).ToString(), "[1, 2]");
}

TEST(IntervalTest, InvalidBoundsThrow) {
  EXPECT_THROW(Interval(2.0, 1.0), std::invalid_argument);
  EXPECT_THROW(Interval(std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(Interval(0.0, std::nan("")), std::invalid_argument);
  EXPECT_THROW(Interval(kInf, -kInf), std::invalid_argument);
  EXPECT_NO_THROW(Interval(-kInf, -kInf));
  EXPECT_NO_THROW(Interval(-0.0, 0.0));
  EXPECT_NO_THROW(Interval(0.0, -0.0));  // -0 == 0
}

// --- arithmetic ------------------------------------------------------------------------------

TEST(IntervalTest, AdditionAndSubtraction) {
  EXPECT_TRUE(TightlyEncloses(Interval(1.0, 2.0) + Interval(3.0, 4.0), 4.0, 6.0));
  EXPECT_TRUE(TightlyEncloses(Interval(1.0, 2.0) - Interval(3.0, 4.0), -3.0, -1.0));
  EXPECT_TRUE(
      TightlyEncloses(Interval(0.1) + Interval(0.2), 0.30000000000000004, 0.30000000000000004));
  // 0.1 + 0.2 rounds up: the exact sum of the two doubles lies below the rounded one.
  EXPECT_LT((Interval(0.1) + Interval(0.2)).lo(), 0.1 + 0.2);
  EXPECT_EQ(-Interval(1.0, 2.0), Interval(-2.0, -1.0));
  EXPECT_EQ((Interval::Entire() + Interval(1.0)).hi(), kInf);
  EXPECT_EQ((Interval::Entire() - Interval::Entire()).lo(), -kInf);
}

TEST(IntervalTest, Multiplication) {
  EXPECT_TRUE(TightlyEncloses(Interval(2.0, 3.0) * Interval(4.0, 5.0), 8.0, 15.0));
  EXPECT_TRUE(TightlyEncloses(Interval(-1.0, 2.0) * Interval(-3.0, 4.0), -6.0, 8.0));
  EXPECT_TRUE(TightlyEncloses(Interval(-2.0, -1.0) * Interval(3.0, 4.0), -8.0, -3.0));
  EXPECT_TRUE(TightlyEncloses(Interval(-2.0, -1.0) * Interval(-4.0, -3.0), 3.0, 8.0));
  // 0 * inf counts as 0: [0, 0] * Entire is [0, 0], not NaN or Entire.
  EXPECT_TRUE(TightlyEncloses(Interval(0.0) * Interval::Entire(), 0.0, 0.0));
  EXPECT_EQ((Interval(1.0, 2.0) * Interval(1.0, kInf)).hi(), kInf);
}

TEST(IntervalTest, Division) {
  EXPECT_TRUE(TightlyEncloses(Interval(1.0, 2.0) / Interval(4.0, 8.0), 0.125, 0.5));
  EXPECT_TRUE(TightlyEncloses(Interval(-1.0, 2.0) / Interval(-4.0, -2.0), -1.0, 0.5));
  EXPECT_EQ(Interval(1.0, 2.0) / Interval(-1.0, 1.0), Interval::Entire());
  EXPECT_EQ(Interval(1.0, 2.0) / Interval(0.0, 1.0), Interval::Entire());
  EXPECT_EQ(Interval(1.0, 2.0) / Interval(-1.0, 0.0), Interval::Entire());
  EXPECT_EQ(Interval(0.0) / Interval(0.0), Interval::Entire());
  const Interval third = Interval(1.0) / Interval(3.0);
  EXPECT_TRUE(third.Contains(1.0 / 3.0));
  EXPECT_LT(third.lo(), third.hi());  // 1/3 is not a double: the enclosure has width
}

// --- elementary functions --------------------------------------------------------------------

TEST(IntervalTest, IntegerPowers) {
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-2.0, 3.0), Interval(2.0)), 0.0, 9.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-3.0, 2.0), Interval(2.0)), 0.0, 9.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-3.0, -2.0), Interval(2.0)), 4.0, 9.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(2.0, 3.0), Interval(2.0)), 4.0, 9.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-1.0, 2.0), Interval(4.0)), 0.0, 16.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-2.0, 3.0), Interval(3.0)), -8.0, 27.0));
  EXPECT_TRUE(TightlyEncloses(Pow(Interval(-3.0, -2.0), Interval(3.0)), -27.0, -8.0));
  EXPECT_EQ(Pow(Interval(-5.0, 7.0), Interval(0.0)), Interval(1.0));
  EXPECT_EQ(Pow(Interval::Entire(), Interval(0.0)), Interval(1.0));
  EXPECT_TRUE(Pow(Interval(2.0, 4.0), Interval(-2.0)).Contains(Interval(1.0 / 16.0, 0.25)));
  EXPECT_LE(Pow(Interval(2.0, 4.0), Interval(-2.0)).hi(), 0.25 + 1e-15);
  EXPECT_TRUE(Pow(Interval(-4.0, -2.0), Interval(-1.0)).Contains(Interval(-0.5, -0.25)));
  EXPECT_EQ(Pow(Interval(-1.0, 2.0), Interval(-1.0)), Interval::Entire());
  EXPECT_EQ(Pow(Interval(-1.0, 2.0), Interval(-2.0)), Interval::Entire());
  EXPECT_LE(Pow(Interval::Entire(), Interval(2.0)).lo(), 0.0);
  EXPECT_GE(Pow(Interval::Entire(), Interval(2.0)).lo(), -1e-300);
  EXPECT_EQ(Pow(Interval::Entire(), Interval(2.0)).hi(), kInf);
}

TEST(IntervalTest, RealPowers) {
  const Interval r = Pow(Interval(4.0, 9.0), Interval(0.5));
  EXPECT_TRUE(r.Contains(Interval(2.0, 3.0)));
  EXPECT_LT(r.width(), 1.0 + 1e-9);
  EXPECT_TRUE(Pow(Interval(2.0, 4.0), Interval(1.0, 2.0)).Contains(Interval(2.0, 16.0)));
  EXPECT_TRUE(Pow(Interval(0.5, 2.0), Interval(-1.0, 1.0)).Contains(Interval(0.5, 2.0)));
  // Bases reaching 0 or below with a non-integer exponent: no finite enclosure is attempted.
  EXPECT_EQ(Pow(Interval(-1.0, 4.0), Interval(0.5)), Interval::Entire());
  EXPECT_EQ(Pow(Interval(0.0, 4.0), Interval(1.5)), Interval::Entire());
  EXPECT_EQ(Pow(Interval(2.0), Interval(2.0, 3.0)).Contains(Interval(4.0, 8.0)), true);
}

TEST(IntervalTest, SqrtExpLog) {
  EXPECT_TRUE(TightlyEncloses(Sqrt(Interval(4.0, 9.0)), 2.0, 3.0));
  const Interval s = Sqrt(Interval(-1.0, 4.0));  // the defined part [0, 4]
  EXPECT_TRUE(s.Contains(Interval(0.0, 2.0)));
  EXPECT_LE(s.lo(), 0.0);
  EXPECT_GE(s.lo(), -1e-300);
  EXPECT_EQ(Sqrt(Interval(-2.0, -1.0)), Interval::Entire());
  EXPECT_TRUE(TightlyEncloses(Exp(Interval(0.0, 1.0)), 1.0, std::exp(1.0)));
  EXPECT_LE(Exp(Interval(-1000.0, 0.0)).lo(), 0.0);  // exp(-1000) underflows to 0
  EXPECT_GE(Exp(Interval(-1000.0, 0.0)).lo(), -1e-300);
  EXPECT_EQ(Exp(Interval(0.0, 1000.0)).hi(), kInf);
  EXPECT_TRUE(TightlyEncloses(Log(Interval(1.0, 8.0)), 0.0, std::log(8.0)));
  EXPECT_EQ(Log(Interval(0.0, 1.0)).lo(), -kInf);
  EXPECT_EQ(Log(Interval(-1.0, 1.0)).lo(), -kInf);
  EXPECT_LE(Log(Interval(-1.0, 1.0)).hi(), 1e-300);
  EXPECT_EQ(Log(Interval(-2.0, -1.0)), Interval::Entire());
  EXPECT_EQ(Log(Interval(-1.0, 0.0)), Interval::Entire());
}

TEST(IntervalTest, SinAndCosIncludeTheirExtrema) {
  EXPECT_EQ(Sin(Interval(1.0, 2.0)).hi(), 1.0);  // pi/2 inside
  EXPECT_TRUE(Sin(Interval(1.0, 2.0)).Contains(Interval(std::sin(1.0), 1.0)));
  EXPECT_EQ(Sin(Interval(4.0, 5.0)).lo(), -1.0);  // 3 pi/2 inside
  EXPECT_EQ(Sin(Interval(-2.0, -1.0)).lo(), -1.0);
  EXPECT_TRUE(TightlyEncloses(Sin(Interval(-1.0, 1.0)), std::sin(-1.0), std::sin(1.0)));
  EXPECT_TRUE(TightlyEncloses(Sin(Interval(2.0, 4.0)), std::sin(4.0), std::sin(2.0)));
  EXPECT_EQ(Sin(Interval(0.0, 7.0)), Interval(-1.0, 1.0));  // a whole period
  EXPECT_EQ(Sin(Interval::Entire()), Interval(-1.0, 1.0));
  EXPECT_EQ(Sin(Interval(0.0, kPi)).hi(), 1.0);
  EXPECT_EQ(Cos(Interval(-0.1, 0.1)).hi(), 1.0);
  EXPECT_EQ(Cos(Interval(3.0, 3.3)).lo(), -1.0);
  EXPECT_EQ(Cos(Interval(2.0 * kPi - 0.1, 2.0 * kPi + 0.1)).hi(), 1.0);
  EXPECT_TRUE(TightlyEncloses(Cos(Interval(0.5, 2.5)), std::cos(2.5), std::cos(0.5)));
  EXPECT_EQ(Cos(Interval(-10.0, 10.0)), Interval(-1.0, 1.0));
  EXPECT_EQ(Cos(Interval(0.0, kInf)), Interval(-1.0, 1.0));
  // Results never leave [-1, 1], even after outward rounding.
  EXPECT_GE(Sin(Interval(1.5, 1.6)).lo(), -1.0);
  EXPECT_LE(Sin(Interval(1.5, 1.6)).hi(), 1.0);
}

/// A double next to x0 + period * k (computed in extended precision) and the adjacent double on
/// the side of the exact point, so that [lo, hi] contains the exact point.
Interval AroundPeriodicPoint(long double x0, long double period, long long k) {
  const long double exact = x0 + period * static_cast<long double>(k);
  const double p = static_cast<double>(exact);
  return exact >= p ? Interval(p, Up(p)) : Interval(Down(p), p);
}

TEST(IntervalTest, ExtremaAndPolesOfLargeArgumentsAreFound) {
  // Regression: the test for an extremum inside [lo, hi] used an absolute slack of 1e-12, smaller
  // than the rounding of lo / 2pi for |lo| ~ 1e9, so Sin missed maxima and Tan missed poles (and
  // threw, since tan(lo) > tan(hi) across a pole).
  constexpr long double kPiL = std::numbers::pi_v<long double>;
  std::uint64_t state = 12345;
  for (int i = 0; i < 20000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const long long k = static_cast<long long>(state >> 34) - (1LL << 29);  // |k| < 5.4e8
    const Interval max_sin = AroundPeriodicPoint(kPiL / 2, 2 * kPiL, k);
    const Interval min_sin = AroundPeriodicPoint(-kPiL / 2, 2 * kPiL, k);
    const Interval max_cos = AroundPeriodicPoint(0, 2 * kPiL, k);
    const Interval min_cos = AroundPeriodicPoint(kPiL, 2 * kPiL, k);
    const Interval pole = AroundPeriodicPoint(kPiL / 2, kPiL, k);
    ASSERT_EQ(Sin(max_sin).hi(), 1.0) << "k = " << k << ", x = " << max_sin.ToString();
    ASSERT_EQ(Sin(min_sin).lo(), -1.0) << "k = " << k << ", x = " << min_sin.ToString();
    ASSERT_EQ(Cos(max_cos).hi(), 1.0) << "k = " << k << ", x = " << max_cos.ToString();
    ASSERT_EQ(Cos(min_cos).lo(), -1.0) << "k = " << k << ", x = " << min_cos.ToString();
    Interval t;
    ASSERT_NO_THROW(t = Tan(pole)) << "k = " << k << ", x = " << pole.ToString();
    ASSERT_EQ(t, Interval::Entire()) << "k = " << k << ", x = " << pole.ToString();
  }
}

TEST(IntervalTest, Tan) {
  EXPECT_TRUE(TightlyEncloses(Tan(Interval(-1.0, 1.0)), std::tan(-1.0), std::tan(1.0)));
  EXPECT_EQ(Tan(Interval(1.0, 2.0)), Interval::Entire());    // pole at pi/2
  EXPECT_EQ(Tan(Interval(-2.0, -1.0)), Interval::Entire());  // pole at -pi/2
  EXPECT_EQ(Tan(Interval(4.0, 5.0)), Interval::Entire());    // pole at 3 pi/2
  EXPECT_EQ(Tan(Interval(0.0, 3.2)), Interval::Entire());    // wider than pi
  EXPECT_TRUE(TightlyEncloses(Tan(Interval(2.0, 4.0)), std::tan(2.0), std::tan(4.0)));
  EXPECT_EQ(Tan(Interval(0.0, kInf)), Interval::Entire());
}

TEST(IntervalTest, AbsMinMax) {
  EXPECT_EQ(Abs(Interval(1.0, 2.0)), Interval(1.0, 2.0));
  EXPECT_EQ(Abs(Interval(-2.0, -1.0)), Interval(1.0, 2.0));
  EXPECT_EQ(Abs(Interval(-3.0, 2.0)), Interval(0.0, 3.0));
  EXPECT_EQ(Abs(Interval(-1.0, 5.0)), Interval(0.0, 5.0));
  EXPECT_EQ(Min(Interval(0.0, 4.0), Interval(1.0, 2.0)), Interval(0.0, 2.0));
  EXPECT_EQ(Max(Interval(0.0, 4.0), Interval(1.0, 2.0)), Interval(1.0, 4.0));
  EXPECT_EQ(Min(Interval(-kInf, 0.0), Interval(1.0, 2.0)), Interval(-kInf, 0.0));
}

TEST(IntervalTest, Atan2) {
  // Right half plane, upper and lower half planes, and the branch cut on the negative x axis.
  EXPECT_TRUE(Atan2(Interval(1.0), Interval(1.0)).Contains(kPi / 4));
  EXPECT_LT(Atan2(Interval(1.0), Interval(1.0)).width(), 1e-15);
  EXPECT_TRUE(Atan2(Interval(1.0), Interval(-1.0)).Contains(3 * kPi / 4));
  EXPECT_TRUE(Atan2(Interval(-1.0), Interval(-1.0)).Contains(-3 * kPi / 4));
  EXPECT_TRUE(Atan2(Interval(1.0, 2.0), Interval(-1.0, 1.0))
                  .Contains(Interval(std::atan2(1.0, 1.0), std::atan2(1.0, -1.0))));
  const Interval cut = Atan2(Interval(-1.0, 1.0), Interval(-1.0, -0.5));
  EXPECT_TRUE(cut.Contains(kPi));
  EXPECT_TRUE(cut.Contains(-kPi));
  EXPECT_TRUE(Atan2(Interval(0.0), Interval(0.0)).Contains(0.0));
  EXPECT_TRUE(Atan2(Interval(-2.0, -1.0), Interval(0.0)).Contains(-kPi / 2));
}

// --- enclosure properties --------------------------------------------------------------------

/// Checks `f_interval(x) ⊇ f(x_i)` for random points x_i of `x` with a finite value.
void CheckUnaryEnclosure(const std::function<Interval(const Interval&)>& f_interval,
                         const std::function<double(double)>& f, const Interval& x) {
  const Interval r = f_interval(x);
  for (int k = 0; k < 12; ++k) {
    const double p = *GenPointIn(x);
    const double v = f(p);
    if (!std::isfinite(v)) continue;
    RC_LOG() << "x = " << x.ToString() << ", p = " << p << ", f(p) = " << v
             << ", f(x) = " << r.ToString() << "\n";
    RC_ASSERT(r.Contains(v));
  }
}

void CheckBinaryEnclosure(
    const std::function<Interval(const Interval&, const Interval&)>& f_interval,
    const std::function<double(double, double)>& f, const Interval& a, const Interval& b) {
  const Interval r = f_interval(a, b);
  for (int k = 0; k < 12; ++k) {
    const double p = *GenPointIn(a);
    const double q = *GenPointIn(b);
    const double v = f(p, q);
    if (!std::isfinite(v)) continue;
    RC_LOG() << "a = " << a.ToString() << ", b = " << b.ToString() << ", p = " << p << ", q = " << q
             << ", f(p, q) = " << v << ", f(a, b) = " << r.ToString() << "\n";
    RC_ASSERT(r.Contains(v));
  }
}

/// An interval at the usual scales, or (for periodic functions) one of a few ulps around a
/// multiple of pi/2 of large magnitude, where extrema and poles are hardest to locate.
Interval GenArgument(bool periodic) {
  if (periodic && *GenInt(0, 2) == 0) {
    constexpr long double kPiL = std::numbers::pi_v<long double>;
    const long long k = *GenInt(-1000000000, 1000000000);
    const double p = static_cast<double>(kPiL / 2 * static_cast<long double>(k));
    double lo = p, hi = p;
    for (int i = *GenInt(0, 3); i > 0; --i) lo = Down(lo);
    for (int i = *GenInt(0, 3); i > 0; --i) hi = Up(hi);
    return Interval(lo, hi);
  }
  return *GenInterval(*rc::gen::element(1.0, 10.0, 1000.0, 1e8));
}

RC_GTEST_PROP(IntervalProperty, NegationEncloses, ()) {
  CheckUnaryEnclosure([](const Interval& x) { return -x; }, [](double v) { return -v; },
                      GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, SqrtEncloses, ()) {
  CheckUnaryEnclosure(
      Sqrt, [](double v) { return std::sqrt(v); }, GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, ExpEncloses, ()) {
  CheckUnaryEnclosure(
      Exp, [](double v) { return std::exp(v); }, GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, LogEncloses, ()) {
  CheckUnaryEnclosure(
      Log, [](double v) { return std::log(v); }, GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, SinEncloses, ()) {
  CheckUnaryEnclosure(
      Sin, [](double v) { return std::sin(v); }, GenArgument(true));
}
RC_GTEST_PROP(IntervalProperty, CosEncloses, ()) {
  CheckUnaryEnclosure(
      Cos, [](double v) { return std::cos(v); }, GenArgument(true));
}
RC_GTEST_PROP(IntervalProperty, TanEncloses, ()) {
  CheckUnaryEnclosure(
      Tan, [](double v) { return std::tan(v); }, GenArgument(true));
}
RC_GTEST_PROP(IntervalProperty, AbsEncloses, ()) {
  CheckUnaryEnclosure(
      Abs, [](double v) { return std::abs(v); }, GenArgument(false));
}

RC_GTEST_PROP(IntervalProperty, AdditionEncloses, ()) {
  CheckBinaryEnclosure(std::plus<Interval>(), std::plus<double>(), GenArgument(false),
                       GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, SubtractionEncloses, ()) {
  CheckBinaryEnclosure(std::minus<Interval>(), std::minus<double>(), GenArgument(false),
                       GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, MultiplicationEncloses, ()) {
  CheckBinaryEnclosure(std::multiplies<Interval>(), std::multiplies<double>(), GenArgument(false),
                       GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, DivisionEncloses, ()) {
  CheckBinaryEnclosure(std::divides<Interval>(), std::divides<double>(), GenArgument(false),
                       GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, MinEncloses, ()) {
  CheckBinaryEnclosure(
      Min, [](double a, double b) { return std::min(a, b); }, GenArgument(false),
      GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, MaxEncloses, ()) {
  CheckBinaryEnclosure(
      Max, [](double a, double b) { return std::max(a, b); }, GenArgument(false),
      GenArgument(false));
}
RC_GTEST_PROP(IntervalProperty, Atan2Encloses, ()) {
  CheckBinaryEnclosure(
      Atan2, [](double a, double b) { return std::atan2(a, b); }, GenArgument(false),
      GenArgument(false));
}

RC_GTEST_PROP(IntervalProperty, PowEncloses, ()) {
  const Interval base = *GenInterval(*rc::gen::element(1.0, 3.0, 10.0));
  Interval exponent;
  switch (*GenInt(0, 3)) {
    case 0:
      exponent = Interval(*GenInt(-6, 7));
      break;  // integer: any base
    case 1:
      exponent = Interval(*rc::gen::element(0.5, -0.5, 1.5, 2.25, 1e-3));
      break;
    default:
      exponent = *GenInterval(3.0);
      break;
  }
  CheckBinaryEnclosure(
      Pow, [](double a, double b) { return std::pow(a, b); }, base, exponent);
}

/// Monotone and bilinear operations attain their extremes at the endpoints: their enclosures
/// must be no wider than the endpoint values plus rounding (so Entire is not an answer).
RC_GTEST_PROP(IntervalProperty, ArithmeticIsTight, ()) {
  const Interval a = *GenInterval(10.0);
  const Interval b = *GenInterval(10.0);
  const auto check = [](const Interval& r, std::vector<double> values) {
    const double lo = *std::min_element(values.begin(), values.end());
    const double hi = *std::max_element(values.begin(), values.end());
    const double slack = 1e-12 * std::max({1e-300, std::abs(lo), std::abs(hi)});
    RC_LOG() << r.ToString() << " vs [" << lo << ", " << hi << "]\n";
    RC_ASSERT(r.lo() <= lo);
    RC_ASSERT(r.hi() >= hi);
    RC_ASSERT(r.lo() >= lo - slack);
    RC_ASSERT(r.hi() <= hi + slack);
  };
  const auto corners = [&](const std::function<double(double, double)>& f) {
    return std::vector<double>{f(a.lo(), b.lo()), f(a.lo(), b.hi()), f(a.hi(), b.lo()),
                               f(a.hi(), b.hi())};
  };
  check(a + b, corners(std::plus<double>()));
  check(a - b, corners(std::minus<double>()));
  check(a * b, corners(std::multiplies<double>()));
  if (!b.Contains(0.0)) check(a / b, corners(std::divides<double>()));
  check(Exp(a), {std::exp(a.lo()), std::exp(a.hi())});
  if (a.lo() > 0.0) check(Log(a), {std::log(a.lo()), std::log(a.hi())});
  if (a.lo() >= 0.0) check(Sqrt(a), {std::sqrt(a.lo()), std::sqrt(a.hi())});
  check(Min(a, b), corners([](double p, double q) { return std::min(p, q); }));
  check(Max(a, b), corners([](double p, double q) { return std::max(p, q); }));
}

}  // namespace
}  // namespace hybrid
