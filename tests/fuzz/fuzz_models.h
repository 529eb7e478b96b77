#pragma once

// Model texts for the parser harnesses: where their imports resolve, and which inputs stay there.

#include <string>
#include <string_view>

namespace hybrid::fuzz {

/// The file name fuzzed model texts are parsed as: a file (that does not exist) in
/// tests/fuzz/imports/, so that `import "lib.ha";` reads tests/fuzz/imports/lib.ha and every
/// run sees the same files (HYBRID_FUZZ_IMPORTS is set by tests/fuzz/CMakeLists.txt).
inline const std::string& ModelFileName() {
  static const std::string name = std::string(HYBRID_FUZZ_IMPORTS) + "/input.ha";
  return name;
}

/// Whether every quoted string of `text` (a model's import paths) names a file directly in the
/// import folder: no '/' (which could reach any file of the machine) and no NUL. Quotes are
/// paired line by line, also inside comments, which errs on the side of rejecting: a string the
/// parser reads is always either the first quote of its line or follows complete pairs.
inline bool ImportsStayInFolder(std::string_view text) {
  bool in_string = false;
  for (const char c : text) {
    if (c == '\n' || c == '\r') {
      in_string = false;
    } else if (c == '"') {
      in_string = !in_string;
    } else if (in_string && (c == '/' || c == '\0')) {
      return false;
    }
  }
  return true;
}

}  // namespace hybrid::fuzz
