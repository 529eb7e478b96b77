#include "solvers/simulation/zeno_detection.h"

#include <algorithm>
#include <cmath>

#include "automaton/internal_assert.h"

namespace hybrid {

bool ShrinkGeometrically(const std::vector<double>& d, double* r) {
  HYBRID_ASSERT(d.size() >= 2, "geometric shrinking is judged on at least two intervals");
  bool geometric = std::all_of(d.begin(), d.end(), [](double x) { return x > 0.0; });
  if (geometric) {
    *r = std::pow(d.back() / d.front(), 1.0 / static_cast<double>(d.size() - 1));
    for (size_t i = 1; i < d.size() && geometric; ++i) {
      geometric = std::abs(d[i] / d[i - 1] - *r) <= 0.01 * *r;
    }
    geometric = geometric && *r < 1.0;
  }
  return geometric;
}

std::vector<std::string> LastTransitionNames(const std::vector<EventRecord>& events, size_t k) {
  HYBRID_ASSERT(k <= events.size(), "at most all events are named");
  std::vector<std::string> names;
  for (size_t i = events.size() - k; i < events.size(); ++i) {
    std::string joined;
    for (const auto& s : events[i].transitions) joined += (joined.empty() ? "" : "+") + s;
    names.push_back(joined);
  }
  return names;
}

std::vector<std::string> RepeatingCycle(const std::vector<std::string>& names) {
  std::vector<std::string> cycle;
  for (size_t p = 1; p <= names.size() / 2; ++p) {
    bool periodic = true;
    for (size_t i = p; i < names.size() && periodic; ++i) periodic = names[i] == names[i - p];
    if (periodic) {
      cycle.assign(names.end() - static_cast<long>(p), names.end());
      break;
    }
  }
  return cycle;
}

std::optional<ZenoFinding> DetectZeno(const std::vector<EventRecord>& events,
                                      const SimulationOptions& options) {
  const size_t k = static_cast<size_t>(std::max(options.zeno_events, 4));
  const auto& ev = events;
  if (ev.size() < k) return std::nullopt;
  const double first = ev[ev.size() - k].time;
  const double last = ev.back().time;
  const double scale = std::max(1.0, std::abs(last));
  std::vector<double> d;  // the k - 1 intervals
  for (size_t i = ev.size() - k + 1; i < ev.size(); ++i) d.push_back(ev[i].time - ev[i - 1].time);
  double r = 0.0;
  const bool geometric = ShrinkGeometrically(d, &r);
  // The shortest cycle of transition names that repeats over the last k events.
  const std::vector<std::string> names = LastTransitionNames(ev, k);
  const std::vector<std::string> cycle = RepeatingCycle(names);
  const double remaining = geometric ? d.back() * r / (1.0 - r) : 0.0;
  const bool chattering = last - first < options.zeno_window * scale;
  // Accumulation needs the events to repeat a cycle: a last event that breaks the pattern (the
  // ball's `stop` into `resting`) ends the sequence instead of continuing it.
  const bool accumulating = geometric && !cycle.empty() && remaining < options.zeno_horizon * scale;
  if (!chattering && !accumulating) return std::nullopt;
  ZenoFinding z;
  z.report.accumulation_time = geometric ? last + remaining : last;
  z.report.cycle = cycle.empty() ? names : cycle;
  z.message = std::to_string(k) + " events within " + FormatNumber(last - first) +
              " time units before t = " + FormatNumber(last) +
              "; events accumulate near t = " + FormatNumber(z.report.accumulation_time);
  return z;
}

ZenoReport IterationZenoReport(const std::vector<EventRecord>& events, double t) {
  ZenoReport z;
  z.accumulation_time = t;
  const size_t k = std::min<size_t>(events.size(), 8);
  for (size_t i = events.size() - k; i < events.size(); ++i) {
    for (const auto& name : events[i].transitions) z.cycle.push_back(name);
  }
  return z;
}

}  // namespace hybrid
