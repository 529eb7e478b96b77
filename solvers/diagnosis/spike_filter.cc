#include "hybrid/diagnosis/spike_filter.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hybrid {

std::vector<char> SpikeMask(const std::vector<double>& values, double threshold) {
  std::vector<char> spike(values.size(), 0);
  if (!(threshold > 0.0) || !std::isfinite(threshold)) return spike;
  std::vector<size_t> present;  // indices of the non-missing samples, in order
  for (size_t k = 0; k < values.size(); ++k) {
    if (!std::isnan(values[k])) present.push_back(k);
  }
  const size_t n = present.size();
  if (n < 3) return spike;  // no median that resists a spike
  const size_t width = std::min<size_t>(5, n);
  for (size_t i = 0; i < n; ++i) {
    // The window [from, from + width) of `present`, centred on i where the run allows.
    const size_t from = std::min(i >= 2 ? i - 2 : 0, n - width);
    std::array<double, 5> window{};
    for (size_t w = 0; w < width; ++w) window[w] = values[present[from + w]];
    std::nth_element(window.begin(), window.begin() + width / 2, window.begin() + width);
    const double median = window[width / 2];
    if (std::abs(values[present[i]] - median) > threshold) spike[present[i]] = 1;
  }
  return spike;
}

}  // namespace hybrid
