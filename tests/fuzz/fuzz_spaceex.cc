// libFuzzer harness: the SpaceEx import (automaton/spaceex/) on arbitrary bytes: the model's XML,
// then, after the first NUL byte if there is one, its configuration.
// Contract checked (spaceex_import.h): every input either gives a translation or throws
// ParseError; a translation either parses (Translation::Parse) or throws ParseError mapped back
// into the SpaceEx files; every error's position lies in the file it names; messages speak of
// the model, not of C++. ASan and UBSan check memory and undefined behaviour.

#include <cstdint>
#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/spaceex/spaceex_import.h"
#include "tests/fuzz/fuzz_utilities.h"

namespace {

constexpr const char* kXml = "m.xml";
constexpr const char* kCfg = "m.cfg";

void CheckError(const hybrid::ParseError& e, std::string_view xml, std::string_view cfg,
                std::string_view input) {
  using hybrid::fuzz::FuzzFail;
  if (e.message().empty()) FuzzFail("empty ParseError message: " + std::string(e.what()));
  const bool in_xml = e.file() == kXml && hybrid::fuzz::IsPositionIn(xml, e.line(), e.column());
  const bool in_cfg = e.file() == kCfg && hybrid::fuzz::IsPositionIn(cfg, e.line(), e.column());
  if (!in_xml && !in_cfg) FuzzFail("ParseError outside the input: " + std::string(e.what()));
  if (hybrid::fuzz::LeaksCppNames(e.message(), input)) {
    FuzzFail("C++ name in a message: " + e.message());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input = hybrid::fuzz::AsText(data, size);
  const std::size_t nul = input.find('\0');
  const std::string_view xml = input.substr(0, nul);
  const std::string_view cfg = nul == std::string_view::npos ? "" : input.substr(nul + 1);
  try {
    const hybrid::spaceex::Translation t = hybrid::spaceex::TranslateSpaceEx(
        xml, kXml, cfg, nul == std::string_view::npos ? "" : kCfg);
    (void)t.Parse(kXml);
  } catch (const hybrid::ParseError& e) {
    CheckError(e, xml, cfg, input);
  }
  return 0;
}
