#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/system.h"

namespace hybrid {

/// A malformed or invalid model file. what() is "FILE:LINE:COL: MESSAGE" (lines and columns count
/// from 1, columns in bytes), the format compilers and editors understand. Messages quote text of
/// the input (names, values, file names), so the message and the file name in what() are
/// escaped with EscapedForMessage (quoted_text.h): a control character read from a file reaches
/// the user as `\x1b`, `\n`, ..., never as itself.
class ParseError : public std::runtime_error {
 public:
  /// `message` is escaped here (escaping is idempotent, so a message built from escaped parts
  /// is unchanged); `file` is kept as given for file() and escaped in what().
  ParseError(std::string file, int line, int column, const std::string& message);
  /// The file as given (not escaped), to be compared with or opened.
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  int column() const { return column_; }
  /// The message without the location prefix, escaped.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_;
  int column_;
  std::string message_;
};

/// Largest model accepted (bytes): a larger file is rejected before parsing, and a model whose
/// file and imports together are larger is rejected at the import that passes the limit. At
/// 4 MiB, the worst case (a file that is one long sum) parses within about 1 GB of memory.
inline constexpr std::size_t kMaxModelFileBytes = 4u << 20;

/// Deepest chain of imports (a file importing a file importing ...) accepted.
inline constexpr int kMaxImportDepth = 64;

/// Parses model-language text (see docs/model_language.md) into the model it declares: its
/// `system` block if it has one, otherwise its only automaton wrapped by System::Of. `file_name`
/// is used in messages and to resolve `import "path";` (relative to its directory). A leading
/// UTF-8 byte-order mark is skipped (columns of the first line count from after it).
/// Throws ParseError for every syntax error, undefined or duplicate name and invalid model,
/// including expressions and predicates deeper than kMaxExpressionDepth (expression.h) and
/// parentheses, unary minus signs, powers or calls nested too deeply for the parser; never
/// anything else for bad input.
System ParseModel(std::string_view text, const std::string& file_name);

/// The whole content of the model file `path` (of any language), read as a stream (pipes and
/// /dev/stdin work). Throws ParseError (line 0, column 0) when it cannot be read, is a directory,
/// or is larger than kMaxModelFileBytes.
std::string ReadModelText(const std::filesystem::path& path);

/// Reads and parses a model file. The file is read as a stream, so a pipe, a FIFO or /dev/stdin
/// works like a regular file. Throws ParseError (with line 0, column 0 when the file cannot be
/// read, is a directory, or is larger than kMaxModelFileBytes).
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
