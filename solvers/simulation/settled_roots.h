#pragma once

// Root functions of exact segments that were reported at an instant at which nothing fired.

#include <cstddef>
#include <limits>
#include <vector>

namespace hybrid {

/// The root functions reported at one instant of an exact segment that fired nothing there. The
/// state reached at a crossing is rounded, so such a root function can be left a hair before its
/// boundary (theta2 = -8.9e-16 for `theta2 == 0`); its crossing time t - g / s then rounds to t
/// itself and would be reported again and again at the same instant without anything changing. A
/// settled root function is not reported again at that instant; a jump (new root functions, and
/// one more event) or an input jump there (Unsettle: the other conjuncts may hold now) unsettles
/// them all.
class SettledRoots {
 public:
  /// Marks the root functions `crossed` (indices below `count`, the number of root functions)
  /// settled at `time`, when `events` events have been recorded; the marks of another instant or
  /// event count are forgotten first.
  void Settle(double time, size_t events, size_t count, const std::vector<int>& crossed);
  /// Whether root function i was settled at `time` with `events` events recorded.
  bool IsSettled(size_t i, double time, size_t events) const;
  /// Forgets every mark (the inputs changed at this instant).
  void Unsettle() { time_ = std::numeric_limits<double>::quiet_NaN(); }

 private:
  std::vector<char> settled_;
  double time_ = std::numeric_limits<double>::quiet_NaN();
  size_t events_ = 0;
};

}  // namespace hybrid
