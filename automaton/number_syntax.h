#pragma once

// The one decimal number syntax of the `hybrid` command line (docs/cli.md, "Numbers"): every
// numeric option, the values of `--set` and `--effect`, the cells of `--input-csv` and of measured
// data, and object descriptions are read by these functions, so that they all accept the same
// texts. The syntax is the model language's number token with an optional sign:
//
//   [+-]? ( DIGITS [ '.' DIGITS? ] | '.' DIGITS ) ( [eE] [+-]? DIGITS )?
//
// with DIGITS one or more of 0-9: decimal only, one sign at most, no blanks, no hexadecimal,
// no "inf" or "nan", no empty text and nothing after the number. Values are converted with
// std::from_chars (correctly rounded, independent of the locale). Integers are a sign and
// digits only (no point, no exponent).

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

namespace hybrid {

/// Why a text is not a number of the requested kind (kNone: it is).
enum class NumberError {
  kNone,
  kEmpty,        ///< the text is empty
  kSyntax,       ///< not the decimal syntax above (see NumberRead::stop for where)
  kOverflow,     ///< decimal syntax, but beyond the largest finite double
  kUnderflow,    ///< decimal syntax, non-zero, but below the smallest positive double
  kNotInteger,   ///< a decimal number with a point or an exponent where an integer is needed
  kNegative,     ///< a negative integer where a non-negative one is needed
  kOutOfBounds,  ///< an integer outside the bounds asked for
};

/// The outcome of reading a number.
template <typename T>
struct NumberRead {
  T value{};  ///< the number when error is kNone, else 0
  NumberError error = NumberError::kNone;
  std::size_t stop = 0;  ///< kSyntax: 0-based offset of the first character that does not fit
  bool ok() const { return error == NumberError::kNone; }
};

namespace number_syntax_detail {

// The length of the longest prefix of `text` that the scanner accepts as part of a number, and
// whether that prefix is a complete number; also the decimal exponent of the leading digit (for
// telling overflow from underflow) and whether a point or an exponent was seen.
struct Scan {
  std::size_t length = 0;
  bool complete = false;
  bool fraction_or_exponent = false;
  long long magnitude = 0;  // floor(log10 |value|) + 1 for a non-zero mantissa
};

inline bool IsDigit(char c) { return c >= '0' && c <= '9'; }

inline Scan ScanDecimal(std::string_view text) {
  Scan s;
  std::size_t i = 0;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
  std::size_t int_digits = 0, frac_digits = 0;
  long long leading = 0;  // position of the first non-zero digit relative to the point
  bool seen_nonzero = false;
  while (i < text.size() && IsDigit(text[i])) {
    if (text[i] != '0' && !seen_nonzero) seen_nonzero = true;
    if (seen_nonzero) ++leading;
    ++int_digits;
    ++i;
  }
  if (i < text.size() && text[i] == '.') {
    s.fraction_or_exponent = true;
    ++i;
    while (i < text.size() && IsDigit(text[i])) {
      if (!seen_nonzero) {
        if (text[i] != '0') {
          seen_nonzero = true;
        } else {
          --leading;
        }
      }
      ++frac_digits;
      ++i;
    }
  }
  s.length = i;
  if (int_digits + frac_digits == 0) return s;  // no mantissa digit: incomplete
  s.complete = true;
  long long exponent = 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    s.fraction_or_exponent = true;
    s.complete = false;  // until a digit of the exponent is read
    ++i;
    bool negative = false;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
    s.length = i;
    while (i < text.size() && IsDigit(text[i])) {
      if (exponent < 100000000) exponent = exponent * 10 + (text[i] - '0');
      s.complete = true;
      ++i;
    }
    if (negative) exponent = -exponent;
    s.length = i;
  }
  s.magnitude = leading + exponent;
  return s;
}

}  // namespace number_syntax_detail

/// Reads all of `text` as a finite double in the decimal syntax above. Errors: kEmpty, kSyntax
/// (with `stop`), kOverflow (|value| above the largest double), kUnderflow (non-zero but below
/// the smallest positive subnormal double; subnormals are read). "-0" reads as -0.0.
inline NumberRead<double> ReadDecimal(std::string_view text) {
  NumberRead<double> out;
  if (text.empty()) {
    out.error = NumberError::kEmpty;
    return out;
  }
  const auto scan = number_syntax_detail::ScanDecimal(text);
  if (!scan.complete || scan.length != text.size()) {
    out.error = NumberError::kSyntax;
    out.stop = scan.complete ? scan.length : std::min(scan.length, text.size());
    return out;
  }
  const bool negative = text.front() == '-';
  const std::string_view unsigned_text =
      (text.front() == '+' || text.front() == '-') ? text.substr(1) : text;
  double value = 0.0;
  const auto [end, ec] =
      std::from_chars(unsigned_text.data(), unsigned_text.data() + unsigned_text.size(), value);
  if (ec == std::errc::result_out_of_range) {
    out.error = scan.magnitude > 0 ? NumberError::kOverflow : NumberError::kUnderflow;
    return out;
  }
  if (ec != std::errc() || end != unsigned_text.data() + unsigned_text.size()) {
    out.error = NumberError::kSyntax;  // not expected after the scan
    out.stop = 0;
    return out;
  }
  out.value = negative ? -value : value;
  return out;
}

namespace number_syntax_detail {

// The sign and magnitude of an integer text: kNone, or kEmpty, kSyntax (with stop),
// kNotInteger, or kOutOfBounds when the magnitude exceeds 2^64 - 1.
struct IntegerText {
  NumberError error = NumberError::kNone;
  std::size_t stop = 0;
  bool negative = false;
  std::uint64_t magnitude = 0;
};

inline IntegerText ScanInteger(std::string_view text) {
  IntegerText out;
  if (text.empty()) {
    out.error = NumberError::kEmpty;
    return out;
  }
  const Scan scan = ScanDecimal(text);
  if (!scan.complete || scan.length != text.size()) {
    out.error = NumberError::kSyntax;
    out.stop = std::min(scan.length, text.size());
    return out;
  }
  if (scan.fraction_or_exponent) {
    out.error = NumberError::kNotInteger;
    return out;
  }
  out.negative = text.front() == '-';
  const std::string_view digits =
      (text.front() == '+' || text.front() == '-') ? text.substr(1) : text;
  const auto [end, ec] =
      std::from_chars(digits.data(), digits.data() + digits.size(), out.magnitude);
  if (ec != std::errc()) out.error = NumberError::kOutOfBounds;
  return out;
}

}  // namespace number_syntax_detail

/// Reads all of `text` as an integer `[+-]?DIGITS` within [lo, hi]. Errors: kEmpty, kSyntax
/// (with `stop`), kNotInteger (a decimal number with a point or an exponent, e.g. "1.5" or
/// "1e3"), kNegative (a value below 0 when lo >= 0), kOutOfBounds (any other value outside
/// [lo, hi]). "-0" reads as 0.
inline NumberRead<std::int64_t> ReadInteger(std::string_view text, std::int64_t lo,
                                            std::int64_t hi) {
  NumberRead<std::int64_t> out;
  const auto t = number_syntax_detail::ScanInteger(text);
  const NumberError too_low = lo >= 0 ? NumberError::kNegative : NumberError::kOutOfBounds;
  constexpr std::uint64_t kMinMagnitude = std::uint64_t{1} << 63;  // |INT64_MIN|
  if (t.error == NumberError::kOutOfBounds) {
    out.error = t.negative ? too_low : NumberError::kOutOfBounds;
    return out;
  }
  if (t.error != NumberError::kNone) {
    out.error = t.error;
    out.stop = t.stop;
    return out;
  }
  std::int64_t value = 0;
  if (t.negative) {
    if (t.magnitude > kMinMagnitude) {
      out.error = too_low;
      return out;
    }
    value = t.magnitude == kMinMagnitude ? std::numeric_limits<std::int64_t>::min()
                                         : -static_cast<std::int64_t>(t.magnitude);
  } else {
    if (t.magnitude > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      out.error = NumberError::kOutOfBounds;
      return out;
    }
    value = static_cast<std::int64_t>(t.magnitude);
  }
  if (value < lo) {
    out.error = too_low;
  } else if (value > hi) {
    out.error = NumberError::kOutOfBounds;
  } else {
    out.value = value;
  }
  return out;
}

/// Reads all of `text` as a non-negative integer `[+-]?DIGITS` up to `hi` ("-0" reads as 0).
/// Errors as ReadInteger: kNegative for a value below 0, kOutOfBounds above `hi`.
inline NumberRead<std::uint64_t> ReadUnsigned(std::string_view text, std::uint64_t hi) {
  NumberRead<std::uint64_t> out;
  const auto t = number_syntax_detail::ScanInteger(text);
  if (t.error != NumberError::kNone) {
    out.error =
        t.negative && t.error == NumberError::kOutOfBounds ? NumberError::kNegative : t.error;
    out.stop = t.stop;
    return out;
  }
  if (t.negative && t.magnitude > 0) {
    out.error = NumberError::kNegative;
  } else if (t.magnitude > hi) {
    out.error = NumberError::kOutOfBounds;
  } else {
    out.value = t.magnitude;
  }
  return out;
}

/// A message for the user about `text` failing with `error` (without naming where the text
/// came from: the caller prefixes the option or the file position), e.g. "'0x10' is not a
/// decimal number", "empty: a number is required". `bounds` (e.g. "[0, 1000]") completes
/// kOutOfBounds.
inline std::string NumberErrorMessage(std::string_view text, NumberError error,
                                      const std::string& bounds = "") {
  const std::string quoted = "'" + std::string(text) + "'";
  switch (error) {
    case NumberError::kNone:
      return "";
    case NumberError::kEmpty:
      return "empty: a number is required";
    case NumberError::kSyntax:
      return quoted + " is not a decimal number";
    case NumberError::kOverflow:
      return quoted + " is out of range (beyond the largest double, about 1.8e308)";
    case NumberError::kUnderflow:
      return quoted + " is too small for a double (non-zero, below about 4.9e-324)";
    case NumberError::kNotInteger:
      return quoted + " is not an integer";
    case NumberError::kNegative:
      return quoted + " is negative; a number >= 0 is required";
    case NumberError::kOutOfBounds:
      return quoted + " is out of range" + (bounds.empty() ? "" : " " + bounds);
  }
  return quoted + " is not a number";
}

}  // namespace hybrid
