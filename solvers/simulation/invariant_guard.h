#pragma once

// The general guard of every run (Simulator::FirstStateOutsideInvariant): no recorded state may
// lie outside its modes' invariants beyond the resolution tolerance, and a result that has one
// ends there as kUnresolved.

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/simulation/simulator.h"
#include "solvers/simulation/compiled_model.h"
#include "solvers/simulation/run_state.h"

namespace hybrid {

/// The first of `samples` outside its modes' invariants beyond the resolution tolerance
/// (RunState::OutsideInvariant at its own time): its index and a message naming its time, the
/// invariant, the mode and the residual; nullopt if none. Exempt: a state that a jump leaves at
/// its own instant (a kBeforeEvent sample in the same modes at the same time, itself or later) if
/// it was entered at that instant (a kAfterEvent sample in the same modes at the same time, itself
/// or earlier: an urgent transition may leave at once a mode entered outside its invariant) or was
/// inside with the inputs just before that instant (an input jump put it outside: a lazy
/// transition takes it away); and states at or after `exempt_from` (the final instant of a run
/// that stopped on a violated invariant). Every sample must fit `model` (modes in range, one value
/// per variable). Leaves `run`'s environment at the last state checked.
std::optional<std::pair<size_t, std::string>> StateOutsideInvariant(
    RunState& run, const std::vector<StateSample>& samples, const CompiledModel& model,
    double exempt_from = std::numeric_limits<double>::infinity());

/// Ends `result` as kUnresolved with `message` at its recorded state `index` (which is not
/// trustworthy; index < samples.size()): the Zeno report is dropped, so are the events and states
/// from that state's time on, and the last state kept is repeated as the end (kEnd). The start
/// (index 0) is always kept.
void TruncateUnresolved(SimulationResult& result, size_t index, std::string message);

}  // namespace hybrid
