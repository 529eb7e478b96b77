#include "hybrid/gripper/svg_figures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string_view>

#include "hybrid/plotting/svg_plot.h"

namespace hybrid::gripper {
namespace {

using plotting::AttributePlacement;
using plotting::LegendEntry;
using plotting::LegendKey;
using plotting::LegendLayout;
using plotting::NumberStyle;
using plotting::SvgPlot;

// Colours of links 1..3 (and of theta1..3 in the angle plot).
constexpr std::array<const char*, 3> kLinkColours = {"#1f77b4", "#d95f02", "#2ca02c"};

// A value for a label: rounded to two decimals, printed shortest ("110", "62.5").
std::string Label(double value) { return plotting::FormatRounded(value, 2); }

// Text content escaped for XML (quotes need no escaping there).
std::string Escape(std::string_view text) { return plotting::XmlEscape(text); }

// A figure: pixel coordinates with two decimals, presentation attributes before the geometry;
// the root element, the document's <title> and a white page.
SvgPlot OpenSvg(double width, double height, const std::string& title) {
  SvgPlot svg(NumberStyle::kFixed2, AttributePlacement::kBeforeGeometry);
  svg.Start("svg")
      .Attribute("xmlns", "http://www.w3.org/2000/svg")
      .Attribute("width", width)
      .Attribute("height", height)
      .Attribute("viewBox", "0 0 " + svg.Number(width) + ' ' + svg.Number(height))
      .Attribute("font-family", "sans-serif")
      .Attribute("font-size", "12")
      .EndStart();
  svg.Start("title").Content("title", Escape(title));
  svg.Start("rect")
      .Attribute("width", width)
      .Attribute("height", height)
      .Attribute("fill", "white")
      .EndEmpty();
  return svg;
}

// The length of a scale bar in m, cm or mm.
std::string LengthLabel(double metres) {
  if (metres >= 1.0) return Label(metres) + " m";
  if (metres >= 0.01) return Label(metres * 100.0) + " cm";
  return Label(metres * 1000.0) + " mm";
}

// Small multiples (FingerDrawingSvg, HandDrawingSvg), in pixels: the larger side of a panel's
// drawing, the caption under it, the gaps between panels, the page margin, title and footer.
constexpr double kPanelPixels = 220.0;
constexpr double kCaption = 24.0, kGap = 16.0, kMargin = 20.0, kTitle = 30.0, kFooter = 40.0;
constexpr double kMinWidth = 400.0;
constexpr double kLinkWidth = 6.0, kJointRadius = 3.5;
// Space (metres) around everything a panel shows.
constexpr double kWorldMargin = 0.01;
// The footer's legend starts this far right of the page margin (after the scale bar).
constexpr double kKeyIndent = 150.0;

// An axis-aligned window in metres, grown to include points and objects.
struct Window {
  Window(double x, double y) : x_min(x), x_max(x), y_min(y), y_max(y) {}
  void Include(double x, double y, double radius = 0.0) {
    x_min = std::min(x_min, x - radius);
    x_max = std::max(x_max, x + radius);
    y_min = std::min(y_min, y - radius);
    y_max = std::max(y_max, y + radius);
  }
  // The object's section in the x-y plane (its capsule).
  void Include(const Obstacle& object) {
    Include(object.a().x(), object.a().y(), object.radius());
    Include(object.b().x(), object.b().y(), object.radius());
  }
  void Grow(double margin) {
    x_min -= margin;
    x_max += margin;
    y_min -= margin;
    y_max += margin;
  }
  double x_min, x_max, y_min, y_max;
};

// A window drawn at `scale` pixels per metre: x to the right, y up (pixel rows grow down).
struct View {
  double X(double x) const { return (x - window.x_min) * scale; }
  double Y(double y) const { return (window.y_max - y) * scale; }
  double width() const { return (window.x_max - window.x_min) * scale; }
  double height() const { return (window.y_max - window.y_min) * scale; }
  Window window;
  double scale;
};

// n panels of the same size in rows of at most four, under the title and above the footer.
struct PanelGrid {
  PanelGrid(int n, double panel_width_, double panel_height_, double min_width = kMinWidth)
      : columns(std::min(4, n)),
        rows((n + columns - 1) / columns),
        panel_width(panel_width_),
        panel_height(panel_height_),
        width(std::max(min_width, 2 * kMargin + columns * panel_width + (columns - 1) * kGap)),
        height(kMargin + kTitle + rows * panel_height + (rows - 1) * kGap + kFooter + kMargin) {}
  double Left(int i) const { return kMargin + (i % columns) * (panel_width + kGap); }
  double Top(int i) const { return kMargin + kTitle + (i / columns) * (panel_height + kGap); }
  // The baseline of the footer's scale bar and legend.
  double FooterY() const { return height - kMargin - kFooter + 24; }
  int columns, rows;
  double panel_width, panel_height, width, height;
};

// "<prefix> at g = 0, 30, 70" for the document's <title>.
std::string AtG(const std::string& prefix, const std::vector<double>& gs) {
  std::string title = prefix + " at g =";
  for (size_t i = 0; i < gs.size(); ++i) title += (i == 0 ? " " : ", ") + Label(gs[i]);
  return title;
}

// Throws std::invalid_argument ("DRAWING: frame at g = ...") unless the frame is finite.
void RequireFinite(const std::string& drawing, double g, bool theta_finite) {
  if (!std::isfinite(g) || !theta_finite) {
    throw std::invalid_argument(drawing + ": frame at g = " + plotting::FormatShortest(g) +
                                " has a value that is not finite");
  }
}

// The page's title in large type at the top left.
void PageTitle(SvgPlot& svg, const std::string& markup) {
  svg.TextMarkup(kMargin, kMargin + 12, markup, "class=\"title\" font-size=\"15\"");
}

// Opens a group of the given class moved to (left, top); close it with svg.EndGroup().
void OpenGroup(SvgPlot& svg, const std::string& class_name, double left, double top) {
  svg.Group("class=\"" + class_name + "\" transform=\"translate(" + svg.Number(left) + ',' +
            svg.Number(top) + ")\"");
}

void FrameRect(SvgPlot& svg, double width, double height) {
  svg.Start("rect")
      .Attributes("class=\"frame\"")
      .Attribute("width", width)
      .Attribute("height", height)
      .Attributes("fill=\"none\" stroke=\"#cccccc\"")
      .EndEmpty();
}

void PalmRect(SvgPlot& svg, double x, double y, double width, double height) {
  svg.Start("rect")
      .Attributes("class=\"palm\"")
      .Attribute("x", x)
      .Attribute("y", y)
      .Attribute("width", width)
      .Attribute("height", height)
      .Attributes("fill=\"#bbbbbb\" stroke=\"#777777\"")
      .EndEmpty();
}

// Objects in the x-y plane: a circle as <circle>, a bar as a thick round-capped <line> (exactly
// its capsule).
void Objects(SvgPlot& svg, const View& view, const std::vector<Obstacle>& objects) {
  for (const Obstacle& object : objects) {
    if (object.is_circle()) {
      svg.Start("circle")
          .Attributes("class=\"object\"")
          .Attribute("cx", view.X(object.a().x()))
          .Attribute("cy", view.Y(object.a().y()))
          .Attribute("r", object.radius() * view.scale)
          .Attributes("fill=\"#e6a0a0\" stroke=\"#a03030\"")
          .EndEmpty();
    } else {
      svg.Line(view.X(object.a().x()), view.Y(object.a().y()), view.X(object.b().x()),
               view.Y(object.b().y()),
               "class=\"object\" stroke=\"#e6a0a0\" stroke-linecap=\"round\" stroke-width=\"" +
                   svg.Number(2 * object.radius() * view.scale) + "\"");
    }
  }
}

void Joint(SvgPlot& svg, double x, double y, double radius) {
  svg.Start("circle")
      .Attributes("class=\"joint\"")
      .Attribute("cx", x)
      .Attribute("cy", y)
      .Attribute("r", radius)
      .Attributes("fill=\"white\" stroke=\"black\"")
      .EndEmpty();
}

// A bar of a round length (metres) about 80 pixels long at the left of the footer.
void ScaleBar(SvgPlot& svg, double y, double scale) {
  const double bar = plotting::NiceLengthAtMost(80.0 / scale);
  svg.Line(kMargin, y, kMargin + bar * scale, y,
           "class=\"scale\" stroke=\"black\" stroke-width=\"2\"");
  svg.TextMarkup(kMargin + bar * scale + 6, y + 4, LengthLabel(bar), "class=\"scale\"");
}

// The footer of the small multiples: the scale bar and a legend of line keys side by side,
// `spacing` pixels apart.
void Footer(SvgPlot& svg, const PanelGrid& grid, double scale, const std::vector<LegendEntry>& keys,
            double spacing) {
  const double footer_y = grid.FooterY();
  svg.Group("class=\"footer\"");
  ScaleBar(svg, footer_y, scale);
  LegendLayout layout;
  layout.key_length = 20.0;
  layout.label_offset = 28.0;
  layout.label_drop = 4.0;
  layout.spacing = spacing;
  layout.per_character = 0.0;
  layout.label_attributes = "class=\"key\"";
  svg.Legend(kMargin + kKeyIndent, footer_y, keys, layout);
  svg.EndGroup();
}

// The finger drawing (FingerDrawingSvg).

// Every panel's window, at the same scale: every frame's joints (`points`), every object and the
// palm's top, plus kWorldMargin, its longer side kPanelPixels.
View FingerView(double palm_y, const std::vector<std::array<Eigen::Vector2d, 4>>& points,
                const std::vector<Obstacle>& objects) {
  Window window(0.0, palm_y);
  for (const auto& frame_points : points) {
    for (const Eigen::Vector2d& p : frame_points) window.Include(p.x(), p.y());
  }
  for (const Obstacle& object : objects) window.Include(object);
  window.Grow(kWorldMargin);
  return {window,
          kPanelPixels / std::max(window.x_max - window.x_min, window.y_max - window.y_min)};
}

// Panel i, showing `frame` (g, configuration) with joint points `p`: frame, palm, objects, the
// three links and their joints, the caption.
void DrawFingerPanel(SvgPlot& svg, const PanelGrid& grid, const View& view, double palm_y,
                     const std::vector<Obstacle>& objects, int i,
                     const std::array<Eigen::Vector2d, 4>& p,
                     const std::pair<double, FingerConfiguration>& frame) {
  const auto& [g, configuration] = frame;
  const double drawing_height = view.height();
  OpenGroup(svg, "panel", grid.Left(i), grid.Top(i));
  FrameRect(svg, grid.panel_width, drawing_height);
  PalmRect(svg, 0.0, view.Y(palm_y), grid.panel_width, drawing_height - view.Y(palm_y));
  Objects(svg, view, objects);
  for (int k = 0; k < 3; ++k) {
    svg.Line(view.X(p[k].x()), view.Y(p[k].y()), view.X(p[k + 1].x()), view.Y(p[k + 1].y()),
             "class=\"link l" + std::to_string(k + 1) + "\" stroke=\"" + kLinkColours[k] +
                 "\" stroke-width=\"" + svg.Number(kLinkWidth) + "\" stroke-linecap=\"round\"");
  }
  for (int k = 0; k < 3; ++k) Joint(svg, view.X(p[k].x()), view.Y(p[k].y()), kJointRadius);
  svg.TextMarkup(grid.panel_width / 2, drawing_height + 17,
                 "g = " + Label(g) + ", phase " + Escape(PhaseName(configuration.phase)),
                 "class=\"caption\" text-anchor=\"middle\"");
  svg.EndGroup();
}

// The footer's keys of links 1 to 3 in their colours.
std::vector<LegendEntry> LinkKeys() {
  std::vector<LegendEntry> keys;
  for (int k = 0; k < 3; ++k) {
    keys.push_back({LegendKey::kLine,
                    "class=\"key\" stroke=\"" + std::string(kLinkColours[k]) +
                        "\" stroke-width=\"" + plotting::FormatFixed(kLinkWidth, 2) +
                        "\" stroke-linecap=\"round\"",
                    "link " + std::to_string(k + 1)});
  }
  return keys;
}

// The hand drawing (HandDrawingSvg).

constexpr std::array<const char*, 3> kFingerNames = {"A", "B", "C"};
constexpr std::array<const char*, 3> kFingerColours = {"#1b9e77", "#7570b3", "#e7298a"};
constexpr std::array<double, 3> kFingerJointRadii = {kJointRadius, kJointRadius, 2.0};
// The palm spans the finger bases (joint 1 does not move) with this margin, in x and z.
constexpr double kPalmMargin = 0.02;
constexpr double kStripGap = 14.0;  // between the side view and the view from above
constexpr double kPhases = 14.0;    // the phases line under the caption
constexpr double kKeySpacing = 90.0, kHandMinWidth = 460.0;  // room for the legend

// Joints 1 to 3 and the fingertip of fingers A, B and C in space (Hand::Points).
using HandPoints = std::array<std::array<Eigen::Vector3d, 4>, 3>;

// Presentation attributes of each finger's links: its colour; finger C thinner and dashed, so
// finger B shows where the two coincide.
std::array<std::string, 3> FingerStyles() {
  std::array<std::string, 3> styles;
  for (int f = 0; f < 3; ++f) {
    styles[f] = std::string("stroke=\"") + kFingerColours[f] + "\" stroke-width=\"" +
                plotting::FormatFixed(f == 2 ? kLinkWidth / 2 : kLinkWidth, 2) +
                "\" stroke-linecap=\"round\"" + (f == 2 ? " stroke-dasharray=\"4 6\"" : "");
  }
  return styles;
}

// The palm's top (y) and its extent in x and z: the finger bases plus kPalmMargin.
struct Palm {
  double y, x0, x1, z0, z1;
};

Palm PalmOf(const Hand& hand) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double base_x_min = kInfinity, base_x_max = -kInfinity;
  double base_z_min = kInfinity, base_z_max = -kInfinity;
  for (int f = 0; f < 3; ++f) {
    const Eigen::Vector3d base = hand.Points(f, Eigen::Vector3d::Zero())[0];
    base_x_min = std::min(base_x_min, base.x());
    base_x_max = std::max(base_x_max, base.x());
    base_z_min = std::min(base_z_min, base.z());
    base_z_max = std::max(base_z_max, base.z());
  }
  return {hand.finger(0).geometry().palm_y(), base_x_min - kPalmMargin, base_x_max + kPalmMargin,
          base_z_min - kPalmMargin, base_z_max + kPalmMargin};
}

// What every panel of the hand drawing shares: the palm, the side view (x, y) and the view from
// above (x, z; its window's "y" is z), at the same scale and with the same x window, and where
// the view from above and the captions start in a panel.
struct HandFigure {
  // From above (from +y) with x to the right, z points down the page.
  double Z(double z) const { return (z - above.window.y_min) * above.scale; }
  Palm palm;
  View side, above;
  double above_top, caption_top;
};

// The common windows: the palm, all frames' joints and fingertips and (side view) all objects,
// plus kWorldMargin; the side view's longer side is kPanelPixels.
HandFigure LayOutHand(const Hand& hand, const std::vector<HandPoints>& points) {
  const Palm palm = PalmOf(hand);
  Window side(palm.x0, palm.y), above(palm.x0, palm.z0);
  side.Include(palm.x1, palm.y);
  above.Include(palm.x1, palm.z1);
  for (const HandPoints& frame_points : points) {
    for (const auto& finger_points : frame_points) {
      for (const Eigen::Vector3d& p : finger_points) {
        side.Include(p.x(), p.y());
        above.Include(p.x(), p.z());
      }
    }
  }
  for (const Obstacle& object : hand.objects()) side.Include(object);
  side.Grow(kWorldMargin);
  above.Grow(kWorldMargin);
  above.x_min = side.x_min;  // the views share their x axis
  above.x_max = side.x_max;
  const double scale = kPanelPixels / std::max(side.x_max - side.x_min, side.y_max - side.y_min);
  const View side_view{side, scale}, above_view{above, scale};
  const double above_top = side_view.height() + kStripGap;
  return {palm, side_view, above_view, above_top, above_top + above_view.height()};
}

// One group per finger holding its three links, from point k to k + 1 of `p` mapped by `to_pixels`,
// each <line class="<prefix><k>">.
template <class ToPixels>
void FingerLinks(SvgPlot& svg, const HandPoints& p, const std::array<std::string, 3>& styles,
                 const std::string& prefix, ToPixels to_pixels) {
  for (int f = 0; f < 3; ++f) {
    svg.Group("class=\"finger " + std::string(kFingerNames[f]) + "\" " + styles[f]);
    for (int k = 0; k < 3; ++k) {
      const auto [x1, y1] = to_pixels(p[f][k]);
      const auto [x2, y2] = to_pixels(p[f][k + 1]);
      svg.Line(x1, y1, x2, y2, "class=\"" + prefix + std::to_string(k + 1) + "\"");
    }
    svg.EndGroup();
  }
}

// A panel's side view: frame, palm, objects, every finger's links and joints.
void DrawSideView(SvgPlot& svg, const Hand& hand, const HandFigure& figure, double panel_width,
                  const HandPoints& p, const std::array<std::string, 3>& styles) {
  const View& side = figure.side;
  const Palm& palm = figure.palm;
  FrameRect(svg, panel_width, side.height());
  PalmRect(svg, side.X(palm.x0), side.Y(palm.y), (palm.x1 - palm.x0) * side.scale,
           side.height() - side.Y(palm.y));
  Objects(svg, side, hand.objects());
  FingerLinks(svg, p, styles, "link l",
              [&](const Eigen::Vector3d& q) { return std::pair(side.X(q.x()), side.Y(q.y())); });
  for (int f = 0; f < 3; ++f) {
    for (int k = 0; k < 3; ++k) {
      Joint(svg, side.X(p[f][k].x()), side.Y(p[f][k].y()), kFingerJointRadii[f]);
    }
  }
}

// A panel's view from above: frame, palm, the objects as bands across the strip (they are
// extruded along z) and every finger's links.
void DrawViewFromAbove(SvgPlot& svg, const Hand& hand, const HandFigure& figure, double panel_width,
                       const HandPoints& p, const std::array<std::string, 3>& styles) {
  const View& side = figure.side;
  const Palm& palm = figure.palm;
  const double scale = side.scale, height = figure.above.height();
  OpenGroup(svg, "top-view", 0.0, figure.above_top);
  FrameRect(svg, panel_width, height);
  PalmRect(svg, side.X(palm.x0), figure.Z(palm.z0), (palm.x1 - palm.x0) * scale,
           (palm.z1 - palm.z0) * scale);
  for (const Obstacle& object : hand.objects()) {
    const double x0 = std::min(object.a().x(), object.b().x()) - object.radius();
    const double x1 = std::max(object.a().x(), object.b().x()) + object.radius();
    svg.Start("rect")
        .Attributes("class=\"object\"")
        .Attribute("x", side.X(x0))
        .Attribute("y", 0.0)
        .Attribute("width", (x1 - x0) * scale)
        .Attribute("height", height)
        .Attributes("fill=\"#e6a0a0\" fill-opacity=\"0.6\" stroke=\"#a03030\"")
        .EndEmpty();
  }
  FingerLinks(svg, p, styles, "top l",
              [&](const Eigen::Vector3d& q) { return std::pair(side.X(q.x()), figure.Z(q.z())); });
  svg.TextMarkup(2, -3, "from above", "class=\"view\" font-size=\"9\" fill=\"#555555\"");
  svg.EndGroup();
}

// A panel's caption "g = <g>" and, smaller, the fingers' phases.
void DrawHandCaption(SvgPlot& svg, const HandFrame& frame, double panel_width, double caption_top) {
  svg.TextMarkup(panel_width / 2, caption_top + 17, "g = " + Label(frame.g),
                 "class=\"caption\" text-anchor=\"middle\"");
  std::string phases;
  for (int f = 0; f < 3; ++f) {
    phases += std::string(f == 0 ? "" : ", ") + kFingerNames[f] + " " +
              Escape(PhaseName(frame.fingers[f].phase));
  }
  svg.TextMarkup(panel_width / 2, caption_top + 17 + kPhases, "phases " + phases,
                 "class=\"phases\" text-anchor=\"middle\" font-size=\"10\" fill=\"#555555\"");
}

// The footer's keys of fingers A, B and C in their styles.
std::vector<LegendEntry> FingerKeys(const std::array<std::string, 3>& styles) {
  std::vector<LegendEntry> keys;
  for (int f = 0; f < 3; ++f) {
    keys.push_back(
        {LegendKey::kLine, "class=\"key\" " + styles[f], std::string("finger ") + kFingerNames[f]});
  }
  return keys;
}

// The angle plot (AnglePlotSvg), in pixels: page, plot area, gridline steps.
constexpr double kPlotPageWidth = 640.0, kPlotPageHeight = 420.0;
constexpr double kPlotLeft = 64.0, kPlotRight = 130.0, kPlotTop = 48.0, kPlotBottom = 56.0;
constexpr double kPlotWidth = kPlotPageWidth - kPlotLeft - kPlotRight;
constexpr double kPlotHeight = kPlotPageHeight - kPlotTop - kPlotBottom;
constexpr double kGStep = 50.0, kThetaStep = 20.0;
// No limit on the number of gridlines (the motor range and angle range bound them).
constexpr int kAllTicks = std::numeric_limits<int>::max();

// The angles sampled for the curves, the angle range shown and the pixel mapping.
struct AngleCurves {
  double X(double g) const { return kPlotLeft + g / g_max * kPlotWidth; }
  double Y(double theta) const { return kPlotTop + (hi - theta) / (hi - lo) * kPlotHeight; }
  double g_max;
  std::vector<double> samples;
  std::vector<Eigen::Vector3d> thetas;
  // [-60, 100] degrees, widened by multiples of kThetaStep to hold every angle.
  double lo = -60.0, hi = 100.0;
};

// Samples: multiples of 0.5 counts, the end of the range and every breakpoint, sorted, without
// samples within 1e-9 counts of an earlier one; the angles there and their range.
AngleCurves SampleAngles(const FingerClosedForm& closed_form) {
  AngleCurves curves;
  const double g_max = curves.g_max = closed_form.parameters().motor_max;
  std::vector<double> gs;
  for (int k = 0; k * 0.5 <= g_max; ++k) gs.push_back(k * 0.5);
  gs.push_back(g_max);
  for (const FingerClosedForm::Piece& piece : closed_form.pieces()) {
    for (double g : {piece.g0, piece.g1}) gs.push_back(std::clamp(g, 0.0, g_max));
  }
  std::sort(gs.begin(), gs.end());
  for (double g : gs) {
    if (curves.samples.empty() || g - curves.samples.back() > 1e-9) curves.samples.push_back(g);
  }
  for (double g : curves.samples) {
    curves.thetas.push_back(closed_form.At(g).theta);
    curves.lo =
        std::min(curves.lo, kThetaStep * std::floor(curves.thetas.back().minCoeff() / kThetaStep));
    curves.hi =
        std::max(curves.hi, kThetaStep * std::ceil(curves.thetas.back().maxCoeff() / kThetaStep));
  }
  return curves;
}

// Calls visit(g, theta) for joint k's present samples of `measured` within [0, g_max].
template <typename Visit>
void ForEachMeasured(const std::vector<MeasuredSeries>& measured, int k, double g_max,
                     Visit visit) {
  for (const MeasuredSeries& run : measured) {
    for (size_t i = 0; i < run.g.size() && i < run.theta[k].size(); ++i) {
      const double g = run.g[i], theta = run.theta[k][i];
      if (std::isfinite(theta) && g >= 0.0 && g <= g_max) visit(g, theta);
    }
  }
}

// Widens `c`'s angle range (multiples of kThetaStep) to hold the measured samples in range.
void WidenForMeasured(AngleCurves& c, const std::vector<MeasuredSeries>& measured) {
  for (int k = 0; k < 3; ++k) {
    ForEachMeasured(measured, k, c.g_max, [&](double, double theta) {
      c.lo = std::min(c.lo, kThetaStep * std::floor(theta / kThetaStep));
      c.hi = std::max(c.hi, kThetaStep * std::ceil(theta / kThetaStep));
    });
  }
}

// The measured samples as dots in the joints' colours.
void DrawMeasured(SvgPlot& svg, const AngleCurves& c, const std::vector<MeasuredSeries>& measured) {
  svg.Group("class=\"measured\" fill-opacity=\"0.5\"");
  for (int k = 0; k < 3; ++k) {
    svg.Group("class=\"measured theta" + std::to_string(k + 1) + "\" fill=\"" + kLinkColours[k] +
              "\"");
    ForEachMeasured(measured, k, c.g_max,
                    [&](double g, double theta) { svg.Marker(c.X(g), c.Y(theta), 1.6); });
    svg.EndGroup();
  }
  svg.EndGroup();
}

// Dotted vertical lines at the contact positions given to the closed form (the report's g_ob).
void DrawContactLines(SvgPlot& svg, const AngleCurves& c, const FingerContacts& contacts) {
  svg.Group("class=\"gob\"");
  for (int i = 0; i < 3; ++i) {
    const double gob = contacts.gob[i];
    if (!(gob >= 0.0 && gob <= c.g_max)) continue;
    const double x = c.X(gob);
    svg.Line(x, kPlotTop, x, kPlotTop + kPlotHeight,
             "class=\"gob\" stroke=\"#777777\" stroke-dasharray=\"2 3\"");
    svg.TextMarkup(x + 4, kPlotTop + kPlotHeight - 8 - 14 * i,
                   "g_ob link " + std::to_string(i + 1) + " = " + Label(gob),
                   "class=\"gob\" text-anchor=\"start\"");
  }
  svg.EndGroup();
}

// Gridlines with their value (data-g, data-theta), ticks and numbers, the frame and the axis
// titles.
void DrawAngleAxes(SvgPlot& svg, const AngleCurves& c) {
  constexpr double kBottom = kPlotTop + kPlotHeight;
  svg.Group("class=\"axes\"");
  for (double g : plotting::Ticks({0.0, c.g_max}, kGStep, kAllTicks)) {
    svg.Line(c.X(g), kPlotTop, c.X(g), kBottom,
             "class=\"grid\" data-g=\"" + Label(g) + "\" stroke=\"#dddddd\"");
    svg.Line(c.X(g), kBottom, c.X(g), kBottom + 5, "class=\"tick\" stroke=\"black\"");
    svg.TextMarkup(c.X(g), kBottom + 18, Label(g), "class=\"tick\" text-anchor=\"middle\"");
  }
  for (double theta : plotting::Ticks({c.lo, c.hi}, kThetaStep, kAllTicks)) {
    svg.Line(kPlotLeft, c.Y(theta), kPlotLeft + kPlotWidth, c.Y(theta),
             "class=\"grid\" data-theta=\"" + Label(theta) + "\" stroke=\"" +
                 (theta == 0.0 ? "#999999" : "#dddddd") + "\"");
    svg.Line(kPlotLeft - 5, c.Y(theta), kPlotLeft, c.Y(theta), "class=\"tick\" stroke=\"black\"");
    svg.TextMarkup(kPlotLeft - 8, c.Y(theta) + 4, Label(theta),
                   "class=\"tick\" text-anchor=\"end\"");
  }
  svg.Start("rect")
      .Attributes("class=\"frame\"")
      .Attribute("x", kPlotLeft)
      .Attribute("y", kPlotTop)
      .Attribute("width", kPlotWidth)
      .Attribute("height", kPlotHeight)
      .Attributes("fill=\"none\" stroke=\"black\"")
      .EndEmpty();
  svg.TextMarkup(kPlotLeft + kPlotWidth / 2, kPlotPageHeight - 16,
                 plotting::WithUnit("motor position g", "counts"),
                 "class=\"axis-label\" text-anchor=\"middle\"");
  svg.Start("text")
      .Attributes("class=\"axis-label\" text-anchor=\"middle\" transform=\"translate(" +
                  svg.Number(18) + ',' + svg.Number(kPlotTop + kPlotHeight / 2) + ") rotate(-90)\"")
      .Content("text", plotting::WithUnit("joint angle", "degrees"));
  svg.EndGroup();
}

// A dashed vertical line at the motor's stop, labelled on the side with more room.
void DrawStopLine(SvgPlot& svg, const AngleCurves& c, double stop) {
  const double x = c.X(stop);
  const bool right_half = stop > c.g_max / 2;
  svg.Group("class=\"stop\"");
  svg.Line(x, kPlotTop, x, kPlotTop + kPlotHeight,
           "class=\"stop\" stroke=\"#444444\" stroke-dasharray=\"6 4\"");
  svg.TextMarkup(
      right_half ? x - 4 : x + 4, kPlotTop + 14, "motor stops (g = " + Label(stop) + ")",
      std::string("class=\"stop\" text-anchor=\"") + (right_half ? "end" : "start") + "\"");
  svg.EndGroup();
}

// theta1..3 as polylines in the links' colours.
void DrawAngleCurves(SvgPlot& svg, const AngleCurves& c) {
  svg.Group("class=\"curves\"");
  for (int k = 0; k < 3; ++k) {
    std::vector<plotting::Point> points;
    for (size_t i = 0; i < c.samples.size(); ++i) {
      points.push_back({c.X(c.samples[i]), c.Y(c.thetas[i][k])});
    }
    svg.Polyline(points, "class=\"theta" + std::to_string(k + 1) + "\" fill=\"none\" stroke=\"" +
                             kLinkColours[k] + "\" stroke-width=\"2\" stroke-linejoin=\"round\"");
  }
  svg.EndGroup();
}

// theta1..3's keys one under the other, right of the plot.
void DrawAngleLegend(SvgPlot& svg) {
  std::vector<LegendEntry> keys;
  for (int k = 0; k < 3; ++k) {
    keys.push_back(
        {LegendKey::kLine,
         "class=\"key\" stroke=\"" + std::string(kLinkColours[k]) + "\" stroke-width=\"2\"",
         plotting::WithUnit("&#952;" + std::to_string(k + 1), "deg")});
  }
  LegendLayout layout;
  layout.vertical = true;
  layout.key_length = 24.0;
  layout.label_offset = 30.0;
  layout.label_drop = 4.0;
  layout.spacing = 22.0;
  layout.label_attributes = "class=\"key\"";
  svg.Group("class=\"legend\"");
  svg.Legend(kPlotLeft + kPlotWidth + 16, kPlotTop + 12, keys, layout);
  svg.EndGroup();
}

}  // namespace

std::string FingerDrawingSvg(const FingerGeometry& geometry, const std::vector<Obstacle>& objects,
                             const std::vector<std::pair<double, FingerConfiguration>>& frames) {
  if (frames.empty()) throw std::invalid_argument("finger drawing: no frames to draw");
  std::vector<std::array<Eigen::Vector2d, 4>> points;
  std::vector<double> gs;
  for (const auto& [g, configuration] : frames) {
    RequireFinite("finger drawing", g, configuration.theta.allFinite());
    gs.push_back(g);
    points.push_back(geometry.Points(configuration.theta));
  }
  const View view = FingerView(geometry.palm_y(), points, objects);
  const int n = static_cast<int>(frames.size());
  const PanelGrid grid(n, view.width(), view.height() + kCaption);

  SvgPlot svg = OpenSvg(grid.width, grid.height, AtG("Finger configurations", gs));
  PageTitle(svg, "Finger configurations");
  for (int i = 0; i < n; ++i) {
    DrawFingerPanel(svg, grid, view, geometry.palm_y(), objects, i, points[i], frames[i]);
  }
  Footer(svg, grid, view.scale, LinkKeys(), 80.0);
  return svg.Finish();
}

std::string HandDrawingSvg(const Hand& hand, const std::vector<HandFrame>& frames) {
  if (frames.empty()) throw std::invalid_argument("hand drawing: no frames to draw");
  std::vector<HandPoints> points;
  std::vector<double> gs;
  for (const HandFrame& frame : frames) {
    bool finite = true;
    for (const FingerConfiguration& finger : frame.fingers) finite &= finger.theta.allFinite();
    RequireFinite("hand drawing", frame.g, finite);
  }
  for (const HandFrame& frame : frames) {
    gs.push_back(frame.g);
    auto& frame_points = points.emplace_back();
    for (int f = 0; f < 3; ++f) frame_points[f] = hand.Points(f, frame.fingers[f].theta);
  }
  const HandFigure figure = LayOutHand(hand, points);
  const int n = static_cast<int>(frames.size());
  const PanelGrid grid(n, figure.side.width(), figure.caption_top + kCaption + kPhases,
                       kHandMinWidth);
  const std::array<std::string, 3> styles = FingerStyles();

  const std::string spread = "spread angle " + Label(hand.spread_angle()) + " deg";
  SvgPlot svg =
      OpenSvg(grid.width, grid.height, AtG("Hand configurations", gs) + " (" + spread + ")");
  PageTitle(svg, "Hand configurations (" + spread + ")");
  for (int i = 0; i < n; ++i) {
    OpenGroup(svg, "panel", grid.Left(i), grid.Top(i));
    DrawSideView(svg, hand, figure, grid.panel_width, points[i], styles);
    DrawViewFromAbove(svg, hand, figure, grid.panel_width, points[i], styles);
    DrawHandCaption(svg, frames[i], grid.panel_width, figure.caption_top);
    svg.EndGroup();
  }
  Footer(svg, grid, figure.side.scale, FingerKeys(styles), kKeySpacing);
  return svg.Finish();
}

std::string AnglePlotSvg(const FingerClosedForm& closed_form, const std::string& title,
                         const std::vector<MeasuredSeries>& measured) {
  AngleCurves curves = SampleAngles(closed_form);
  WidenForMeasured(curves, measured);
  SvgPlot svg = OpenSvg(kPlotPageWidth, kPlotPageHeight, title);
  svg.TextMarkup(kPlotLeft + kPlotWidth / 2, kPlotTop - 18, Escape(title),
                 "class=\"title\" font-size=\"15\" text-anchor=\"middle\"");
  DrawAngleAxes(svg, curves);
  if (std::isfinite(closed_form.stop())) DrawStopLine(svg, curves, closed_form.stop());
  DrawContactLines(svg, curves, closed_form.contacts());
  if (!measured.empty()) DrawMeasured(svg, curves, measured);
  DrawAngleCurves(svg, curves);
  DrawAngleLegend(svg);
  if (!measured.empty()) {
    const double x = kPlotLeft + kPlotWidth + 16, y = kPlotTop + 12 + 3 * 22 + 8;
    svg.TextMarkup(x, y, "dots: measured", "class=\"key\"");
    svg.TextMarkup(
        x, y + 16,
        "(" + std::to_string(measured.size()) + " run" + (measured.size() == 1 ? "" : "s") + ")",
        "class=\"key\"");
  }
  return svg.Finish();
}

}  // namespace hybrid::gripper
