#pragma once

#include <string>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/checking/check_result.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"

namespace hybrid::cli {

/// A counterexample or witness to draw: the (x, y) values of its recorded states.
struct ReachPlotTrace {
  std::string label;
  std::vector<double> xs;
  std::vector<double> ys;
};

/// `hybrid check --plot-reach FILE --axes X,Y`: an SVG of the flowpipe's boxes projected on
/// variables `x` and `y` (one light rectangle per step of every mode entry, as Flow* and SpaceEx
/// draw their flowpipes), each property bound that reads one of the two variables alone (`x <= 22`)
/// as a dashed red line labelled with the property's name, and the counterexample and witness
/// traces as red polylines. Titled with `title`. Throws std::invalid_argument ("no variable 'q';
/// the variables are: x, y") when an axis is not a variable of the reach set. Deterministic.
std::string ReachPlotSvg(const FlowpipeReachability::ReachSet& set, const std::string& x,
                         const std::string& y, const std::vector<Property>& properties,
                         const std::vector<ReachPlotTrace>& traces, const std::string& title);

}  // namespace hybrid::cli
