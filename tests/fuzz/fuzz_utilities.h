#pragma once

// Shared by the libFuzzer harnesses (docs/fuzzing.md): a harness calls FuzzFail when an input
// breaks a documented contract that is not a crash by itself (a wrong exception type is one:
// it escapes the harness and aborts; a wrong result is reported here).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace hybrid::fuzz {

/// Prints `what` and aborts, so that libFuzzer records the input as a crash.
[[noreturn]] inline void FuzzFail(const std::string& what) {
  std::fprintf(stderr, "\n==fuzz== contract broken: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

/// The fuzzer's bytes as text (any bytes, including NUL).
inline std::string_view AsText(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Whether `column` (1-based, bytes) lies on line `line` (1-based) of `text` or just after its
/// end: the positions a message about `text` may name.
inline bool IsPositionIn(std::string_view text, int line, int column) {
  if (line < 1 || column < 1) return false;
  size_t start = 0;
  for (int l = 1; l < line; ++l) {
    const size_t eol = text.find('\n', start);
    if (eol == std::string_view::npos) return false;
    start = eol + 1;
  }
  const size_t eol = text.find('\n', start);
  const size_t length = (eol == std::string_view::npos ? text.size() : eol) - start;
  return static_cast<size_t>(column) <= length + 1;
}

/// Whether `text` contains `word`. A plain loop, not instrumented for coverage: the harnesses'
/// own checks must not feed libFuzzer's comparison tracing (which would add their words to the
/// fuzzer's dictionary).
#if defined(__clang__)
__attribute__((no_sanitize("coverage")))
#endif
inline bool
Contains(std::string_view text, std::string_view word) {
  for (size_t i = 0; i + word.size() <= text.size(); ++i) {
    size_t k = 0;
    while (k < word.size() && text[i + k] == word[k]) ++k;
    if (k == word.size()) return true;
  }
  return false;
}

/// Whether a user-facing message speaks of C++ rather than of the input: "std::", "bad_alloc",
/// "basic_string"... or a "::" that the input itself does not contain (messages may quote it).
inline bool LeaksCppNames(std::string_view message, std::string_view input) {
  for (std::string_view word : {"std::", "bad_alloc", "basic_string", "vector::", "stoi", "stod"}) {
    if (Contains(message, word) && !Contains(input, word)) return true;
  }
  return Contains(message, "::") && !Contains(input, "::");
}

}  // namespace hybrid::fuzz
