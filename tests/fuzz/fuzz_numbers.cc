// libFuzzer harness: the decimal number readers of the command line (ReadDecimal, ReadInteger,
// ReadUnsigned in automaton/number_syntax.h), compared with the documented syntax read
// independently (tests/fuzz/number_oracle.h):
//  - ReadDecimal accepts exactly the texts of the syntax whose value is a finite double, with
//    strtod's value (bit for bit, -0 included); an empty text is kEmpty, any other text outside
//    the syntax kSyntax with `stop` inside the text; a value strtod overflows is kOverflow, a
//    non-zero one it rounds to 0 kUnderflow;
//  - ReadInteger and ReadUnsigned accept exactly the sign-and-digits texts within their bounds,
//    with their value; a decimal with a point or exponent is kNotInteger; below the bounds is
//    kNegative when the lower bound is >= 0, else kOutOfBounds; above is kOutOfBounds;
//  - every error has a message quoting the text (NumberErrorMessage).

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "automaton/number_syntax.h"
#include "tests/fuzz/fuzz_utilities.h"
#include "tests/fuzz/number_oracle.h"

namespace {

using hybrid::NumberError;
using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers

std::string Show(std::string_view text) { return "'" + std::string(text) + "'"; }

// The error the syntax gives `text` before any value is considered (kNone: decimal syntax).
NumberError SyntaxError(const OracleNumber& n) {
  if (n.empty) return NumberError::kEmpty;
  return n.decimal ? NumberError::kNone : NumberError::kSyntax;
}

void CheckDecimal(std::string_view text, const OracleNumber& n) {
  const hybrid::NumberRead<double> r = hybrid::ReadDecimal(text);
  NumberError expected = SyntaxError(n);
  double value = 0.0;
  if (expected == NumberError::kNone) {
    value = StrtodValue(text);
    if (std::isinf(value)) expected = NumberError::kOverflow;
    if (value == 0.0 && n.nonzero_mantissa) expected = NumberError::kUnderflow;
  }
  if (r.error != expected) {
    FuzzFail("ReadDecimal(" + Show(text) + ") gives error " +
             std::to_string(static_cast<int>(r.error)) + ", expected " +
             std::to_string(static_cast<int>(expected)));
  }
  if (expected == NumberError::kNone && std::memcmp(&r.value, &value, sizeof value) != 0) {
    FuzzFail("ReadDecimal(" + Show(text) + ") = " + std::to_string(r.value) + ", strtod gives " +
             std::to_string(value));
  }
  if (expected == NumberError::kSyntax && r.stop > text.size()) {
    FuzzFail("ReadDecimal(" + Show(text) + "): stop beyond the text");
  }
}

// The error of an integer reader with bounds [lo, hi] (lo_negative_error: kNegative when lo >= 0).
NumberError IntegerError(std::string_view text, const OracleNumber& n, __int128 lo, __int128 hi) {
  const NumberError syntax = SyntaxError(n);
  if (syntax != NumberError::kNone) return syntax;
  if (!n.integer) return NumberError::kNotInteger;
  const __int128 v = IntegerValue(text);
  if (v < lo) return lo >= 0 ? NumberError::kNegative : NumberError::kOutOfBounds;
  if (v > hi) return NumberError::kOutOfBounds;
  return NumberError::kNone;
}

void CheckInteger(std::string_view text, const OracleNumber& n, std::int64_t lo, std::int64_t hi) {
  const hybrid::NumberRead<std::int64_t> r = hybrid::ReadInteger(text, lo, hi);
  const NumberError expected = IntegerError(text, n, lo, hi);
  const std::string call =
      "ReadInteger(" + Show(text) + ", " + std::to_string(lo) + ", " + std::to_string(hi) + ")";
  if (r.error != expected) {
    FuzzFail(call + " gives error " + std::to_string(static_cast<int>(r.error)) + ", expected " +
             std::to_string(static_cast<int>(expected)));
  }
  if (expected == NumberError::kNone && r.value != IntegerValue(text)) {
    FuzzFail(call + " = " + std::to_string(r.value));
  }
}

void CheckUnsigned(std::string_view text, const OracleNumber& n, std::uint64_t hi) {
  const hybrid::NumberRead<std::uint64_t> r = hybrid::ReadUnsigned(text, hi);
  const NumberError expected = IntegerError(text, n, 0, hi);
  const std::string call = "ReadUnsigned(" + Show(text) + ", " + std::to_string(hi) + ")";
  if (r.error != expected) {
    FuzzFail(call + " gives error " + std::to_string(static_cast<int>(r.error)) + ", expected " +
             std::to_string(static_cast<int>(expected)));
  }
  if (expected == NumberError::kNone && r.value != static_cast<std::uint64_t>(IntegerValue(text))) {
    FuzzFail(call + " = " + std::to_string(r.value));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text = AsText(data, size);
  const OracleNumber n = ClassifyNumber(text);
  CheckDecimal(text, n);
  constexpr auto kMin64 = std::numeric_limits<std::int64_t>::min();
  constexpr auto kMax64 = std::numeric_limits<std::int64_t>::max();
  CheckInteger(text, n, kMin64, kMax64);
  CheckInteger(text, n, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
  CheckInteger(text, n, 0, 1000);
  CheckInteger(text, n, -5, 5);
  CheckUnsigned(text, n, std::numeric_limits<std::uint64_t>::max());
  CheckUnsigned(text, n, 255);
  for (NumberError e :
       {NumberError::kEmpty, NumberError::kSyntax, NumberError::kOverflow, NumberError::kUnderflow,
        NumberError::kNotInteger, NumberError::kNegative, NumberError::kOutOfBounds}) {
    const std::string message = hybrid::NumberErrorMessage(text, e, "[0, 1]");
    if (message.empty() || (e != NumberError::kEmpty && !Contains(message, Show(text)))) {
      FuzzFail("NumberErrorMessage does not quote " + Show(text) + ": " + message);
    }
  }
  return 0;
}
