#pragma once

#include <functional>

namespace hybrid {

/// Calls body(0), ..., body(count - 1), on up to `threads` threads (the calling one included);
/// serially when threads <= 1 or count <= 1. Which thread runs which index is unspecified, so
/// `body` must only write to its own index's results. The first exception a call throws is
/// rethrown once every thread has stopped (the remaining indices still run).
void ParallelFor(int count, int threads, const std::function<void(int)>& body);

}  // namespace hybrid
