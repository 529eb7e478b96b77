#include "solvers/simulation/settled_roots.h"

#include "automaton/internal_assert.h"

namespace hybrid {

void SettledRoots::Settle(double time, size_t events, size_t count,
                          const std::vector<int>& crossed) {
  if (!(time == time_ && events == events_)) {
    settled_.assign(count, 0);
    time_ = time;
    events_ = events;
  }
  for (int r : crossed) {
    HYBRID_ASSERT(r >= 0 && static_cast<size_t>(r) < settled_.size(),
                  "a settled root function is one of the current ones");
    settled_[r] = 1;
  }
}

bool SettledRoots::IsSettled(size_t i, double time, size_t events) const {
  return time == time_ && events == events_ && i < settled_.size() && settled_[i] != 0;
}

}  // namespace hybrid
