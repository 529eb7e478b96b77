#pragma once

// Looking up a model's declared property by name (shared by the verification tests).

#include <stdexcept>
#include <string>

#include "hybrid/automaton/system.h"

namespace hybrid::testing {

/// The property of `system` named `name`; throws std::invalid_argument if there is none.
inline const Property& Named(const System& system, const std::string& name) {
  for (const Property& p : system.properties()) {
    if (p.name == name) return p;
  }
  throw std::invalid_argument("no property " + name);
}

}  // namespace hybrid::testing
