#pragma once

// An independent reading of the command line's decimal number syntax (docs/cli.md, "Numbers";
// automaton/number_syntax.h), for the harnesses to compare the real readers with:
//
//   [+-]? ( DIGITS [ '.' DIGITS? ] | '.' DIGITS ) ( [eE] [+-]? DIGITS )?
//
// Written from the documented grammar, not from the reader's code: a character-class matcher,
// values from strtod in the "C" locale, integers accumulated in 128 bits.

#include <cerrno>
#include <clocale>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

namespace hybrid::fuzz {

/// What the documented syntax says about a text.
struct OracleNumber {
  bool empty = false;
  bool decimal = false;  ///< the whole text is in the decimal syntax
  bool integer = false;  ///< ... and is only a sign and digits
  bool nonzero_mantissa = false;
};

inline OracleNumber ClassifyNumber(std::string_view t) {
  OracleNumber out;
  out.empty = t.empty();
  size_t i = 0;
  auto digits = [&] {
    const size_t start = i;
    while (i < t.size() && t[i] >= '0' && t[i] <= '9') {
      if (t[i] != '0') out.nonzero_mantissa = true;
      ++i;
    }
    return i - start;
  };
  if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
  const size_t whole = digits();
  size_t fraction = 0;
  bool point = false;
  if (i < t.size() && t[i] == '.') {
    point = true;
    ++i;
    fraction = digits();
  }
  if (whole + fraction == 0) return out;
  bool exponent = false;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    exponent = true;
    ++i;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
    const bool mantissa_nonzero = out.nonzero_mantissa;
    if (digits() == 0) return out;
    out.nonzero_mantissa = mantissa_nonzero;  // exponent digits do not count
  }
  out.decimal = i == t.size();
  out.integer = out.decimal && !point && !exponent;
  return out;
}

/// The value strtod gives a text in the decimal syntax (the "C" locale is the default of a
/// program that never calls setlocale, as the harnesses do not).
inline double StrtodValue(std::string_view t) {
  const std::string copy(t);
  return std::strtod(copy.c_str(), nullptr);
}

/// An integer text's value, saturated at +-2^100 (beyond every bound the readers take).
inline __int128 IntegerValue(std::string_view t) {
  const bool negative = !t.empty() && t.front() == '-';
  if (!t.empty() && (t.front() == '+' || t.front() == '-')) t.remove_prefix(1);
  const __int128 cap = static_cast<__int128>(1) << 100;
  __int128 v = 0;
  for (char c : t) v = v >= cap ? cap : v * 10 + (c - '0');
  if (v > cap) v = cap;
  return negative ? -v : v;
}

}  // namespace hybrid::fuzz
