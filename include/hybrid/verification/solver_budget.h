#pragma once

#include <cstdint>
#include <functional>
#include <utility>

namespace hybrid {

/// Solver resource units (the SMT solver's deterministic `rlimit` count) in one budget second:
/// about one second of solver work on the machine it was calibrated on (see docs/verification.md).
inline constexpr std::uint64_t kResourceUnitsPerBudgetSecond = 2'500'000;

/// The solver budget of one check: every SMT query of the check draws resource units from it
/// (the SMT solver's `rlimit` count, which depends on the formulas only, not on the machine or its
/// load), so the same check with the same budget always gives the same verdicts. A query is given
/// at most what is left; once nothing is left, no query runs and what is undecided stays `unknown`.
///
/// A safety net bounds CPU time where the solver's count misses its work (some nonlinear
/// arithmetic; a search query of the finger that allocates about 200 million times per second):
/// with T = max(60 s, 10 s per budget second), no query starts after the process has used T of CPU
/// time since the budget's creation, and a query given u units runs at most 10 s of CPU time per
/// budget second of u (at least 10 s, at most T). CPU time, not wall-clock time, so that the
/// machine's load does not change where it fires; a query it stops is `unknown`, is charged its
/// whole allowance, and its solver gets no further query, so that what follows does not depend on
/// where it stopped. Only the machine's speed can then change a verdict, and the reasons say when
/// the net fired.
///
/// Not thread-safe: the queries of one budget run one after the other.
class SolverBudget {
 public:
  /// A budget of `seconds` budget seconds (positive and finite, at most 10^6), i.e. seconds *
  /// kResourceUnitsPerBudgetSecond resource units. Throws std::invalid_argument otherwise.
  explicit SolverBudget(double seconds);

  double seconds() const { return seconds_; }
  std::uint64_t total() const { return total_; }
  std::uint64_t used() const { return used_; }
  std::uint64_t remaining() const { return used_ < total_ ? total_ - used_ : 0; }
  /// Records `units` spent (the budget may be overdrawn by the last query's overshoot).
  void Charge(std::uint64_t units) {
    used_ += units;
    if (observer_) observer_(*this);
  }
  /// Called after every Charge (for a progress report; it must not throw or charge).
  void SetObserver(std::function<void(const SolverBudget&)> observer) {
    observer_ = std::move(observer);
  }

  /// The safety net's deadline, in seconds of the process's CPU time from the budget's
  /// creation: max(60, 10 * seconds()).
  double SafetySeconds() const;
  /// The CPU-time limit of a query given `units` resource units, in seconds: 10 s per budget
  /// second of `units`, at least 10 s, at most SafetySeconds().
  double SafetyCpuSeconds(std::uint64_t units) const;
  /// Whether the deadline has passed (no query may start).
  bool SafetyExpired() const;
  /// Records that the safety net stopped a query; safety_stopped() tells.
  void NoteSafetyStop() { safety_stopped_ = true; }
  bool safety_stopped() const { return safety_stopped_; }

 private:
  double seconds_;
  std::uint64_t total_;
  std::uint64_t used_ = 0;
  double start_cpu_ = 0.0;  // the process's CPU time at creation, in seconds
  bool safety_stopped_ = false;
  std::function<void(const SolverBudget&)> observer_;
};

}  // namespace hybrid
