// libFuzzer harness: signals as given on the command line (`--input 'u=step(0: 5, 30: 15)'`,
// ParseSignal in include/hybrid/automaton/parser.h). Every input either throws ParseError at a
// position of the text, or gives a signal whose times strictly increase and whose numbers are
// finite; writing that signal back (shortest round-trip numbers) and parsing it gives it again.

#include <cmath>
#include <cstdint>
#include <string>

#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/parser.h"
#include "tests/fuzz/fuzz_utilities.h"

namespace {

std::string SignalText(const hybrid::InputSignal& s) {
  std::string out = s.shape == hybrid::InputSignal::Shape::kStep ? "step(" : "linear(";
  for (size_t i = 0; i < s.points.size(); ++i) {
    out += (i > 0 ? ", " : "") + hybrid::FormatNumber(s.points[i].first) + ": " +
           hybrid::FormatNumber(s.points[i].second);
  }
  return out + ")";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers
  const std::string_view text = AsText(data, size);
  const std::string source = "--input u";
  hybrid::InputSignal signal;
  try {
    signal = hybrid::ParseSignal(text, source);
  } catch (const hybrid::ParseError& e) {
    // Line 1 unless the text itself has line breaks (white space, so allowed in a signal).
    if (e.file() != source || !IsPositionIn(text, e.line(), e.column())) {
      FuzzFail("ParseError outside the signal: " + std::string(e.what()));
    }
    if (e.message().empty() || LeaksCppNames(e.message(), text)) {
      FuzzFail("bad message: " + std::string(e.what()));
    }
    return 0;
  }
  if (signal.points.empty()) FuzzFail("a signal without points");
  for (size_t i = 0; i < signal.points.size(); ++i) {
    const auto [t, v] = signal.points[i];
    if (!std::isfinite(t) || !std::isfinite(v)) FuzzFail("a signal with a non-finite number");
    if (i > 0 && !(t > signal.points[i - 1].first)) FuzzFail("signal times do not increase");
  }
  const std::string written = SignalText(signal);
  hybrid::InputSignal again;
  try {
    again = hybrid::ParseSignal(written, source);
  } catch (const hybrid::ParseError& e) {
    FuzzFail("the written signal '" + written + "' does not parse: " + e.what());
  }
  if (!(again == signal)) FuzzFail("the written signal '" + written + "' parses differently");
  return 0;
}
