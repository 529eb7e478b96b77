// libFuzzer harness: object descriptions (`--object circle:X,Y,R` or segment:X1,Y1,X2,Y2[,R],
// gripper::Obstacle::Parse in gripper/obstacle.h). Every input either throws ObstacleParseError
// with a column of the text, or gives an object with finite coordinates and a finite radius of
// at least kMinimumRadius whose description (ToString) parses back to the same object.

#include <cstdint>
#include <string>

#include "gripper/obstacle.h"
#include "tests/fuzz/fuzz_utilities.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using hybrid::gripper::Obstacle;
  using hybrid::gripper::ObstacleParseError;
  using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers
  const std::string_view text = AsText(data, size);
  try {
    const Obstacle object = Obstacle::Parse(text);
    if (!object.a().allFinite() || !object.b().allFinite() || !std::isfinite(object.radius()) ||
        !(object.radius() >= Obstacle::kMinimumRadius)) {
      FuzzFail("an object outside its invariant from '" + std::string(text) + "'");
    }
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
