#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/checking/property_checker.h"
#include "hybrid/verification/property_prover.h"

namespace hybrid {

/// The `prove` method as a PropertyChecker: PropertyProver (SMT bounded model checking and
/// k-induction) with `options`, every query drawing from `budget`, which the caller owns and which
/// must outlive the checker (one budget may serve several checkers in turn, as in `auto`).
class ProveChecker : public PropertyChecker {
 public:
  ProveChecker(PropertyProver::Options options, SolverBudget& budget)
      : options_(options), budget_(budget) {}
  std::string_view name() const override { return "prove"; }
  std::vector<CheckResult> Check(const System& system,
                                 std::span<const Property> properties) override {
    return PropertyProver(options_).Check(system, properties, budget_);
  }

 private:
  PropertyProver::Options options_;
  SolverBudget& budget_;
};

}  // namespace hybrid
