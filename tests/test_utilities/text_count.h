#pragma once

#include <string>

namespace hybrid::testing {

/// How many times `what` occurs in `text`, overlapping occurrences included.
inline int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace hybrid::testing
