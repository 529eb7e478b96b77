// libFuzzer harness: parse, print, parse again (include/hybrid/automaton/printer.h). For every
// input the parser accepts, the printed model must parse back (no ParseError) into an equal System
// (operator==), and printing that gives the same text again.

#include <cstdint>
#include <optional>
#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"
#include "tests/fuzz/fuzz_models.h"
#include "tests/fuzz/fuzz_utilities.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers
  const std::string_view text = AsText(data, size);
  if (!ImportsStayInFolder(text)) return -1;  // not added to the corpus
  std::optional<hybrid::System> first;
  try {
    first.emplace(hybrid::ParseModel(text, ModelFileName()));
  } catch (const hybrid::ParseError&) {
    return 0;  // fuzz_model_parser checks rejections
  }
  const std::string printed = hybrid::PrintSystem(*first);
  std::optional<hybrid::System> second;
  try {
    second.emplace(hybrid::ParseModel(printed, ModelFileName()));
  } catch (const hybrid::ParseError& e) {
    FuzzFail("the printed model does not parse: " + std::string(e.what()) + "\n--- printed:\n" +
             printed);
  }
  if (!(*second == *first)) {
    FuzzFail("the printed model parses to a different model\n--- printed:\n" + printed +
             "--- printed again:\n" + hybrid::PrintSystem(*second));
  }
  const std::string again = hybrid::PrintSystem(*second);
  if (again != printed) {
    FuzzFail("printing is not a fixed point\n--- printed:\n" + printed + "--- printed again:\n" +
             again);
  }
  return 0;
}
