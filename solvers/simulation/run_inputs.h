#pragma once

// The input signals of a run: the scenario's merged with the caller's, checked against the model,
// and the times at which they (and scheduled jumps) interrupt the integration.

#include <span>
#include <vector>

#include "hybrid/automaton/scenario.h"
#include "hybrid/automaton/system.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// The scenario's signals of `system` overridden by `signals` (a signal for an input the scenario
/// drives replaces the scenario's, which is dropped; the caller's come last, in their order).
/// Throws std::invalid_argument for a signal that drives something other than an input.
std::vector<InputSignal> MergedInputs(const System& system, std::span<const InputSignal> signals);

/// Throws std::invalid_argument for a signal of `inputs` with no points, a non-finite point, times
/// that do not increase strictly or a value outside its input's bounds (signal by signal, in that
/// order), then for an input of `system` with no signal whose bounds exclude 0. Every signal must
/// drive an input of `system` (MergedInputs).
void ValidateInputs(const System& system, const std::vector<InputSignal>& inputs);

/// The breakpoints of the inputs and the times of scheduled jumps: the times in (0, until) of
/// their points, sorted and distinct. Integration restarts there.
std::vector<double> Breakpoints(const std::vector<InputSignal>& inputs, double until,
                                const std::vector<ScheduledJump>& schedule);

}  // namespace hybrid
