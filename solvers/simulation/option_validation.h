#pragma once

// What a run is asked to do, checked before it starts: its horizon, the settings of
// SimulationOptions (ValidateSimulationOptions, declared in the public header, is defined here)
// and the listed sample times. Messages speak in the API's words (the fields of
// SimulationOptions), never of a command line's options.

#include "hybrid/automaton/system.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// The horizon of a run: options.until, else the scenario's `until`. Throws std::invalid_argument
/// if there is neither.
double Horizon(const System& system, const SimulationOptions& options);

/// Throws std::invalid_argument, naming the first offending time, unless options.sample_times is
/// finite, within [0, until] and non-decreasing.
void ValidateSampleTimes(const SimulationOptions& options, double until);

}  // namespace hybrid
