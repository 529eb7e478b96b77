#pragma once

// Zeno detection over the events of a run (SimulationOptions::zeno_events and the rules stated
// there): chattering (many events in a vanishing window) and accumulation (a cycle of transitions
// whose intervals shrink geometrically, close to its limit point), and the report of an event
// iteration that does not settle at one instant.

#include <optional>
#include <string>
#include <vector>

#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// A run found Zeno: the report and the message of the result.
struct ZenoFinding {
  ZenoReport report;
  std::string message;
};

/// Whether the last k = max(options.zeno_events, 4) of `events` are Zeno (fewer events: never),
/// with time scale s = max(1, |t_last|): (a) chattering, t_last - t_first < zeno_window * s; or
/// (b) accumulation, their intervals shrink geometrically with ratio r (ShrinkGeometrically), their
/// transitions repeat a cycle (RepeatingCycle) and the predicted remaining time
/// d_last * r / (1 - r) is below zeno_horizon * s. The report's accumulation time is
/// t_last + d_last * r / (1 - r) for geometric intervals, else t_last; its cycle the repeating
/// cycle, else the last k events' transitions.
std::optional<ZenoFinding> DetectZeno(const std::vector<EventRecord>& events,
                                      const SimulationOptions& options);

/// The report of an event iteration that does not settle at time `t`: accumulation at `t`, the
/// cycle the transitions of the last (at most 8) of `events`, oldest first.
ZenoReport IterationZenoReport(const std::vector<EventRecord>& events, double t);

/// Whether the intervals `d` (at least two) shrink geometrically: all positive, every ratio of
/// consecutive intervals within 1% of r = (d_last / d_first)^(1 / (|d| - 1)), and r < 1. Sets *r
/// when all are positive (left alone otherwise).
bool ShrinkGeometrically(const std::vector<double>& d, double* r);

/// The transitions of each of the last k of `events` (k <= events.size()), an event's qualified
/// names joined with "+", oldest first.
std::vector<std::string> LastTransitionNames(const std::vector<EventRecord>& events, size_t k);

/// The shortest cycle that `names` repeats (a period p of at most half its length: names[i] ==
/// names[i - p] throughout), as its last p names; empty if there is none.
std::vector<std::string> RepeatingCycle(const std::vector<std::string>& names);

}  // namespace hybrid
