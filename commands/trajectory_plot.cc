#include "commands/trajectory_plot.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
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
constexpr double kPanelHeight = 110, kPanelGap = 22, kBandHeight = 22, kRowGap = 3;
constexpr double kLegendLine = 14;
constexpr int kMaxLegendLines = 3;
const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};
// Pale fills of the mode bands, one per mode of a row (by first appearance, repeating).
const char* const kBandColours[] = {"#cfdcef", "#f6dcc4", "#d5ecd0", "#e6d5ef",
                                    "#f4d0d0", "#e9e4c8", "#d0ece9", "#eed6e6"};

// Text extent estimates for a sans-serif font of size `font` (pixels): at most 0.6 em per
// character (digits, lower case and underscores are narrower), 0.8 em above the baseline and
// 0.25 em below it.
constexpr double kEm = 0.6, kAscent = 0.8, kDescent = 0.25;
double TextWidth(size_t characters, double font) {
  return kEm * font * static_cast<double>(characters);
}

// The jump labels: font size, slant (degrees, rising to the right), the lowest y their tops may
// reach (under the title) and the padding kept between two labels.
constexpr double kLabelFont = 9, kLabelSlant = 35, kLabelCeiling = 26, kLabelPad = 2;
const double kCos = std::cos(kLabelSlant * std::numbers::pi / 180);
const double kSin = std::sin(kLabelSlant * std::numbers::pi / 180);

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

// A slanted jump label whose baseline starts at (x, the labels' common y) and runs `length`
// pixels up to the right.
struct SlantedLabel {
  double x = 0;
  double length = 0;
};

// Whether two slanted labels overlap (padding included). In the frame of the text (along the
// baseline, across it downwards) each is the rectangle [x cos, x cos + length] x
// [x sin - ascent, x sin + descent], since their anchors share one y.
bool Overlap(const SlantedLabel& a, const SlantedLabel& b) {
  const double a0 = a.x * kCos, b0 = b.x * kCos;
  const bool along = a0 < b0 + b.length + kLabelPad && b0 < a0 + a.length + kLabelPad;
  const bool across = std::abs(a.x - b.x) * kSin < (kAscent + kDescent) * kLabelFont + kLabelPad;
  return along && across;
}

// The text of jump `e`'s label at anchor (x, y), shortened with "..." to stay under
// kLabelCeiling and inside the figure; "" when too little of it would fit.
std::string FittedJumpLabel(const EventRecord& e, double x, double y) {
  std::string label;
  for (const std::string& t : e.transitions) label += (label.empty() ? "" : "+") + t;
  // The top of the label's end: (x + L cos - ascent sin, y - L sin - ascent cos).
  const double ascent = kAscent * kLabelFont;
  const double by_height = (y - kLabelCeiling - ascent * kCos) / kSin;
  const double by_width = (kWidth - 2 - x + ascent * kSin) / kCos;
  const double fit = std::floor(std::min(by_height, by_width) / TextWidth(1, kLabelFont));
  if (static_cast<double>(label.size()) <= fit) return label;
  if (fit < 6) return "";
  return label.substr(0, static_cast<size_t>(fit) - 3) + "...";
}

// Dashed lines at the jumps over [top, bottom], labelled above `top` where a label overlaps no
// other; the number of jumps left unlabelled, if any, at the top right.
void DrawJumps(SvgPlot& svg, const PlotArea& time, const SimulationResult& r, double top,
               double bottom) {
  svg.Group("class=\"jumps\" stroke=\"#888\" stroke-dasharray=\"3,3\" stroke-width=\"0.7\"");
  for (const EventRecord& e : r.events) svg.PlainLine(time.X(e.time), top, time.X(e.time), bottom);
  svg.EndGroup();
  svg.Group("class=\"jump-labels\" fill=\"#555\" font-size=\"9\"");
  const double y = top - 4;
  size_t labelled = 0;
  SlantedLabel last{-1e9, 0};
  for (const EventRecord& e : r.events) {
    // Labels go left to right on one baseline height, so a label that overlaps none of the
    // drawn ones is one that does not overlap the last drawn.
    const double x = time.X(e.time);
    const std::string text = FittedJumpLabel(e, x, y);
    const SlantedLabel box{x, TextWidth(text.size(), kLabelFont)};
    if (text.empty() || Overlap(last, box)) continue;
    last = box;
    ++labelled;
    svg.Text(x, y, text, "transform=\"rotate(-35 " + svg.Number(x) + " " + svg.Number(y) + ")\"");
  }
  svg.EndGroup();
  if (labelled < r.events.size()) {
    svg.Text(kLeft + kPlotWidth, 14,
             std::to_string(r.events.size()) + " jumps, " + std::to_string(labelled) +
                 " labelled (the other labels would overlap)",
             "class=\"jump-count\" text-anchor=\"end\" font-size=\"10\"");
  }
}

// One stay in a mode: the mode (an index into ModeRow::names) and its pixel columns.
struct Stay {
  int mode = 0;
  double t0 = 0, t1 = 0;
  double x0 = 0, x1 = 0;
};

// One row of the mode strip: a component's modes (or, for a system with too many components,
// the joined modes of all), its stays and whether each mode's name is shown in full somewhere.
struct ModeRow {
  std::string title;
  std::vector<std::string> names;
  std::vector<Stay> stays;
  std::vector<bool> named;
};

constexpr double kBandFont = 10;
constexpr double kBandInset = 3;

// The characters of a mode name that fit in a band `width` pixels wide.
size_t CharactersThatFit(double width) {
  return static_cast<size_t>(
      std::max(0.0, std::floor((width - 2 * kBandInset) / TextWidth(1, kBandFont))));
}

// The mode name of row `row` (of `rows`) in the modes `modes`.
std::string RowModeName(const Simulator& sim, std::span<const int> modes, size_t row, size_t rows) {
  if (rows == 1) return sim.ModeLabel(modes);
  const Component& c = sim.system().components()[row];
  return c.automaton.modes()[static_cast<size_t>(modes[row])].name;
}

std::vector<ModeRow> ModeRowsOf(const Simulator& sim, const SimulationResult& r,
                                const PlotArea& time) {
  const auto components = sim.system().components();
  const size_t rows =
      components.size() > 1 && components.size() <= static_cast<size_t>(kMaxModeRows)
          ? components.size()
          : 1;
  std::vector<ModeRow> out(rows);
  for (size_t row = 0; row < rows; ++row) {
    ModeRow& m = out[row];
    const Component& c = components[row];
    m.title = rows == 1 ? "mode" : (c.instance.empty() ? c.automaton.name() : c.instance);
    std::map<std::string, int> index;
    for (const StateSample& s : r.samples) {
      const std::string name = RowModeName(sim, s.modes, row, rows);
      const auto [it, added] = index.emplace(name, static_cast<int>(m.names.size()));
      if (added) m.names.push_back(name);
      if (m.stays.empty() || m.stays.back().mode != it->second) {
        m.stays.push_back({it->second, s.time, s.time, 0, 0});
      }
      m.stays.back().t1 = s.time;
    }
    m.named.assign(m.names.size(), false);
    for (Stay& stay : m.stays) {
      stay.x0 = time.X(stay.t0);
      stay.x1 = time.X(stay.t1);
      const size_t fit = CharactersThatFit(stay.x1 - stay.x0);
      if (m.names[static_cast<size_t>(stay.mode)].size() <= fit) {
        m.named[static_cast<size_t>(stay.mode)] = true;
      }
    }
  }
  return out;
}

// The bands of `row` at height `y`: one per stay, with its tooltip and its (shortened) name.
void DrawModeRow(SvgPlot& svg, const ModeRow& row, double y) {
  for (const Stay& stay : row.stays) {
    const std::string& name = row.names[static_cast<size_t>(stay.mode)];
    const double width = std::max(stay.x1 - stay.x0, 0.5);
    svg.Start("rect")
        .Attribute("x", stay.x0)
        .Attribute("y", y)
        .Attribute("width", width)
        .Attribute("height", kBandHeight)
        .Attribute("fill", kBandColours[stay.mode % std::ssize(kBandColours)])
        .Attributes("stroke=\"white\" stroke-width=\"0.6\"")
        .EndStart();
    svg.Start("title").Content(
        "title", plotting::XmlEscape(name + ": t = " + plotting::FormatSignificant(stay.t0, 6) +
                                     " to " + plotting::FormatSignificant(stay.t1, 6)));
    svg.End("rect");
    const size_t fit = CharactersThatFit(width);
    if (name.size() <= fit) {
      svg.Text(stay.x0 + kBandInset, y + 15, name);
    } else if (fit >= 4) {
      svg.Text(stay.x0 + kBandInset, y + 15, name.substr(0, fit - 3) + "...");
    }
  }
  svg.Text(kLeft - 8, y + 15, row.title, "text-anchor=\"end\" font-size=\"10\"");
}

// A legend entry: a mode not named in full in the strip, its band colour and its x.
struct LegendEntry {
  std::string label;
  int colour = 0;
  double x = 0;
};

// The legend's lines (at most kMaxLegendLines) of the modes shown nowhere in full; `left_out`:
// how many did not fit.
std::vector<std::vector<LegendEntry>> LegendLines(const std::vector<ModeRow>& rows, int* left_out) {
  std::vector<std::vector<LegendEntry>> lines;
  *left_out = 0;
  double x = kLeft + kPlotWidth;
  for (const ModeRow& row : rows) {
    for (size_t m = 0; m < row.names.size(); ++m) {
      if (row.named[m]) continue;
      const std::string label = (rows.size() > 1 ? row.title + ": " : "") + row.names[m];
      const double width = 14 + TextWidth(label.size(), kBandFont) + 10;
      if (x + width > kLeft + kPlotWidth) {
        if (static_cast<int>(lines.size()) == kMaxLegendLines) {
          ++*left_out;
          continue;
        }
        lines.emplace_back();
        x = kLeft;
      }
      lines.back().push_back({label, static_cast<int>(m), x});
      x += width;
    }
  }
  return lines;
}

void DrawLegend(SvgPlot& svg, const std::vector<std::vector<LegendEntry>>& lines, int left_out,
                double y) {
  if (lines.empty()) return;
  svg.Group("class=\"mode-legend\" font-size=\"10\"");
  svg.Text(kLeft - 8, y, "modes", "text-anchor=\"end\"");
  for (size_t l = 0; l < lines.size(); ++l) {
    const double line_y = y + static_cast<double>(l) * kLegendLine;
    for (const LegendEntry& e : lines[l]) {
      svg.Rect(e.x, line_y - 9, 10, 10,
               std::string("fill=\"") + kBandColours[e.colour % std::ssize(kBandColours)] +
                   "\" stroke=\"#999\" stroke-width=\"0.5\"");
      svg.Text(e.x + 14, line_y, e.label);
    }
  }
  if (left_out > 0) {
    svg.Text(kLeft + kPlotWidth, y + static_cast<double>(lines.size()) * kLegendLine,
             "and " + std::to_string(left_out) + " more (a band's tooltip names its mode)",
             "text-anchor=\"end\"");
  }
  svg.EndGroup();
}

// The panels, one under the other from `first_top`, each with its axes and series.
void DrawPanels(SvgPlot& svg, const std::vector<Panel>& panels, const plotting::Range& times,
                const SimulationResult& r, double first_top) {
  std::vector<double> ts;
  for (const StateSample& s : r.samples) ts.push_back(s.time);
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
}

}  // namespace

SimulationOptions PlotOptions(const SimulationOptions& options, double until) {
  SimulationOptions plotted = options;
  const long n = std::min<long>(kPlotSamples, options.max_samples);
  if (options.sample_step > 0.0 || n <= 0 || !(until > 0.0)) return plotted;
  plotted.sample_step = until / static_cast<double>(n);
  return plotted;
}

std::string TrajectoryPlotSvg(const Simulator& sim, const SimulationResult& r,
                              std::span<const InputSignal> signals, const std::string& title) {
  int left_out = 0;
  const std::vector<Panel> panels = PanelsOf(sim, r, signals, &left_out);
  const double t0 = r.samples.empty() ? 0.0 : r.samples.front().time;
  const double t1 = r.samples.empty() ? 1.0 : r.samples.back().time;
  const plotting::Range times = t1 > t0 ? plotting::Range{t0, t1} : plotting::Range{t0, t0 + 1};
  const double first_top = kTop + 70;  // room for the slanted jump labels
  const double panels_bottom =
      first_top + static_cast<double>(panels.size()) * (kPanelHeight + kPanelGap);
  const PlotArea time{kLeft, first_top, kPlotWidth, 1, times, {0, 1}};
  const std::vector<ModeRow> rows = ModeRowsOf(sim, r, time);
  int legend_left_out = 0;
  const auto legend = LegendLines(rows, &legend_left_out);
  const double strip_top = panels_bottom + 18;
  const double strip_bottom =
      strip_top + static_cast<double>(rows.size()) * (kBandHeight + kRowGap);
  const double legend_top = strip_bottom + 14;
  const double legend_lines = static_cast<double>(legend.size() + (legend_left_out > 0 ? 1 : 0));
  const double height = strip_bottom + legend_lines * kLegendLine + 36;
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
  DrawPanels(svg, panels, times, r, first_top);
  DrawJumps(svg, time, r, first_top, panels_bottom - kPanelGap);
  svg.Group("class=\"modes\" font-size=\"10\"");
  for (size_t k = 0; k < rows.size(); ++k) {
    DrawModeRow(svg, rows[k], strip_top + static_cast<double>(k) * (kBandHeight + kRowGap));
  }
  svg.EndGroup();
  DrawLegend(svg, legend, legend_left_out, legend_top);
  if (left_out > 0) {
    svg.Text(kLeft, height - 8,
             std::to_string(left_out) + " more variables or inputs not drawn (at most " +
                 std::to_string(kMaxPlotPanels) + " panels)",
             "font-size=\"10\"");
  }
  return svg.Finish();
}

}  // namespace hybrid::cli
