// libFuzzer harness: the model-language parser (ParseModel) on arbitrary bytes.
// Contract checked (include/hybrid/automaton/parser.h): every input either gives a System or throws
// ParseError, never anything else; the error's position lies in the input when it concerns the
// input's own file; messages speak of the model, not of C++. ASan and UBSan check memory and
// undefined behaviour; libFuzzer's -timeout and -rss_limit_mb bound time and memory per input.

#include <cstdint>
#include <string>

#include "hybrid/automaton/parser.h"
#include "tests/fuzz/fuzz_models.h"
#include "tests/fuzz/fuzz_utilities.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers
  const std::string_view text = AsText(data, size);
  if (!ImportsStayInFolder(text)) return -1;  // not added to the corpus
  try {
    const hybrid::System system = hybrid::ParseModel(text, ModelFileName());
    (void)system;
  } catch (const hybrid::ParseError& e) {
    if (e.message().empty()) FuzzFail("empty ParseError message: " + std::string(e.what()));
    if (e.file() == ModelFileName() && !IsPositionIn(text, e.line(), e.column())) {
      FuzzFail("ParseError outside the input: " + std::string(e.what()));
    }
    if (LeaksCppNames(e.message(), text)) FuzzFail("C++ name in a message: " + e.message());
  }
  return 0;
}
