#include "solvers/simulation/sample_schedule.h"

#include <algorithm>
#include <cmath>

namespace hybrid {

SampleSchedule::SampleSchedule(const SimulationOptions& options, double until)
    : options_(options),
      until_(until),
      next_uniform_(options.sample_step > 0.0 ? options.sample_step : until) {}

bool SampleSchedule::TakeUniform(double t) {
  if (!(t >= next_uniform_ && options_.sample_step > 0.0 && t < until_)) return false;
  // The k-th sample is at k * sample_step exactly (no accumulated drift).
  next_uniform_ =
      std::min(until_, options_.sample_step * (std::floor(t / options_.sample_step + 0.5) + 1.0));
  return true;
}

bool SampleSchedule::TakeListed(double t) {
  const std::vector<double>& listed = options_.sample_times;
  if (!(next_listed_ < listed.size() && listed[next_listed_] <= t)) return false;
  ++next_listed_;
  return true;
}

double SampleSchedule::Next() const {
  const std::vector<double>& listed = options_.sample_times;
  return std::min(next_uniform_, next_listed_ < listed.size() ? listed[next_listed_] : until_);
}

}  // namespace hybrid
