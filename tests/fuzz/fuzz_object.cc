// libFuzzer harness: object descriptions (`--object circle:X,Y,R` or segment:X1,Y1,X2,Y2[,R],
// gripper::Obstacle::Parse in include/hybrid/gripper/obstacle.h). Every input either throws
// ObstacleParseError with a column of the text, or gives an object with finite coordinates and a
// finite radius of at least kMinimumRadius whose description (ToString) parses back to the same
// object, from a text in the documented syntax (decimal numbers, automaton/number_syntax.h) with
// those numbers.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "hybrid/gripper/obstacle.h"
#include "tests/fuzz/fuzz_utilities.h"
#include "tests/fuzz/number_oracle.h"

namespace {

using hybrid::gripper::Obstacle;
using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers

// Checks an accepted description against the documented syntax, read independently: KIND ':'
// then 3 (circle) or 4 or 5 (segment) comma-separated numbers in the decimal syntax, each with
// optional spaces around it, giving the centre and radius, or the ends and radius.
void CheckAgainstSyntax(std::string_view text, const Obstacle& object) {
  const size_t colon = text.find(':');
  std::vector<double> values;
  for (size_t begin = colon + 1;;) {
    const size_t comma = std::min(text.find(',', begin), text.size());
    std::string_view field = text.substr(begin, comma - begin);
    while (!field.empty() && field.front() == ' ') field.remove_prefix(1);
    while (!field.empty() && field.back() == ' ') field.remove_suffix(1);
    if (!ClassifyNumber(field).decimal) {
      FuzzFail("'" + std::string(text) + "' accepted with the field '" + std::string(field) + "'");
    }
    values.push_back(StrtodValue(field));
    if (comma == text.size()) break;
    begin = comma + 1;
  }
  const bool circle = text.substr(0, colon) == "circle";
  const size_t n = values.size();
  if (circle ? n != 3 : (n != 4 && n != 5)) FuzzFail("'" + std::string(text) + "': count");
  const Eigen::Vector2d a(values[0], values[1]);
  const Eigen::Vector2d b = circle ? a : Eigen::Vector2d(values[2], values[3]);
  const double r = circle ? values[2] : (n == 5 ? values[4] : Obstacle::kDefaultBarRadius);
  if (object.a() != a || object.b() != b || object.radius() != r) {
    FuzzFail("'" + std::string(text) + "' parses to other numbers: " + object.ToString());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using hybrid::gripper::ObstacleParseError;
  const std::string_view text = AsText(data, size);
  try {
    const Obstacle object = Obstacle::Parse(text);
    if (!object.a().allFinite() || !object.b().allFinite() || !std::isfinite(object.radius()) ||
        !(object.radius() >= Obstacle::kMinimumRadius)) {
      FuzzFail("an object outside its invariant from '" + std::string(text) + "'");
    }
    CheckAgainstSyntax(text, object);
    const std::string written = object.ToString();
    try {
      if (!(Obstacle::Parse(written) == object)) {
        FuzzFail("'" + written + "' parses to another object");
      }
    } catch (const ObstacleParseError& e) {
      FuzzFail("'" + written + "' does not parse: " + e.what());
    }
  } catch (const ObstacleParseError& e) {
    if (e.column() < 1 || static_cast<size_t>(e.column()) > text.size() + 1) {
      FuzzFail("column " + std::to_string(e.column()) + " outside the text: " + e.what());
    }
    if (std::string_view(e.what()).empty() || LeaksCppNames(e.what(), text)) {
      FuzzFail(std::string("bad message: ") + e.what());
    }
  }
  return 0;
}
