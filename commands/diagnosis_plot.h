#pragma once

#include <string>

#include "hybrid/model_diagnosis/automaton_diagnosis.h"

namespace hybrid::cli {

/// Most runs one plot draws (one panel each, stacked); the figure says how many it left out.
inline constexpr int kMaxDiagnosisPlotRuns = 8;

/// `hybrid diagnose MODEL DATA --report DIR`: an SVG of observed variable `channel` of `d`
/// (index into AutomatonDiagnosis::channels): one panel per run (at most kMaxDiagnosisPlotRuns),
/// against time, with the measured samples as dots, the baseline's prediction as a blue line and
/// the extended model's as an orange one (the same as the baseline's when no cause is named),
/// titled with the cause. Deterministic: the same diagnosis gives the same bytes.
std::string DiagnosisPlotSvg(const AutomatonDiagnosis& d, int channel);

}  // namespace hybrid::cli
