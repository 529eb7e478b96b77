#pragma once

#include <algorithm>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "solvers/checking/property_checker.h"
#include "solvers/reachability/polyhedral_reachability.h"

namespace hybrid {

/// The `reach` method as a PropertyChecker: PolyhedralReachability with `options`. It handles
/// linear hybrid automata only (Handles says why not). With `usage` (if not null; the caller owns
/// it and it must outlive the checker), each Check adds what it spent there.
class ReachChecker : public PropertyChecker {
 public:
  explicit ReachChecker(PolyhedralReachability::Options options,
                        PolyhedralReachability::Usage* usage = nullptr)
      : options_(std::move(options)), usage_(usage) {}
  std::string_view name() const override { return "reach"; }
  bool Handles(const System& system, std::span<const Property> properties,
               std::string* why) const override {
    return PolyhedralReachability::Handles(
        system, std::vector<Property>(properties.begin(), properties.end()), why);
  }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    PolyhedralReachability::Usage spent;
    std::vector<CheckResult> results = PolyhedralReachability(options_).Check(
        system, std::vector<Property>(properties.begin(), properties.end()), &spent);
    if (usage_) {
      usage_->units_total += spent.units_total;
      usage_->units_used += spent.units_used;
      usage_->states += spent.states;
      usage_->stop = std::max(usage_->stop, spent.stop);
    }
    return results;
  }

 private:
  PolyhedralReachability::Options options_;
  PolyhedralReachability::Usage* usage_;
};

}  // namespace hybrid
