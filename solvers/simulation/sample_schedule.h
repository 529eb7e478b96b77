#pragma once

// The times at which a run records its state besides the start, the end and the events: every
// `sample_step` from the start (uniform samples) and the listed `sample_times`
// (SimulationOptions).

#include <cstddef>

#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// The sample times of a run up to the horizon `until`, taken in time order. Uniform samples: the
/// k-th is due at k * sample_step exactly (no accumulated drift; none when sample_step is 0), and
/// one is taken only before the horizon (the end is recorded anyway). Listed samples:
/// options.sample_times (validated: non-decreasing, within [0, until]), each entry once, so that a
/// repeated time gives one sample per occurrence.
class SampleSchedule {
 public:
  /// Keeps a reference to `options`, which must outlive the schedule.
  SampleSchedule(const SimulationOptions& options, double until);

  /// Whether a uniform sample is due at time `t` (the next uniform time reached, t before the
  /// horizon); if so, moves on to the first uniform time after `t`, k * sample_step with
  /// k = round(t / sample_step) + 1 (the horizon at most).
  bool TakeUniform(double t);
  /// Whether the next listed sample time is at or before `t`; if so, moves past that entry. Call
  /// until false to take every entry due.
  bool TakeListed(double t);
  /// The next time a sample is due: the earlier of the next uniform time and the next listed one,
  /// or the horizon when none is left.
  double Next() const;

 private:
  const SimulationOptions& options_;
  const double until_;
  double next_uniform_;
  size_t next_listed_ = 0;  // in options_.sample_times
};

}  // namespace hybrid
