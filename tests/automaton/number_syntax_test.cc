// Tests of the one decimal number syntax of the command line (automaton/number_syntax.h):
// hand-written texts and values, every refused form with its error and the offset of the first
// character that does not fit, integer ranges at the limits of int64 and uint64, and a property:
// the shortest text of any finite double reads back to the same double.

#include "automaton/number_syntax.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace hybrid {
namespace {

TEST(ReadDecimal, ReadsTheDecimalForms) {
  struct Case {
    const char* text;
    double value;
  };
  for (const Case& c :
       std::vector<Case>{{"0", 0.0},      {"7", 7.0},
                         {"+7", 7.0},     {"-7", -7.0},
                         {"007", 7.0},    {"1.5", 1.5},
                         {"-1.5", -1.5},  {"5.", 5.0},
                         {".5", 0.5},     {"-.5", -0.5},
                         {"+.5", 0.5},    {"1e3", 1000.0},
                         {"1E3", 1000.0}, {"1e+3", 1000.0},
                         {"1e-3", 0.001}, {"2.5e-1", 0.25},
                         {".5e1", 5.0},   {"5.e1", 50.0},
                         {"0.1", 0.1},    {"1e-310", 1e-310},  // subnormal
                         {"0e-999", 0.0}, {"1.7976931348623157e308", 1.7976931348623157e308}}) {
    const NumberRead<double> r = ReadDecimal(c.text);
    EXPECT_TRUE(r.ok()) << c.text << ": error " << static_cast<int>(r.error);
    EXPECT_EQ(r.value, c.value) << c.text;
  }
  EXPECT_TRUE(std::signbit(ReadDecimal("-0").value));
  EXPECT_FALSE(std::signbit(ReadDecimal("+0").value));
}

TEST(ReadDecimal, RefusesEverythingElseSayingWhere) {
  struct Case {
    const char* text;
    NumberError error;
    std::size_t stop;  // checked for kSyntax
  };
  for (const Case& c : std::vector<Case>{
           {"", NumberError::kEmpty, 0},
           {"+", NumberError::kSyntax, 1},
           {"-", NumberError::kSyntax, 1},
           {".", NumberError::kSyntax, 1},
           {"+-1", NumberError::kSyntax, 1},
           {"-+1", NumberError::kSyntax, 1},
           {"--1", NumberError::kSyntax, 1},
           {"++1", NumberError::kSyntax, 1},
           {"0x10", NumberError::kSyntax, 1},
           {"0X1p3", NumberError::kSyntax, 1},
           {"inf", NumberError::kSyntax, 0},
           {"-inf", NumberError::kSyntax, 1},
           {"nan", NumberError::kSyntax, 0},
           {"infinity", NumberError::kSyntax, 0},
           {" 1", NumberError::kSyntax, 0},
           {"1 ", NumberError::kSyntax, 1},
           {"1,5", NumberError::kSyntax, 1},
           {"1.2.3", NumberError::kSyntax, 3},
           {"1e", NumberError::kSyntax, 2},
           {"1e+", NumberError::kSyntax, 3},
           {"1e1.5", NumberError::kSyntax, 3},
           {"1x", NumberError::kSyntax, 1},
           {"- 1", NumberError::kSyntax, 1},
           {"e5", NumberError::kSyntax, 0},
           {"1_000", NumberError::kSyntax, 1},
           {"1e999", NumberError::kOverflow, 0},
           {"-1e999", NumberError::kOverflow, 0},
           {"1.7976931348623159e308", NumberError::kOverflow, 0},
           {"1e-999", NumberError::kUnderflow, 0},
           {"-2e-324", NumberError::kUnderflow, 0},
           {"0.0000001e-320", NumberError::kUnderflow, 0},
       }) {
    const NumberRead<double> r = ReadDecimal(c.text);
    EXPECT_EQ(r.error, c.error) << "'" << c.text << "'";
    if (c.error == NumberError::kSyntax) {
      EXPECT_EQ(r.stop, c.stop) << "'" << c.text << "'";
    }
  }
  EXPECT_EQ(ReadDecimal("100000e-330").error, NumberError::kUnderflow);  // 1e-325
  EXPECT_TRUE(ReadDecimal("100000e-328").ok());                          // 1e-323, subnormal
  EXPECT_EQ(ReadDecimal("0.01e311").error, NumberError::kOverflow);      // 1e309
  EXPECT_TRUE(ReadDecimal("0.001e311").ok());                            // 1e308
}

TEST(ReadInteger, ReadsSignedIntegersWithinBounds) {
  constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(ReadInteger("42", 0, 100).value, 42);
  EXPECT_EQ(ReadInteger("+42", 0, 100).value, 42);
  EXPECT_EQ(ReadInteger("-42", -100, 100).value, -42);
  EXPECT_EQ(ReadInteger("010", 0, 100).value, 10);  // decimal, not octal
  EXPECT_EQ(ReadInteger("-0", 0, 100).value, 0);
  EXPECT_EQ(ReadInteger("9223372036854775807", kMin, kMax).value, kMax);
  EXPECT_EQ(ReadInteger("-9223372036854775808", kMin, kMax).value, kMin);
  EXPECT_EQ(ReadInteger("9223372036854775808", kMin, kMax).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadInteger("-9223372036854775809", kMin, kMax).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadInteger("99999999999999999999999", kMin, kMax).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadInteger("101", 0, 100).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadInteger("-101", -100, 100).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadInteger("-1", 0, 100).error, NumberError::kNegative);
  EXPECT_EQ(ReadInteger("-99999999999999999999999", 0, 100).error, NumberError::kNegative);
  EXPECT_EQ(ReadInteger("", 0, 100).error, NumberError::kEmpty);
  EXPECT_EQ(ReadInteger("1.5", 0, 100).error, NumberError::kNotInteger);
  EXPECT_EQ(ReadInteger("1.", 0, 100).error, NumberError::kNotInteger);
  EXPECT_EQ(ReadInteger("1e3", 0, 10000).error, NumberError::kNotInteger);
  EXPECT_EQ(ReadInteger("0x10", 0, 100).error, NumberError::kSyntax);
  EXPECT_EQ(ReadInteger("+-1", -100, 100).error, NumberError::kSyntax);
  EXPECT_EQ(ReadInteger("1 ", 0, 100).error, NumberError::kSyntax);
}

TEST(ReadUnsigned, RefusesNegativeValuesInsteadOfWrappingThem) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(ReadUnsigned("18446744073709551615", kMax).value, kMax);
  EXPECT_EQ(ReadUnsigned("+5", kMax).value, 5u);
  EXPECT_EQ(ReadUnsigned("-0", kMax).value, 0u);
  EXPECT_TRUE(ReadUnsigned("-0", kMax).ok());
  EXPECT_EQ(ReadUnsigned("-1", kMax).error, NumberError::kNegative);
  EXPECT_EQ(ReadUnsigned("-18446744073709551616", kMax).error, NumberError::kNegative);
  EXPECT_EQ(ReadUnsigned("18446744073709551616", kMax).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadUnsigned("256", 255).error, NumberError::kOutOfBounds);
  EXPECT_EQ(ReadUnsigned("", kMax).error, NumberError::kEmpty);
  EXPECT_EQ(ReadUnsigned("0x1", kMax).error, NumberError::kSyntax);
  EXPECT_EQ(ReadUnsigned("1e2", kMax).error, NumberError::kNotInteger);
}

TEST(NumberErrorMessage, SaysWhatIsWrongWithTheText) {
  EXPECT_EQ(NumberErrorMessage("", NumberError::kEmpty), "empty: a number is required");
  EXPECT_EQ(NumberErrorMessage("0x10", NumberError::kSyntax), "'0x10' is not a decimal number");
  EXPECT_EQ(NumberErrorMessage("1.5", NumberError::kNotInteger), "'1.5' is not an integer");
  EXPECT_EQ(NumberErrorMessage("-1", NumberError::kNegative),
            "'-1' is negative; a number >= 0 is required");
  EXPECT_EQ(NumberErrorMessage("300", NumberError::kOutOfBounds, "[0, 255]"),
            "'300' is out of range [0, 255]");
}

// Every finite double, written as its shortest decimal text (std::to_chars, which may give
// "1e+300" or "-5e-324"), reads back exactly, with and without a leading '+'.
RC_GTEST_PROP(ReadDecimal, ShortestTextsOfDoublesReadBack, (std::uint64_t bits)) {
  double x = 0.0;
  static_assert(sizeof x == sizeof bits);
  std::memcpy(&x, &bits, sizeof x);
  RC_PRE(std::isfinite(x));
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  RC_ASSERT(ec == std::errc());
  const std::string text(buffer, end);
  const NumberRead<double> r = ReadDecimal(text);
  RC_ASSERT(r.ok());
  RC_ASSERT(std::memcmp(&r.value, &x, sizeof x) == 0);
  if (text.front() != '-') {
    const NumberRead<double> plus = ReadDecimal("+" + text);
    RC_ASSERT(plus.ok());
    RC_ASSERT(plus.value == x);
  }
}

}  // namespace
}  // namespace hybrid
