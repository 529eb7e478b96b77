#pragma once

#include <span>
#include <string>

#include "hybrid/automaton/scenario.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::cli {

/// Most panels one plot draws (variables first, then inputs); the rest are left out and the
/// figure says how many.
inline constexpr int kMaxPlotPanels = 12;

/// Most components given a row of their own in the mode strip; a system with more draws one row
/// of joined mode names ("A.open|B.closed").
inline constexpr int kMaxModeRows = 8;

/// The states a plot records between events when the run itself records none: about this many
/// across the horizon (StateSample::Kind::kSample), so that curves are drawn from the model
/// rather than joined by straight lines from one event to the next.
inline constexpr int kPlotSamples = 600;

/// The options of the run a plot of a run with `options` up to horizon `until` draws: `options`
/// itself when it records states between events already (a `sample_step` > 0) or may record none
/// (max_samples 0); otherwise the same options with `sample_step` until / n, n = kPlotSamples or
/// max_samples if smaller, so the plotted run stays within the simulator's bounds. The states it
/// adds are stops of the integration, so outputs other than the plot keep the run with `options`.
SimulationOptions PlotOptions(const SimulationOptions& options, double until);

/// `hybrid simulate --plot FILE`: an SVG of the run `r` of `sim`. One panel per continuous
/// variable against time (its unit on the axis), then one per input driven by `signals`, stacked
/// on one time axis (at most kMaxPlotPanels), each a polyline through the run's recorded states.
/// Every jump is a dashed vertical line across the panels, labelled above them with its
/// transitions, slanted: a label is drawn only where its box (an estimate of the text's extent,
/// 0.6 em per character) overlaps no other label's and stays inside the figure under the title
/// (shortened with "..." to fit), and the figure says how many jumps went unlabelled. The modes
/// are a strip under the panels, one row per component (kMaxModeRows at most), one band per stay
/// coloured by mode, each band holding its mode's name where the name fits (shortened with "..."
/// where a part fits) and a tooltip (<title>) with the name and the stay's times; modes whose
/// names are nowhere shown in full are listed in a legend under the strip. Titled with `title`
/// and the run's status. Deterministic: the same run gives the same bytes.
std::string TrajectoryPlotSvg(const Simulator& sim, const SimulationResult& r,
                              std::span<const InputSignal> signals, const std::string& title);

}  // namespace hybrid::cli
