#include "commands/reach_plot.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hybrid/plotting/svg_plot.h"

namespace hybrid::cli {
namespace {

using plotting::AxesStyle;
using plotting::Extent;
using plotting::PlotArea;
using plotting::Point;
using plotting::SvgPlot;

constexpr double kWidth = 640, kHeight = 520, kLeft = 70, kTop = 40, kSide = 520, kPlotHeight = 420;
constexpr std::size_t kMaxBoxes = 50000;  // drawn (evenly thinned beyond)

std::size_t Column(const FlowpipeReachability::ReachSet& set, const std::string& name) {
  for (std::size_t i = 0; i < set.variables.size(); ++i) {
    if (set.variables[i] == name) return i;
  }
  std::string list;
  for (const std::string& v : set.variables) list += (list.empty() ? "" : ", ") + v;
  throw std::invalid_argument("no variable '" + name + "'; the variables are: " + list);
}

// A bound `v REL c` (or `c REL v`) of the predicate on variable `name`, with its constant.
void BoundsOn(const Predicate& p, const std::string& name, std::vector<double>& out) {
  if (p.kind() == Predicate::Kind::kComparison) {
    const Comparison& c = p.comparison();
    const auto affine = c.Residual().AsAffine();
    if (affine && affine->terms.size() == 1 && c.lhs.is_symbol() != c.rhs.is_symbol()) {
      const Expression& symbol = c.lhs.is_symbol() ? c.lhs : c.rhs;
      if (symbol.symbol_name() == name) out.push_back(-affine->constant / affine->terms[0].second);
    }
    return;
  }
  for (const Predicate& q : p.operands()) BoundsOn(q, name, out);
}

}  // namespace

std::string ReachPlotSvg(const FlowpipeReachability::ReachSet& set, const std::string& x,
                         const std::string& y, const std::vector<Property>& properties,
                         const std::vector<ReachPlotTrace>& traces, const std::string& title) {
  const std::size_t cx = Column(set, x), cy = Column(set, y);
  Extent ex, ey;
  for (const auto& b : set.boxes) {
    ex.Add(b.box[cx].first);
    ex.Add(b.box[cx].second);
    ey.Add(b.box[cy].first);
    ey.Add(b.box[cy].second);
  }
  for (const ReachPlotTrace& t : traces) {
    for (double v : t.xs) ex.Add(v);
    for (double v : t.ys) ey.Add(v);
  }
  const PlotArea area{kLeft, kTop, kSide, kPlotHeight, ex.Padded(), ey.Padded()};
  SvgPlot svg(plotting::NumberStyle::kSignificant4);
  svg.Start("svg")
      .Attribute("xmlns", "http://www.w3.org/2000/svg")
      .Attribute("width", kWidth)
      .Attribute("height", kHeight)
      .Attribute("font-family", "sans-serif")
      .Attribute("font-size", "11")
      .EndStart();
  svg.Rect(0, 0, kWidth, kHeight, "fill=\"white\"");
  svg.Text(kLeft, 20, title, "font-size=\"13\" font-weight=\"bold\"");
  const std::size_t stride =
      std::max<std::size_t>(1, (set.boxes.size() + kMaxBoxes - 1) / kMaxBoxes);
  svg.Start("g")
      .Attribute("fill", "#9ecae1")
      .Attribute("fill-opacity", "0.5")
      .Attribute("stroke", "#3182bd")
      .Attribute("stroke-width", "0.3")
      .EndStart();
  for (std::size_t i = 0; i < set.boxes.size(); i += stride) {
    const auto& b = set.boxes[i];
    const double x0 = area.X(std::max(b.box[cx].first, area.x.lo));
    const double x1 = area.X(std::min(b.box[cx].second, area.x.hi));
    const double y0 = area.Y(std::min(b.box[cy].second, area.y.hi));
    const double y1 = area.Y(std::max(b.box[cy].first, area.y.lo));
    if (!(x1 >= x0) || !(y1 >= y0)) continue;
    svg.Rect(x0, y0, std::max(x1 - x0, 0.2), std::max(y1 - y0, 0.2));
  }
  svg.End("g");
  for (const Property& p : properties) {
    std::vector<double> vx, vy;
    BoundsOn(p.predicate, x, vx);
    BoundsOn(p.predicate, y, vy);
    for (double v : vx) {
      if (v < area.x.lo || v > area.x.hi) continue;
      const Point line[2] = {{area.X(v), area.top}, {area.X(v), area.bottom()}};
      svg.Polyline(line, "fill=\"none\" stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
      svg.Text(area.X(v) + 3, area.top + 12, p.name, "fill=\"#d62728\" font-size=\"10\"");
    }
    for (double v : vy) {
      if (v < area.y.lo || v > area.y.hi) continue;
      const Point line[2] = {{area.left, area.Y(v)}, {area.left + area.width, area.Y(v)}};
      svg.Polyline(line, "fill=\"none\" stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
      svg.Text(area.left + 4, area.Y(v) - 3, p.name, "fill=\"#d62728\" font-size=\"10\"");
    }
  }
  for (const ReachPlotTrace& t : traces) {
    svg.Series(area, t.xs, t.ys, "fill=\"none\" stroke=\"#d62728\" stroke-width=\"1.5\"");
    if (!t.xs.empty())
      svg.Text(area.X(t.xs.back()) + 4, area.Y(t.ys.back()), t.label, "fill=\"#d62728\"");
  }
  AxesStyle style;
  svg.Axes(area, x, y, style);
  svg.Text(kLeft, kHeight - 12,
           std::to_string(set.boxes.size()) + " flowpipe boxes" +
               (stride > 1 ? " (every " + std::to_string(stride) + "th drawn)" : "") +
               "; dashed: property bounds; red lines: counterexamples and witnesses",
           "font-size=\"10\"");
  return svg.Finish();
}

}  // namespace hybrid::cli
