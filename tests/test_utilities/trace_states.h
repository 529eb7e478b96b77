#pragma once

// Simulating a verifier's trace again, apart from ReplayTrace (include/hybrid/checking/trace.h),
// for tests that judge the states it reaches themselves (shared by the verification tests).

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::testing {

/// Simulates `trace` on a fresh copy of `system` (the trace's parameters and initial values set,
/// its inputs until its horizon, a state recorded every horizon / `samples` besides the events)
/// and calls visit(simulator, state) for every recorded state, in order.
inline void ForEachTraceState(
    const System& system, const Trace& trace, int samples,
    const std::function<void(const Simulator&, const StateSample&)>& visit) {
  System copy = system;
  for (const auto& [name, value] : trace.parameters) copy.SetParameter(name, value);
  for (const auto& [name, value] : trace.initial_values) copy.SetInitialValue(name, value);
  const Simulator simulator(copy);
  SimulationOptions options;
  options.until = trace.inputs.until;
  options.sample_step = trace.inputs.until / samples;
  options.lazy_schedule = trace.schedule;  // lazy jumps where the verifier chose them
  const SimulationResult run = simulator.Run(options, trace.inputs.inputs);
  for (const StateSample& s : run.samples) visit(simulator, s);
}

/// Replays a copy of the result's trace (ReplayTrace): it must reach its target at a recorded
/// state (test failures otherwise). Returns the replayed copy (empty without a trace).
inline Trace Replayed(const System& system, const Property& property, const CheckResult& result) {
  EXPECT_TRUE(result.trace.has_value());
  if (!result.trace) return {};
  Trace copy = *result.trace;
  copy.run = {};
  copy.state_index = -1;
  EXPECT_TRUE(ReplayTrace(system, property, copy));
  EXPECT_GE(copy.state_index, 0);
  EXPECT_LT(copy.state_index, static_cast<int>(copy.run.samples.size()));
  return copy;
}

/// The value of variable `name` (a System name) at the trace's target state; a test failure and
/// 0 if there is no such variable or target state.
inline double AtTarget(const System& system, const Trace& trace, const std::string& name) {
  const Simulator sim(system);
  const auto& names = sim.variable_names();
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  if (it == names.end() || trace.state_index < 0 ||
      trace.state_index >= static_cast<int>(trace.run.samples.size())) {
    return 0.0;
  }
  return trace.run.samples[static_cast<size_t>(trace.state_index)]
      .x[static_cast<int>(it - names.begin())];
}

}  // namespace hybrid::testing
