#pragma once

#include <span>
#include <string>

#include "hybrid/automaton/scenario.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::cli {

/// Most panels one plot draws (variables first, then inputs); the rest are left out and the
/// figure says how many.
inline constexpr int kMaxPlotPanels = 12;

/// `hybrid simulate --plot FILE`: an SVG of the run `r` of `sim`. One panel per continuous
/// variable against time (its unit on the axis), then one per input driven by `signals`, stacked
/// on one time axis (at most kMaxPlotPanels); every jump a dashed vertical line across the panels,
/// labelled at the top with its transitions (of the first 40 jumps, those at least 12 pixels from
/// the previous label; the number of jumps when there are more); the modes as a
/// band under the panels, one segment per stay, named where it is wide enough. Titled with
/// `title` and the run's status. Deterministic: the same run gives the same bytes.
std::string TrajectoryPlotSvg(const Simulator& sim, const SimulationResult& r,
                              std::span<const InputSignal> signals, const std::string& title);

}  // namespace hybrid::cli
