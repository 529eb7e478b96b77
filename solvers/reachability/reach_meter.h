#pragma once

#include <time.h>

#include <algorithm>
#include <cstdint>

#include "hybrid/reachability/polyhedral_reachability.h"
#include "solvers/reachability/convex_polyhedron.h"

namespace hybrid {

/// The CPU time the calling thread has used, in seconds.
inline double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// The deterministic cost count of one PolyhedralReachability::Check, in reach units
/// (kReachUnitsPerBudgetSecond: what each operation costs), and its CPU-time safety net, shared
/// by its explorations: each may use units up to its share.
class ReachMeter {
 public:
  ReachMeter(std::uint64_t total, double cpu_seconds)
      : total_(total), limit_(total), cpu_seconds_(cpu_seconds), start_(ThreadCpuSeconds()) {}

  /// Charges `count` operations that read a polyhedron of the size of `p` (and one of `q`'s).
  void Op(const ConvexPolyhedron& p, std::uint64_t count = 1) {
    used_ += count * (kReachUnitsPerOperation + p.RepresentationBytes() / kReachBytesPerUnit);
  }
  void Op(const ConvexPolyhedron& p, const ConvexPolyhedron& q) {
    used_ += kReachUnitsPerOperation +
             (p.RepresentationBytes() + q.RepresentationBytes()) / kReachBytesPerUnit;
  }

  /// Charges `count` comparisons of bounding boxes.
  void Boxes(std::uint64_t count) { used_ += count * kReachUnitsPerBoxComparison; }
  /// Charges the construction of a location.
  void Location() { used_ += kReachUnitsPerLocation; }
  /// Charges `units` reach units.
  void Charge(std::uint64_t units) { used_ += units; }
  /// Charges the replay of a run along a path of `steps` symbolic states.
  void Replay(std::size_t steps) { used_ += steps * kReachUnitsPerReplayedStep; }

  /// The next exploration's share: what is left split equally among the `parts` still to run.
  void ShareAmong(int parts) {
    share_ = (total_ - std::min(used_, total_)) / static_cast<std::uint64_t>(parts);
    limit_ = used_ + share_;
    ClearSlice();  // a slice left by an exploration that ended early does not carry over
  }
  /// Whether the current exploration has used its share (or its slice, if one is set).
  bool Exhausted() const { return used_ >= std::min(limit_, slice_limit_); }
  /// Whether the current exploration has used its share, whatever the slice.
  bool ShareExhausted() const { return used_ >= limit_; }
  /// Lets the work that follows use at most `units` more (within the share): explorations that
  /// take turns (PolyhedralReachability's exact exploration and the interaction groups') stop at
  /// the end of their slice and resume later.
  void SetSlice(std::uint64_t units) {
    slice_limit_ = units > limit_ - std::min(used_, limit_) ? limit_ : used_ + units;
  }
  /// Removes the slice: the share alone bounds the work.
  void ClearSlice() { slice_limit_ = UINT64_MAX; }
  /// Whether the CPU-time safety net has passed (the thread's time since the Check began).
  bool OutOfTime() const { return ThreadCpuSeconds() - start_ > cpu_seconds_; }

  std::uint64_t used() const { return used_; }
  std::uint64_t total() const { return total_; }
  std::uint64_t share() const { return share_; }
  double cpu_seconds() const { return cpu_seconds_; }

 private:
  std::uint64_t total_;
  std::uint64_t share_ = total_;
  std::uint64_t limit_;
  std::uint64_t slice_limit_ = UINT64_MAX;
  std::uint64_t used_ = 0;
  double cpu_seconds_;
  double start_;  // thread CPU time at the start of the Check
};

}  // namespace hybrid
