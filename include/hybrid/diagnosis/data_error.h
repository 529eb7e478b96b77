#pragma once

#include <stdexcept>
#include <string>

namespace hybrid {

/// Invalid data. what() is "SOURCE:LINE:COL: MESSAGE" where LINE is the 1-based line in the file
/// and COL the 1-based column (field) number, e.g.
/// "data.csv:14:3: column 'theta1': not a number: 'abc'". COL is 0 when the whole line is
/// concerned (e.g. a row with the wrong number of cells, a missing column in the header), and
/// LINE and COL are both 0 when the whole file is (it cannot be opened, it has no header).
class DataError : public std::runtime_error {
 public:
  DataError(std::string source, int line, int column, std::string message);

  /// The file name given to the constructor.
  const std::string& source() const { return source_; }
  /// 1-based line, 0 for the whole file.
  int line() const { return line_; }
  /// 1-based column (field) number, 0 for the whole line or file.
  int column() const { return column_; }
  /// The message without the "SOURCE:LINE:COL: " prefix.
  const std::string& message() const { return message_; }

 private:
  std::string source_;
  int line_;
  int column_;
  std::string message_;
};

}  // namespace hybrid
