#include "commands/trajectory_plot.h"

#include <algorithm>
#include <string>
#include <vector>

#include "hybrid/plotting/svg_plot.h"

namespace hybrid::cli {
namespace {

using plotting::AxesStyle;
using plotting::Extent;
using plotting::PlotArea;
using plotting::SvgPlot;

constexpr double kWidth = 760, kLeft = 80, kPlotWidth = 640, kTop = 46;
constexpr double kPanelHeight = 110, kPanelGap = 22, kBandHeight = 22;
constexpr int kMaxLabelledJumps = 40;
const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

// One panel: a name with its unit and the values at the run's times.
struct Panel {
  std::string title;
  std::vector<double> values;
};

std::vector<Panel> PanelsOf(const Simulator& sim, const SimulationResult& r,
                            std::span<const InputSignal> signals, int* left_out) {
  std::vector<Panel> panels;
  const SymbolTable& symbols = sim.system().symbols();
  const auto& names = sim.variable_names();
  for (size_t v = 0; v < names.size(); ++v) {
    Panel p;
    const auto slot = symbols.Find(names[v]);
    p.title = plotting::WithUnit(names[v], slot ? symbols[*slot].unit : "");
    for (const StateSample& s : r.samples) p.values.push_back(s.x[static_cast<Eigen::Index>(v)]);
    panels.push_back(std::move(p));
  }
  for (const InputSignal& signal : signals) {
    Panel p;
    p.title = plotting::WithUnit("input " + symbols[signal.slot].name, symbols[signal.slot].unit);
    for (const StateSample& s : r.samples) p.values.push_back(signal.ValueAt(s.time));
    panels.push_back(std::move(p));
  }
  *left_out = std::max(0, static_cast<int>(panels.size()) - kMaxPlotPanels);
  if (*left_out > 0) panels.resize(kMaxPlotPanels);
  return panels;
}

// Dashed lines at the jumps over [top, bottom], labelled with their transitions above `top`.
void DrawJumps(SvgPlot& svg, const PlotArea& time, const SimulationResult& r, double top,
               double bottom) {
  svg.Group("class=\"jumps\" stroke=\"#888\" stroke-dasharray=\"3,3\" stroke-width=\"0.7\"");
  for (const EventRecord& e : r.events) svg.PlainLine(time.X(e.time), top, time.X(e.time), bottom);
  svg.EndGroup();
  svg.Group("class=\"jump-labels\" fill=\"#555\" font-size=\"9\"");
  const int labelled = std::min(static_cast<int>(r.events.size()), kMaxLabelledJumps);
  double last_x = -1e9;
  for (int k = 0; k < labelled; ++k) {
    // A label only where it does not overlap the previous one (12 pixels apart).
    if (time.X(r.events[static_cast<size_t>(k)].time) - last_x < 12) continue;
    last_x = time.X(r.events[static_cast<size_t>(k)].time);
    std::string label;
    for (const std::string& t : r.events[static_cast<size_t>(k)].transitions) {
      label += (label.empty() ? "" : "+") + t;
    }
    if (label.size() > 32) label = label.substr(0, 30) + "...";
    const double x = time.X(r.events[static_cast<size_t>(k)].time), y = top - 4;
    svg.Text(x, y, label, "transform=\"rotate(-35 " + svg.Number(x) + " " + svg.Number(y) + ")\"");
  }
  svg.EndGroup();
  if (static_cast<int>(r.events.size()) > labelled) {
    svg.Text(kLeft + kPlotWidth, 14,
             std::to_string(r.events.size()) + " jumps (the first " +
                 std::to_string(kMaxLabelledJumps) + " considered for labels)",
             "text-anchor=\"end\" font-size=\"10\"");
  }
}

// The modes as a band: one segment per stay, alternating shades, named where wide enough.
void DrawModes(SvgPlot& svg, const Simulator& sim, const PlotArea& time, const SimulationResult& r,
               double y) {
  svg.Group("class=\"modes\" font-size=\"10\"");
  size_t start = 0;
  int shade = 0;
  for (size_t k = 1; k <= r.samples.size(); ++k) {
    if (k < r.samples.size() && r.samples[k].modes == r.samples[start].modes) continue;
    const double x0 = time.X(r.samples[start].time), x1 = time.X(r.samples[k - 1].time);
    svg.Rect(x0, y, std::max(x1 - x0, 0.5), kBandHeight,
             shade++ % 2 ? "fill=\"#e8eef7\"" : "fill=\"#cfdcef\"");
    const std::string name = sim.ModeLabel(r.samples[start].modes);
    if (x1 - x0 > 6.5 * static_cast<double>(name.size()) + 6) {
      svg.Text(x0 + 3, y + 15, name);
    }
    start = k;
  }
  svg.EndGroup();
  svg.Text(kLeft - 8, y + 15, "mode", "text-anchor=\"end\" font-size=\"10\"");
}

}  // namespace

std::string TrajectoryPlotSvg(const Simulator& sim, const SimulationResult& r,
                              std::span<const InputSignal> signals, const std::string& title) {
  int left_out = 0;
  const std::vector<Panel> panels = PanelsOf(sim, r, signals, &left_out);
  const double t0 = r.samples.empty() ? 0.0 : r.samples.front().time;
  const double t1 = r.samples.empty() ? 1.0 : r.samples.back().time;
  const plotting::Range times = t1 > t0 ? plotting::Range{t0, t1} : plotting::Range{t0, t0 + 1};
  const double panels_bottom =
      kTop + 70 + static_cast<double>(panels.size()) * (kPanelHeight + kPanelGap);
  const double height = panels_bottom + kBandHeight + 50;
  SvgPlot svg(plotting::NumberStyle::kFixed2);
  svg.Start("svg")
      .Attribute("xmlns", "http://www.w3.org/2000/svg")
      .Attribute("width", kWidth)
      .Attribute("height", height)
      .Attribute("font-family", "sans-serif")
      .Attribute("font-size", "11")
      .EndStart();
  svg.Rect(0, 0, kWidth, height, "fill=\"white\"");
  svg.Text(kLeft, 18, title + " (" + std::string(StatusName(r.status)) + ")",
           "font-size=\"13\" font-weight=\"bold\"");
  std::vector<double> ts;
  for (const StateSample& s : r.samples) ts.push_back(s.time);
  const double first_top = kTop + 70;  // room for the slanted jump labels
  for (size_t p = 0; p < panels.size(); ++p) {
    Extent extent;
    for (double v : panels[p].values) extent.Add(v);
    const double top = first_top + static_cast<double>(p) * (kPanelHeight + kPanelGap);
    const PlotArea area{kLeft, top, kPlotWidth, kPanelHeight, times, extent.Padded()};
    AxesStyle style;
    style.x_ticks = p + 1 == panels.size() ? 8 : 0;
    svg.Axes(area, p + 1 == panels.size() ? "time" : "", panels[p].title, style);
    svg.Series(area, ts, panels[p].values,
               std::string("fill=\"none\" stroke-width=\"1.4\" stroke=\"") +
                   kColours[p % std::size(kColours)] + "\"");
  }
  const PlotArea time{kLeft, first_top, kPlotWidth, 1, times, {0, 1}};
  DrawJumps(svg, time, r, first_top, panels_bottom - kPanelGap);
  DrawModes(svg, sim, time, r, panels_bottom + 18);
  if (left_out > 0) {
    svg.Text(kLeft, height - 8,
             std::to_string(left_out) + " more variables or inputs not drawn (at most " +
                 std::to_string(kMaxPlotPanels) + " panels)",
             "font-size=\"10\"");
  }
  return svg.Finish();
}

}  // namespace hybrid::cli
