#pragma once

// Simulating a verifier's trace again, apart from ReplayTrace (solvers/verification/trace.h), for
// tests that judge the states it reaches themselves (shared by the verification tests).

#include <functional>

#include "automaton/system.h"
#include "solvers/simulation/simulator.h"
#include "solvers/verification/trace.h"

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
  const SimulationResult run = simulator.Run(options, trace.inputs.inputs);
  for (const StateSample& s : run.samples) visit(simulator, s);
}

}  // namespace hybrid::testing
