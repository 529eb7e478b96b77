#include "hybrid/automaton/property.h"

namespace hybrid {

std::string_view KindKeyword(Property::Kind kind) {
  switch (kind) {
    case Property::Kind::kAlways:
      return "always";
    case Property::Kind::kNever:
      return "never";
    case Property::Kind::kReach:
      return "reach";
  }
  return "?";
}

}  // namespace hybrid
