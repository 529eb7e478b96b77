#include "hybrid/automaton/scenario.h"

#include <algorithm>

namespace hybrid {

double InputSignal::ValueAt(double t) const {
  if (points.empty()) return 0.0;
  if (t <= points.front().first) return points.front().second;
  if (t >= points.back().first) return points.back().second;
  // First point with time > t; t lies in [prev.time, next.time).
  auto next = std::upper_bound(points.begin(), points.end(), t,
                               [](double x, const auto& p) { return x < p.first; });
  auto prev = next - 1;
  if (shape == Shape::kStep) return prev->second;
  const double w = (t - prev->first) / (next->first - prev->first);
  return prev->second + w * (next->second - prev->second);
}

}  // namespace hybrid
