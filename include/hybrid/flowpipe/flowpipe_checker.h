#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hybrid/checking/property_checker.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"

namespace hybrid {

/// The `flowpipe` method as a PropertyChecker: FlowpipeReachability with `options`. It handles
/// systems whose flows are polynomial or rational in the variables and affine in the inputs
/// (Handles says which flow is not). With `reach_set` (if not null; the caller owns it and it
/// must outlive the checker), each Check leaves there the boxes it explored.
class FlowpipeChecker : public PropertyChecker {
 public:
  explicit FlowpipeChecker(FlowpipeReachability::Options options,
                           FlowpipeReachability::ReachSet* reach_set = nullptr)
      : options_(std::move(options)), reach_set_(reach_set) {}
  std::string_view name() const override { return "flowpipe"; }
  bool Handles(const System& system, std::span<const Property> properties,
               std::string* why) const override {
    return FlowpipeReachability::Handles(system, properties, why);
  }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    return FlowpipeReachability(options_).Check(system, properties, nullptr, reach_set_);
  }
  /// A flowpipe encloses the reachable states: it proves, or says `unknown`.
  bool Falsifies() const override { return false; }

 private:
  FlowpipeReachability::Options options_;
  FlowpipeReachability::ReachSet* reach_set_;
};

}  // namespace hybrid
