#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "automaton/automaton.h"
#include "automaton/system.h"

namespace hybrid {

/// A malformed or invalid model file. what() is "FILE:LINE:COL: MESSAGE" (lines and columns count
/// from 1, columns in bytes), the format compilers and editors understand.
class ParseError : public std::runtime_error {
 public:
  ParseError(std::string file, int line, int column, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  /// The message without the location prefix.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

/// Largest model file accepted (bytes); larger files are rejected before parsing.
inline constexpr std::size_t kMaxModelFileBytes = 16u << 20;

/// Deepest expression or predicate tree accepted, in levels of operators (each operator of a
/// left-associative chain such as `a + b + c` is one level). Deeper ones are a ParseError: the
/// IR's tree walks recurse, so a sum of millions of terms would overflow the stack.
inline constexpr int kMaxExpressionDepth = 10000;

/// Parses model-language text (see docs/model_language.md) into the model it declares: its
/// `system` block if it has one, otherwise its only automaton wrapped by System::Of. `file_name`
/// is used in messages and to resolve `import "path";` (relative to its directory).
/// Throws ParseError for every syntax error, undefined or duplicate name and invalid model; never
/// anything else for bad input.
System ParseModel(std::string_view text, const std::string& file_name);

/// Reads and parses a model file. Throws ParseError (with line 0, column 0 when the file cannot be
/// read or is larger than kMaxModelFileBytes).
System ParseModelFile(const std::filesystem::path& path);

/// Parses text that declares exactly one automaton and no system (used by round-trip tests and
/// tools that want the automaton itself). Throws ParseError otherwise.
Automaton ParseAutomaton(std::string_view text, const std::string& file_name);

/// Parses a signal written as in a scenario: a number (constant), `step(t: v, ...)` or
/// `linear(t: v, ...)`, e.g. from the command line. The result has slot -1. Throws ParseError
/// (named `source_name`, line 1, the column of the problem) for malformed text or non-increasing
/// times; values are not checked against any bounds here.
InputSignal ParseSignal(std::string_view text, const std::string& source_name);

}  // namespace hybrid
