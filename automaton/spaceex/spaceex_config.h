#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "automaton/spaceex/text_positions.h"

namespace hybrid::spaceex {

/// A SpaceEx configuration file (`MODEL.cfg`): lines `option = value`, the value plain or in
/// double quotes (a quoted value may span lines); `#` and `//` start comment lines.
class SpaceExConfig {
 public:
  /// One option's value and where it starts in the file (byte offset of its first character,
  /// inside the quotes).
  struct Value {
    std::string text;
    std::size_t offset = 0;
  };

  /// Parses `text`, named `file` in messages. Throws ParseError (include/hybrid/automaton/parser.h)
  /// at the line and column of a line that is not `option = value`, an unterminated quote or an
  /// option given twice.
  SpaceExConfig(std::string_view text, std::string file);

  const std::string& file() const { return file_; }
  /// The value of `option`, or nullopt.
  std::optional<Value> Find(const std::string& option) const;
  /// Line and column of byte `offset` of the file.
  std::pair<int, int> LineColumn(std::size_t offset) const { return positions_.LineColumn(offset); }
  const std::map<std::string, Value>& options() const { return options_; }

 private:
  std::string file_;
  TextPositions positions_;
  std::map<std::string, Value> options_;
};

}  // namespace hybrid::spaceex
