#pragma once

#include <optional>
#include <string>

#include "hybrid/automaton/predicate.h"

namespace hybrid {

/// A named question about the reachable states of a model.
struct Property {
  enum class Kind {
    /// `always P`: P holds in every reachable state (an invariant).
    kAlways,
    /// `never P`: no reachable state satisfies P (the invariant `always not P`).
    kNever,
    /// `reach P`: some reachable state satisfies P (a reachability query).
    kReach,
  };
  std::string name;
  Kind kind = Kind::kAlways;
  Predicate predicate;
  /// Bounded variant: only states reachable within this time (`within T`); nullopt = unbounded.
  std::optional<double> horizon;
  friend bool operator==(const Property&, const Property&) = default;
};

/// "always", "never", "reach".
std::string_view KindKeyword(Property::Kind kind);

}  // namespace hybrid
