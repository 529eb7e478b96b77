#pragma once

#include <array>
#include <sstream>
#include <string>
#include <vector>

namespace hybrid::testing {

/// The values of every `name="..."` attribute in `text`, in order. A plain scan rather than
/// std::regex: libstdc++ matches `[^"]*` by one recursive call per character, which overflows
/// the stack on a long points list under AddressSanitizer's larger frames.
inline std::vector<std::string> AttributeValues(const std::string& text, const std::string& name) {
  const std::string opening = " " + name + "=\"";
  std::vector<std::string> values;
  for (std::size_t at = text.find(opening); at != std::string::npos;
       at = text.find(opening, at + 1)) {
    const std::size_t from = at + opening.size();
    const std::size_t to = text.find('"', from);
    if (to == std::string::npos) break;
    values.push_back(text.substr(from, to - from));
  }
  return values;
}

/// The pairs of an SVG `points` list "x1,y1 x2,y2 ...", up to the first malformed pair.
inline std::vector<std::array<double, 2>> PointPairs(const std::string& points) {
  std::vector<std::array<double, 2>> pairs;
  std::istringstream text(points);
  double x = 0, y = 0;
  char comma = 0;
  while (text >> x >> comma >> y && comma == ',') pairs.push_back({x, y});
  return pairs;
}

}  // namespace hybrid::testing
