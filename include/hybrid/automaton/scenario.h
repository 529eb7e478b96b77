#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hybrid {

/// A scalar input signal u(t).
struct InputSignal {
  enum class Shape {
    /// u(t) = value of the last point with time <= t (first value before the first point).
    kStep,
    /// Linear interpolation between points, constant beyond the first and last.
    kLinear,
  };
  /// Slot of the input driven by this signal.
  int slot = -1;
  Shape shape = Shape::kStep;
  /// (time, value) pairs with strictly increasing times; at least one.
  std::vector<std::pair<double, double>> points;

  /// u(t) as defined by the shape.
  double ValueAt(double t) const;
  friend bool operator==(const InputSignal&, const InputSignal&) = default;
};

/// The default run of a model: simulate from the initial state until `until`, with each listed
/// input driven by its signal (inputs not listed stay at 0, which must lie in their bounds).
struct Scenario {
  double until = 0.0;
  std::vector<InputSignal> inputs;
  friend bool operator==(const Scenario&, const Scenario&) = default;
};

}  // namespace hybrid
