#include "commands/diagnosis_plot.h"

#include <algorithm>

#include "hybrid/plotting/svg_plot.h"

namespace hybrid::cli {
using plotting::Extent;
using plotting::LegendEntry;
using plotting::LegendKey;
using plotting::NumberStyle;
using plotting::PlotArea;
using plotting::Range;
using plotting::SvgPlot;

namespace {

constexpr double kWidth = 760, kPanelHeight = 170, kLeft = 70, kTop = 60, kGap = 50;

// The y range of one run's panel: measured, baseline and extended values.
Range PanelRange(const AutomatonDiagnosis& d, int run, int channel) {
  Extent extent;
  for (double v : d.runs[run].channels[channel]) extent.Add(v);
  for (double v : d.result.baseline[run].channels[channel]) extent.Add(v);
  for (double v : d.result.extended[run].channels[channel]) extent.Add(v);
  return extent.Padded();
}

void Panel(SvgPlot& svg, const AutomatonDiagnosis& d, int run, int channel, double top) {
  const std::vector<double>& time = d.runs[run].input;
  Extent t;
  for (double v : time) t.Add(v);
  const PlotArea area{kLeft,        top,           kWidth - kLeft - 20,
                      kPanelHeight, t.Padded(0.0), PanelRange(d, run, channel)};
  svg.Axes(area,
           run + 1 == static_cast<int>(std::min<size_t>(d.runs.size(), kMaxDiagnosisPlotRuns))
               ? "time"
               : "",
           d.channels[channel]);
  svg.Text(area.left + 4, top + 12, "run " + d.runs[run].label, R"(font-size="11")");
  svg.Group(R"(fill="#555")");
  for (size_t k = 0; k < time.size(); ++k) {
    const double y = d.runs[run].channels[channel][k];
    if (y == y) svg.Marker(area.X(time[k]), area.Y(y), 1.4);
  }
  svg.EndGroup();
  svg.Series(area, time, d.result.baseline[run].channels[channel],
             R"(fill="none" stroke="#1f77b4" stroke-width="1.4")");
  svg.Series(area, time, d.result.extended[run].channels[channel],
             R"(fill="none" stroke="#ff7f0e" stroke-width="1.4" stroke-dasharray="5 3")");
}

}  // namespace

std::string DiagnosisPlotSvg(const AutomatonDiagnosis& d, int channel) {
  const int runs = static_cast<int>(std::min<size_t>(d.runs.size(), kMaxDiagnosisPlotRuns));
  const double height = kTop + runs * (kPanelHeight + kGap) + 10;
  SvgPlot svg(NumberStyle::kFixed2);
  svg.Start("svg")
      .Attribute("xmlns", "http://www.w3.org/2000/svg")
      .Attribute("width", kWidth)
      .Attribute("height", height)
      .Attribute("font-family", "sans-serif")
      .EndStart();
  std::string cause;
  for (const std::string& c : d.result.cause) cause += (cause.empty() ? "" : ", ") + c;
  std::string title =
      d.channels[channel] + ": measured, baseline and extended model (cause: " + cause + ")";
  if (static_cast<int>(d.runs.size()) > runs) {
    title += "; " + std::to_string(d.runs.size() - runs) + " more runs not drawn";
  }
  svg.Text(kLeft, 20, title, R"(font-size="13")");
  const LegendEntry legend[] = {
      {LegendKey::kSquare, R"(fill="#555")", "measured"},
      {LegendKey::kLine, R"(stroke="#1f77b4" stroke-width="2")", "baseline"},
      {LegendKey::kLine, R"(stroke="#ff7f0e" stroke-width="2" stroke-dasharray="5 3")",
       "extended"}};
  svg.Legend(kLeft, 40, legend);
  for (int r = 0; r < runs; ++r) Panel(svg, d, r, channel, kTop + r * (kPanelHeight + kGap));
  return svg.Finish();
}

}  // namespace hybrid::cli
