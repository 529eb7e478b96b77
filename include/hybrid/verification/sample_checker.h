#pragma once

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/checking/property_checker.h"
#include "hybrid/verification/property_sampler.h"

namespace hybrid {

/// The `sample` method as a PropertyChecker: PropertySampler with `options`, one property after
/// the other; `before` (if set) is called with (index, count, property) before each one (for a
/// progress report). Sampling never proves: its verdicts are `violated`, `reachable` or `unknown`.
class SampleChecker : public PropertyChecker {
 public:
  using Progress = std::function<void(std::size_t, std::size_t, const Property&)>;
  explicit SampleChecker(PropertySampler::Options options, Progress before = {})
      : options_(options), before_(std::move(before)) {}
  std::string_view name() const override { return "sample"; }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    const PropertySampler sampler(options_);
    std::vector<CheckResult> results;
    for (const Property& p : properties) {
      if (before_) before_(results.size(), properties.size(), p);
      results.push_back(sampler.Check(system, p));
    }
    return results;
  }

 private:
  PropertySampler::Options options_;
  Progress before_;
};

}  // namespace hybrid
