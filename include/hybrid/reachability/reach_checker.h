#pragma once

#include <algorithm>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/checking/property_checker.h"
#include "hybrid/reachability/polyhedral_reachability.h"

namespace hybrid {

/// The `reach` method as a PropertyChecker: PolyhedralReachability with `options`. It handles
/// linear hybrid automata only (Handles says why not). With `usage` (if not null; the caller owns
/// it and it must outlive the checker), each Check adds what it spent there (emplacing it on the
/// first Check: it stays empty when reachability never ran).
class ReachChecker : public PropertyChecker {
 public:
  explicit ReachChecker(PolyhedralReachability::Options options,
                        std::optional<PolyhedralReachability::Usage>* usage = nullptr)
      : options_(std::move(options)), usage_(usage) {}
  std::string_view name() const override { return "reach"; }
  bool Handles(const System& system, std::span<const Property> properties,
               std::string* why) const override {
    std::string reason;
    const bool handles = PolyhedralReachability::Handles(
        system, std::vector<Property>(properties.begin(), properties.end()), &reason);
    if (why) *why = reason;
    return handles;
  }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    PolyhedralReachability::Usage spent;
    std::vector<CheckResult> results = PolyhedralReachability(options_).Check(
        system, std::vector<Property>(properties.begin(), properties.end()), &spent);
    if (usage_) {
      PolyhedralReachability::Usage& total = usage_->has_value() ? **usage_ : usage_->emplace();
      total.units_total += spent.units_total;
      total.units_used += spent.units_used;
      total.states += spent.states;
      total.stop = std::max(total.stop, spent.stop);
    }
    return results;
  }

 private:
  PolyhedralReachability::Options options_;
  std::optional<PolyhedralReachability::Usage>* usage_;
};

}  // namespace hybrid
