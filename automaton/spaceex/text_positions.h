#pragma once

#include <algorithm>
#include <cstddef>
#include <string_view>
#include <utility>
#include <vector>

namespace hybrid::spaceex {

/// Line and column (both from 1, columns in bytes) of byte offsets in a text.
class TextPositions {
 public:
  explicit TextPositions(std::string_view text) {
    starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '\n') starts_.push_back(i + 1);
    }
  }
  /// The line and column of byte `offset` (an offset past the end counts on the last line).
  std::pair<int, int> LineColumn(std::size_t offset) const {
    const auto next = std::upper_bound(starts_.begin(), starts_.end(), offset);
    const std::size_t line = static_cast<std::size_t>(next - starts_.begin());
    return {static_cast<int>(line), static_cast<int>(offset - starts_[line - 1] + 1)};
  }

 private:
  std::vector<std::size_t> starts_;
};

}  // namespace hybrid::spaceex
