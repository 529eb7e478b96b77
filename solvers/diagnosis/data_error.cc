#include "hybrid/diagnosis/data_error.h"

#include <utility>

#include "automaton/quoted_text.h"

namespace hybrid {

// Messages quote cells, column names and run labels of the file: escaped (quoted_text.h), like
// the file name in what(), so that no control character of the input reaches a terminal.
DataError::DataError(std::string source, int line, int column, std::string message)
    : std::runtime_error(EscapedForMessage(source) + ":" + std::to_string(line) + ":" +
                         std::to_string(column) + ": " + EscapedForMessage(message)),
      source_(std::move(source)),
      line_(line),
      column_(column),
      message_(EscapedForMessage(message)) {}

}  // namespace hybrid
