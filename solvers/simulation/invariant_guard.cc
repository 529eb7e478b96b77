#include "solvers/simulation/invariant_guard.h"

#include <algorithm>
#include <cmath>

#include "automaton/internal_assert.h"

namespace hybrid {

std::optional<std::pair<size_t, std::string>> StateOutsideInvariant(
    RunState& run, const std::vector<StateSample>& samples, const CompiledModel& model,
    double exempt_from) {
  for (size_t i = 0; i < samples.size(); ++i) {
    const StateSample& s = samples[i];
    if (s.time >= exempt_from) break;
    const auto outside = run.OutsideInvariant(s, s.time);
    if (!outside) continue;
    auto same_instant = [&](size_t j) {
      return samples[j].time == s.time && samples[j].modes == s.modes;
    };
    bool left = false, entered = false;
    for (size_t j = i; j < samples.size() && same_instant(j) && !left; ++j) {
      left = samples[j].kind == StateSample::Kind::kBeforeEvent;
    }
    for (size_t j = i + 1; j-- > 0 && same_instant(j) && !entered;) {
      entered = samples[j].kind == StateSample::Kind::kAfterEvent;
    }
    const double before = std::nextafter(s.time, -std::numeric_limits<double>::infinity());
    if (left && (entered || !run.OutsideInvariant(s, before))) continue;
    return std::make_pair(
        i, "the state recorded at t = " + FormatNumber(s.time) + " lies outside the invariant '" +
               outside->first + "' of mode " + model.ModeLabel(s.modes) + " (residual " +
               FormatNumber(outside->second) + "): the run is not resolved there");
  }
  return std::nullopt;
}

void TruncateUnresolved(SimulationResult& result, size_t index, std::string message) {
  HYBRID_ASSERT(index < result.samples.size(), "the unresolved state is a recorded one");
  result.status = SimulationStatus::kUnresolved;
  result.message = std::move(message);
  result.zeno.reset();
  const double bad_time = result.samples[index].time;
  std::erase_if(result.events, [&](const EventRecord& e) { return e.time >= bad_time; });
  size_t keep = index;
  while (keep > 1 && result.samples[keep - 1].time >= bad_time) --keep;
  result.samples.resize(std::max<size_t>(keep, 1));
  StateSample end = result.samples.back();
  end.kind = StateSample::Kind::kEnd;
  result.samples.push_back(std::move(end));
}

}  // namespace hybrid
