#pragma once

namespace hybrid {

/// The first index j in [lo, hi) where `holds(j)` is false, or hi if it holds on all of them.
/// Precondition: `holds` is partitioned on [lo, hi) (true on a prefix, false after it); then this
/// is std::partition_point over the indices, with O(log(hi - lo)) calls of `holds`. (Written out
/// because Clang 14, the fuzz build's compiler, rejects libstdc++ 12's std::views::iota.)
template <class Predicate>
long PartitionIndex(long lo, long hi, const Predicate& holds) {
  while (lo < hi) {
    const long mid = lo + (hi - lo) / 2;
    if (holds(mid)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

}  // namespace hybrid
