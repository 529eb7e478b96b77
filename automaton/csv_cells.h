#pragma once

// The cells of one line of the project's CSV files (the finger's measured data, traces of any
// model): comma-separated, no quoting, each cell trimmed of spaces and tabs.

#include <string_view>
#include <vector>

namespace hybrid {

/// `s` without its leading and trailing spaces and tabs.
inline std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

/// The comma-separated cells of `line`, each trimmed (TrimBlanks); one cell for a line without a
/// comma, an empty last cell after a trailing comma. The views point into `line`.
inline std::vector<std::string_view> SplitCsvCells(std::string_view line) {
  std::vector<std::string_view> cells;
  for (size_t comma = line.find(','); comma != std::string_view::npos; comma = line.find(',')) {
    cells.push_back(TrimBlanks(line.substr(0, comma)));
    line.remove_prefix(comma + 1);
  }
  cells.push_back(TrimBlanks(line));
  return cells;
}

}  // namespace hybrid
