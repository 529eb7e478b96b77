#include "solvers/simulation/option_validation.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hybrid {

void ValidateSimulationOptions(const SimulationOptions& o, double until) {
  auto fail = [](const std::string& message) { throw std::invalid_argument(message); };
  auto positive = [&](double v, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      fail(std::string("the ") + what + " must be positive and finite, got " + FormatNumber(v));
    }
  };
  auto non_negative = [&](double v, const char* what) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      fail(std::string("the ") + what + " must be finite and >= 0, got " + FormatNumber(v));
    }
  };
  positive(until, "horizon `until`");
  positive(o.relative_tolerance, "relative tolerance");
  positive(o.absolute_tolerance, "absolute tolerance");
  non_negative(o.event_tolerance, "event tolerance");
  non_negative(o.resolution_tolerance, "resolution tolerance");
  non_negative(o.sample_step, "sample step `sample_step`");
  non_negative(o.max_step, "largest step");
  non_negative(o.zeno_window, "Zeno window");
  non_negative(o.zeno_horizon, "Zeno horizon");
  if (o.dense_checks < 0 || o.dense_checks > 1000) fail("dense checks must lie in [0, 1000]");
  if (o.max_event_iterations < 1) fail("the event iteration bound must be at least 1");
  if (o.zeno_events < 0) fail("the Zeno event count must be >= 0");
  if (o.max_events < 0) fail("the event limit must be >= 0");
  if (o.max_samples < 0) fail("the sample limit must be >= 0");
  if (o.max_steps < 1) fail("the step limit must be at least 1");
  for (size_t i = 0; i < o.lazy_schedule.size(); ++i) {
    const double t = o.lazy_schedule[i].time;
    if (!(t >= 0.0) || !(t <= until) || (i > 0 && t < o.lazy_schedule[i - 1].time)) {
      fail("scheduled jump " + std::to_string(i + 1) + " at t = " + FormatNumber(t) +
           ": jump times must be non-decreasing and within [0, " + FormatNumber(until) + "]");
    }
  }
  // Samples at sample times: refused before the run rather than grown without bound.
  const double uniform = o.sample_step > 0.0 ? std::floor(until / o.sample_step) : 0.0;
  const double planned = uniform + static_cast<double>(o.sample_times.size());
  if (planned > static_cast<double>(o.max_samples)) {
    std::string what;
    if (uniform > 0.0) {
      what =
          "recording the state every sample step `sample_step` = " + FormatNumber(o.sample_step) +
          " up to the horizon `until` = " + FormatNumber(until);
    }
    if (!o.sample_times.empty()) {
      what += (what.empty() ? "recording the state at " : " and at ") +
              std::to_string(o.sample_times.size()) + " listed times";
    }
    fail(what + " would record " + FormatNumber(planned) + " samples, more than the limit of " +
         std::to_string(o.max_samples) +
         (uniform > 0.0 ? ": give a larger sample step or a shorter horizon" : ""));
  }
}

double Horizon(const System& system, const SimulationOptions& options) {
  if (options.until) return *options.until;
  if (system.scenario()) return system.scenario()->until;
  throw std::invalid_argument(
      "no horizon: set the horizon `until` or declare a scenario in the model");
}

void ValidateSampleTimes(const SimulationOptions& options, double until) {
  for (size_t i = 0; i < options.sample_times.size(); ++i) {
    const double ts = options.sample_times[i];
    if (!std::isfinite(ts) || ts < 0.0 || ts > until) {
      throw std::invalid_argument("sample time " + FormatNumber(ts) + " lies outside [0, " +
                                  FormatNumber(until) + "]");
    }
    if (i > 0 && ts < options.sample_times[i - 1]) {
      throw std::invalid_argument("sample times must not decrease");
    }
  }
}

}  // namespace hybrid
