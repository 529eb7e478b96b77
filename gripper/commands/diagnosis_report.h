#pragma once

#include <string>
#include <utility>
#include <vector>

#include "hybrid/gripper/finger_diagnosis.h"

namespace hybrid::cli {

/// The SVG files of `hybrid diagnose DATA.csv --report DIR` as (path, content) pairs, ready for
/// WriteOutputs (commands/output.h):
/// - DIR/run_<label>.svg for each run (Diagnosis::curves), the label sanitised to [A-Za-z0-9_-]
///   (other characters replaced by '_'; an empty label becomes the run's 1-based number) and made
///   unique with a numeric suffix ("_2", "_3", ...) when two runs' names collide: three stacked
///   panels theta1, theta2, theta3 (degrees) against the sample index, each with the measured
///   samples as small grey dots (missing ones skipped), the baseline model as a dashed blue line
///   and the extended model as a solid red line (one <polyline> per stretch of finite values), a
///   legend, axis ticks with numbers, a title with the run label, and a thin strip below showing
///   g (the motor position) against the sample index so the direction of travel is visible.
/// - DIR/residuals.svg: for each joint a panel of residual (measured - model) against g, baseline
///   residuals in blue and extended in red (all runs, small dots), with horizontal dashed lines at
///   +-2 noise standard deviations (sqrt(d.noise.variance[j]), when it is positive).
/// - DIR/summary.svg: a bar chart of held-out MSE per joint, baseline vs extended, with the noise
///   floor variance as a horizontal tick per joint, the cause list as the title and the fitted
///   parameters below it.
/// Paths are DIR + "/" + name, in that order (runs, residuals, summary). Dots are
/// <circle r="1.2">; axis ranges come from the finite data (padded 5%, +-1 around an empty or
/// degenerate range); numbers have at most 4 significant digits; text is XML-escaped; no "nan" or
/// "inf" is ever written (non-finite values are skipped). Throws std::invalid_argument if `dir` is
/// empty.
std::vector<std::pair<std::string, std::string>> DiagnosisReportFiles(const Diagnosis& d,
                                                                      const std::string& dir);

}  // namespace hybrid::cli
