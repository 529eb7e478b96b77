#include "hybrid/automaton/mode.h"

namespace hybrid {

std::optional<Expression> Mode::FlowOf(int slot) const {
  for (const auto& [s, rhs] : flows) {
    if (s == slot) return rhs;
  }
  return std::nullopt;
}

std::optional<int> Mode::DiscreteValueOf(int slot) const {
  for (const auto& [s, value] : discrete_values) {
    if (s == slot) return value;
  }
  return std::nullopt;
}

}  // namespace hybrid
