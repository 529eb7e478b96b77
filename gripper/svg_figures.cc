#include "gripper/svg_figures.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "automaton/expression.h"

namespace hybrid::gripper {
namespace {

// Colours of links 1..3 (and of theta1..3 in the angle plot).
constexpr std::array<const char*, 3> kLinkColours = {"#1f77b4", "#d95f02", "#2ca02c"};

// A pixel coordinate with two decimals; "-0.00" is printed as "0.00".
std::string Px(double value) {
  char buffer[64];
  auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::fixed, 2);
  if (ec != std::errc()) throw std::logic_error("svg_figures: cannot format a coordinate");
  std::string out(buffer, end);
  if (out == "-0.00") out = "0.00";
  return out;
}

// A value for a label: rounded to two decimals, printed shortest ("110", "62.5").
std::string Label(double value) { return FormatNumber(std::round(value * 100.0) / 100.0 + 0.0); }

std::string Escape(std::string_view text) { return XmlEscape(text); }

void OpenSvg(std::ostringstream& out, double width, double height, const std::string& title) {
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << Px(width) << "\" height=\""
      << Px(height) << "\" viewBox=\"0 0 " << Px(width) << ' ' << Px(height)
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<title>" << Escape(title) << "</title>\n"
      << "<rect width=\"" << Px(width) << "\" height=\"" << Px(height) << "\" fill=\"white\"/>\n";
}

void Line(std::ostringstream& out, const std::string& attributes, double x1, double y1, double x2,
          double y2) {
  out << "<line " << attributes << " x1=\"" << Px(x1) << "\" y1=\"" << Px(y1) << "\" x2=\""
      << Px(x2) << "\" y2=\"" << Px(y2) << "\"/>\n";
}

void Text(std::ostringstream& out, const std::string& attributes, double x, double y,
          const std::string& escaped_text) {
  out << "<text " << attributes << " x=\"" << Px(x) << "\" y=\"" << Px(y) << "\">" << escaped_text
      << "</text>\n";
}

// The largest 1, 2 or 5 times a power of ten not above `limit` (> 0).
double NiceLength(double limit) {
  const double decade = std::pow(10.0, std::floor(std::log10(limit)));
  for (double factor : {5.0, 2.0, 1.0}) {
    if (factor * decade <= limit) return factor * decade;
  }
  return decade;
}

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

void RequireFinite(const std::string& function, double g, bool theta_finite) {
  if (!std::isfinite(g) || !theta_finite) {
    throw std::invalid_argument(function + ": frame at g = " + FormatNumber(g) +
                                " has a value that is not finite");
  }
}

void OpenGroup(std::ostringstream& out, const std::string& class_name, double left, double top) {
  out << "<g class=\"" << class_name << "\" transform=\"translate(" << Px(left) << ',' << Px(top)
      << ")\">\n";
}

void FrameRect(std::ostringstream& out, double width, double height) {
  out << "<rect class=\"frame\" width=\"" << Px(width) << "\" height=\"" << Px(height)
      << "\" fill=\"none\" stroke=\"#cccccc\"/>\n";
}

void PalmRect(std::ostringstream& out, double x, double y, double width, double height) {
  out << "<rect class=\"palm\" x=\"" << Px(x) << "\" y=\"" << Px(y) << "\" width=\"" << Px(width)
      << "\" height=\"" << Px(height) << "\" fill=\"#bbbbbb\" stroke=\"#777777\"/>\n";
}

// Objects in the x-y plane: a circle as <circle>, a bar as a thick round-capped <line> (exactly
// its capsule).
void Objects(std::ostringstream& out, const View& view, const std::vector<Obstacle>& objects) {
  for (const Obstacle& object : objects) {
    if (object.is_circle()) {
      out << "<circle class=\"object\" cx=\"" << Px(view.X(object.a().x())) << "\" cy=\""
          << Px(view.Y(object.a().y())) << "\" r=\"" << Px(object.radius() * view.scale)
          << "\" fill=\"#e6a0a0\" stroke=\"#a03030\"/>\n";
    } else {
      Line(out,
           "class=\"object\" stroke=\"#e6a0a0\" stroke-linecap=\"round\" stroke-width=\"" +
               Px(2 * object.radius() * view.scale) + "\"",
           view.X(object.a().x()), view.Y(object.a().y()), view.X(object.b().x()),
           view.Y(object.b().y()));
    }
  }
}

void Joint(std::ostringstream& out, double x, double y, double radius) {
  out << "<circle class=\"joint\" cx=\"" << Px(x) << "\" cy=\"" << Px(y) << "\" r=\"" << Px(radius)
      << "\" fill=\"white\" stroke=\"black\"/>\n";
}

// A bar of a round length (metres) about 80 pixels long at the left of the footer.
void ScaleBar(std::ostringstream& out, double y, double scale) {
  const double bar = NiceLength(80.0 / scale);
  Line(out, "class=\"scale\" stroke=\"black\" stroke-width=\"2\"", kMargin, y,
       kMargin + bar * scale, y);
  Text(out, "class=\"scale\"", kMargin + bar * scale + 6, y + 4, LengthLabel(bar));
}

}  // namespace

std::string FingerDrawingSvg(const FingerGeometry& geometry, const std::vector<Obstacle>& objects,
                             const std::vector<std::pair<double, FingerConfiguration>>& frames) {
  if (frames.empty()) throw std::invalid_argument("FingerDrawingSvg: no frames to draw");
  for (const auto& [g, configuration] : frames) {
    RequireFinite("FingerDrawingSvg", g, configuration.theta.allFinite());
  }

  // The common window (metres): every frame's joints, every object and the palm's top.
  const double palm_y = geometry.palm_y();
  Window window(0.0, palm_y);
  std::vector<std::array<Eigen::Vector2d, 4>> points;
  std::vector<double> gs;
  for (const auto& [g, configuration] : frames) {
    gs.push_back(g);
    points.push_back(geometry.Points(configuration.theta));
    for (const Eigen::Vector2d& p : points.back()) window.Include(p.x(), p.y());
  }
  for (const Obstacle& object : objects) window.Include(object);
  window.Grow(kWorldMargin);
  const View view{
      window, kPanelPixels / std::max(window.x_max - window.x_min, window.y_max - window.y_min)};
  const double drawing_height = view.height();
  const int n = static_cast<int>(frames.size());
  const PanelGrid grid(n, view.width(), drawing_height + kCaption);

  std::ostringstream out;
  OpenSvg(out, grid.width, grid.height, AtG("Finger configurations", gs));
  Text(out, "class=\"title\" font-size=\"15\"", kMargin, kMargin + 12, "Finger configurations");

  for (int i = 0; i < n; ++i) {
    const auto& [g, configuration] = frames[i];
    OpenGroup(out, "panel", grid.Left(i), grid.Top(i));
    FrameRect(out, grid.panel_width, drawing_height);
    PalmRect(out, 0.0, view.Y(palm_y), grid.panel_width, drawing_height - view.Y(palm_y));
    Objects(out, view, objects);
    const auto& p = points[i];
    for (int k = 0; k < 3; ++k) {
      Line(out,
           "class=\"link l" + std::to_string(k + 1) + "\" stroke=\"" + kLinkColours[k] +
               "\" stroke-width=\"" + Px(kLinkWidth) + "\" stroke-linecap=\"round\"",
           view.X(p[k].x()), view.Y(p[k].y()), view.X(p[k + 1].x()), view.Y(p[k + 1].y()));
    }
    for (int k = 0; k < 3; ++k) Joint(out, view.X(p[k].x()), view.Y(p[k].y()), kJointRadius);
    Text(out, "class=\"caption\" text-anchor=\"middle\"", grid.panel_width / 2, drawing_height + 17,
         "g = " + Label(g) + ", phase " + Escape(PhaseName(configuration.phase)));
    out << "</g>\n";
  }

  // Footer: a scale bar and the link colours.
  const double footer_y = grid.FooterY();
  out << "<g class=\"footer\">\n";
  ScaleBar(out, footer_y, view.scale);
  for (int k = 0; k < 3; ++k) {
    const double x = kMargin + 150 + 80 * k;
    Line(out,
         "class=\"key\" stroke=\"" + std::string(kLinkColours[k]) +
             "\" stroke-width=\"6.00\" stroke-linecap=\"round\"",
         x, footer_y, x + 20, footer_y);
    Text(out, "class=\"key\"", x + 28, footer_y + 4, "link " + std::to_string(k + 1));
  }
  out << "</g>\n</svg>\n";
  return out.str();
}

std::string HandDrawingSvg(const Hand& hand, const std::vector<HandFrame>& frames) {
  if (frames.empty()) throw std::invalid_argument("HandDrawingSvg: no frames to draw");
  for (const HandFrame& frame : frames) {
    bool finite = true;
    for (const FingerConfiguration& finger : frame.fingers) finite &= finger.theta.allFinite();
    RequireFinite("HandDrawingSvg", frame.g, finite);
  }

  // The palm spans the finger bases (joint 1 does not move) with this margin, in x and z.
  constexpr double kPalmMargin = 0.02;
  constexpr std::array<const char*, 3> kFingerNames = {"A", "B", "C"};
  constexpr std::array<const char*, 3> kFingerColours = {"#1b9e77", "#7570b3", "#e7298a"};
  constexpr double kStripGap = 14.0;  // between the side view and the view from above
  constexpr double kPhases = 14.0;    // the phases line under the caption
  constexpr double kKeySpacing = 90.0, kHandMinWidth = 460.0;  // room for the legend
  // Finger C is thinner and dashed, so finger B shows where the two coincide.
  std::array<std::string, 3> finger_styles;
  for (int f = 0; f < 3; ++f) {
    finger_styles[f] = std::string("stroke=\"") + kFingerColours[f] + "\" stroke-width=\"" +
                       Px(f == 2 ? kLinkWidth / 2 : kLinkWidth) + "\" stroke-linecap=\"round\"" +
                       (f == 2 ? " stroke-dasharray=\"4 6\"" : "");
  }
  const std::array<double, 3> joint_radii = {kJointRadius, kJointRadius, 2.0};

  // Palm extent from the finger bases.
  const double palm_y = hand.finger(0).geometry().palm_y();
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
  const double palm_x0 = base_x_min - kPalmMargin, palm_x1 = base_x_max + kPalmMargin;
  const double palm_z0 = base_z_min - kPalmMargin, palm_z1 = base_z_max + kPalmMargin;

  // The common windows (metres): side (x, y) and from above (x, z; "y" of the window is z).
  Window side(palm_x0, palm_y), above(palm_x0, palm_z0);
  side.Include(palm_x1, palm_y);
  above.Include(palm_x1, palm_z1);
  std::vector<std::array<std::array<Eigen::Vector3d, 4>, 3>> points;
  std::vector<double> gs;
  for (const HandFrame& frame : frames) {
    gs.push_back(frame.g);
    auto& frame_points = points.emplace_back();
    for (int f = 0; f < 3; ++f) {
      frame_points[f] = hand.Points(f, frame.fingers[f].theta);
      for (const Eigen::Vector3d& p : frame_points[f]) {
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
  // From above (from +y) with x to the right, z points down the page.
  auto Z = [&](double z) { return (z - above.y_min) * scale; };
  const double side_height = side_view.height(), above_height = above_view.height();
  const double above_top = side_height + kStripGap;
  const double caption_top = above_top + above_height;
  const int n = static_cast<int>(frames.size());
  const PanelGrid grid(n, side_view.width(), caption_top + kCaption + kPhases, kHandMinWidth);

  const std::string spread = "spread angle " + Label(hand.spread_angle()) + " deg";
  std::ostringstream out;
  OpenSvg(out, grid.width, grid.height, AtG("Hand configurations", gs) + " (" + spread + ")");
  Text(out, "class=\"title\" font-size=\"15\"", kMargin, kMargin + 12,
       "Hand configurations (" + spread + ")");

  for (int i = 0; i < n; ++i) {
    const HandFrame& frame = frames[i];
    const auto& p = points[i];
    OpenGroup(out, "panel", grid.Left(i), grid.Top(i));
    // Side view.
    FrameRect(out, grid.panel_width, side_height);
    PalmRect(out, side_view.X(palm_x0), side_view.Y(palm_y), (palm_x1 - palm_x0) * scale,
             side_height - side_view.Y(palm_y));
    Objects(out, side_view, hand.objects());
    for (int f = 0; f < 3; ++f) {
      out << "<g class=\"finger " << kFingerNames[f] << "\" " << finger_styles[f] << ">\n";
      for (int k = 0; k < 3; ++k) {
        Line(out, "class=\"link l" + std::to_string(k + 1) + "\"", side_view.X(p[f][k].x()),
             side_view.Y(p[f][k].y()), side_view.X(p[f][k + 1].x()), side_view.Y(p[f][k + 1].y()));
      }
      out << "</g>\n";
    }
    for (int f = 0; f < 3; ++f) {
      for (int k = 0; k < 3; ++k) {
        Joint(out, side_view.X(p[f][k].x()), side_view.Y(p[f][k].y()), joint_radii[f]);
      }
    }
    // From above: objects are extruded along z, so they cross the whole strip.
    OpenGroup(out, "top-view", 0.0, above_top);
    FrameRect(out, grid.panel_width, above_height);
    PalmRect(out, side_view.X(palm_x0), Z(palm_z0), (palm_x1 - palm_x0) * scale,
             (palm_z1 - palm_z0) * scale);
    for (const Obstacle& object : hand.objects()) {
      const double x0 = std::min(object.a().x(), object.b().x()) - object.radius();
      const double x1 = std::max(object.a().x(), object.b().x()) + object.radius();
      out << "<rect class=\"object\" x=\"" << Px(side_view.X(x0)) << "\" y=\"0.00\" width=\""
          << Px((x1 - x0) * scale) << "\" height=\"" << Px(above_height)
          << "\" fill=\"#e6a0a0\" fill-opacity=\"0.6\" stroke=\"#a03030\"/>\n";
    }
    for (int f = 0; f < 3; ++f) {
      out << "<g class=\"finger " << kFingerNames[f] << "\" " << finger_styles[f] << ">\n";
      for (int k = 0; k < 3; ++k) {
        Line(out, "class=\"top l" + std::to_string(k + 1) + "\"", side_view.X(p[f][k].x()),
             Z(p[f][k].z()), side_view.X(p[f][k + 1].x()), Z(p[f][k + 1].z()));
      }
      out << "</g>\n";
    }
    Text(out, "class=\"view\" font-size=\"9\" fill=\"#555555\"", 2, -3, "from above");
    out << "</g>\n";
    Text(out, "class=\"caption\" text-anchor=\"middle\"", grid.panel_width / 2, caption_top + 17,
         "g = " + Label(frame.g));
    std::string phases;
    for (int f = 0; f < 3; ++f) {
      phases += std::string(f == 0 ? "" : ", ") + kFingerNames[f] + " " +
                Escape(PhaseName(frame.fingers[f].phase));
    }
    Text(out, "class=\"phases\" text-anchor=\"middle\" font-size=\"10\" fill=\"#555555\"",
         grid.panel_width / 2, caption_top + 17 + kPhases, "phases " + phases);
    out << "</g>\n";
  }

  // Footer: a scale bar and the fingers.
  const double footer_y = grid.FooterY();
  out << "<g class=\"footer\">\n";
  ScaleBar(out, footer_y, scale);
  for (int f = 0; f < 3; ++f) {
    const double x = kMargin + 150 + kKeySpacing * f;
    Line(out, "class=\"key\" " + finger_styles[f], x, footer_y, x + 20, footer_y);
    Text(out, "class=\"key\"", x + 28, footer_y + 4, std::string("finger ") + kFingerNames[f]);
  }
  out << "</g>\n</svg>\n";
  return out.str();
}

std::string AnglePlotSvg(const FingerClosedForm& closed_form, const std::string& title) {
  const double g_max = closed_form.parameters().motor_max;

  // Samples: multiples of 0.5 counts, the end of the range and every breakpoint.
  std::vector<double> gs;
  for (int k = 0; k * 0.5 <= g_max; ++k) gs.push_back(k * 0.5);
  gs.push_back(g_max);
  for (const FingerClosedForm::Piece& piece : closed_form.pieces()) {
    for (double g : {piece.g0, piece.g1}) gs.push_back(std::clamp(g, 0.0, g_max));
  }
  std::sort(gs.begin(), gs.end());
  std::vector<double> samples;
  for (double g : gs) {
    if (samples.empty() || g - samples.back() > 1e-9) samples.push_back(g);
  }
  std::vector<Eigen::Vector3d> thetas;
  double lo = -60.0, hi = 100.0;
  for (double g : samples) {
    thetas.push_back(closed_form.At(g).theta);
    lo = std::min(lo, 20.0 * std::floor(thetas.back().minCoeff() / 20.0));
    hi = std::max(hi, 20.0 * std::ceil(thetas.back().maxCoeff() / 20.0));
  }

  // Layout (pixels).
  constexpr double kWidth = 640.0, kHeight = 420.0;
  constexpr double kLeft = 64.0, kRight = 130.0, kTop = 48.0, kBottom = 56.0;
  const double plot_width = kWidth - kLeft - kRight, plot_height = kHeight - kTop - kBottom;
  auto X = [&](double g) { return kLeft + g / g_max * plot_width; };
  auto Y = [&](double theta) { return kTop + (hi - theta) / (hi - lo) * plot_height; };

  std::ostringstream out;
  OpenSvg(out, kWidth, kHeight, title);
  Text(out, "class=\"title\" font-size=\"15\" text-anchor=\"middle\"", kLeft + plot_width / 2,
       kTop - 18, Escape(title));

  out << "<g class=\"axes\">\n";
  for (double g = 0.0; g <= g_max; g += 50.0) {
    Line(out, "class=\"grid\" data-g=\"" + Label(g) + "\" stroke=\"#dddddd\"", X(g), kTop, X(g),
         kTop + plot_height);
    Line(out, "class=\"tick\" stroke=\"black\"", X(g), kTop + plot_height, X(g),
         kTop + plot_height + 5);
    Text(out, "class=\"tick\" text-anchor=\"middle\"", X(g), kTop + plot_height + 18, Label(g));
  }
  for (double theta = lo; theta <= hi; theta += 20.0) {
    Line(out,
         "class=\"grid\" data-theta=\"" + Label(theta) + "\" stroke=\"" +
             (theta == 0.0 ? "#999999" : "#dddddd") + "\"",
         kLeft, Y(theta), kLeft + plot_width, Y(theta));
    Line(out, "class=\"tick\" stroke=\"black\"", kLeft - 5, Y(theta), kLeft, Y(theta));
    Text(out, "class=\"tick\" text-anchor=\"end\"", kLeft - 8, Y(theta) + 4, Label(theta));
  }
  out << "<rect class=\"frame\" x=\"" << Px(kLeft) << "\" y=\"" << Px(kTop) << "\" width=\""
      << Px(plot_width) << "\" height=\"" << Px(plot_height)
      << "\" fill=\"none\" stroke=\"black\"/>\n";
  Text(out, "class=\"axis-label\" text-anchor=\"middle\"", kLeft + plot_width / 2, kHeight - 16,
       "motor position g (counts)");
  out << "<text class=\"axis-label\" text-anchor=\"middle\" transform=\"translate(" << Px(18) << ','
      << Px(kTop + plot_height / 2) << ") rotate(-90)\">joint angle (degrees)</text>\n";
  out << "</g>\n";

  if (std::isfinite(closed_form.stop())) {
    const double x = X(closed_form.stop());
    const bool right_half = closed_form.stop() > g_max / 2;
    out << "<g class=\"stop\">\n";
    Line(out, "class=\"stop\" stroke=\"#444444\" stroke-dasharray=\"6 4\"", x, kTop, x,
         kTop + plot_height);
    Text(out, std::string("class=\"stop\" text-anchor=\"") + (right_half ? "end" : "start") + "\"",
         right_half ? x - 4 : x + 4, kTop + 14,
         "motor stops (g = " + Label(closed_form.stop()) + ")");
    out << "</g>\n";
  }

  out << "<g class=\"curves\">\n";
  for (int k = 0; k < 3; ++k) {
    out << "<polyline class=\"theta" << k + 1 << "\" fill=\"none\" stroke=\"" << kLinkColours[k]
        << "\" stroke-width=\"2\" stroke-linejoin=\"round\" points=\"";
    for (size_t i = 0; i < samples.size(); ++i) {
      out << (i == 0 ? "" : " ") << Px(X(samples[i])) << ',' << Px(Y(thetas[i][k]));
    }
    out << "\"/>\n";
  }
  out << "</g>\n";

  out << "<g class=\"legend\">\n";
  for (int k = 0; k < 3; ++k) {
    const double x = kLeft + plot_width + 16, y = kTop + 12 + 22 * k;
    Line(out, "class=\"key\" stroke=\"" + std::string(kLinkColours[k]) + "\" stroke-width=\"2\"", x,
         y, x + 24, y);
    Text(out, "class=\"key\"", x + 30, y + 4, "&#952;" + std::to_string(k + 1) + " (deg)");
  }
  out << "</g>\n</svg>\n";
  return out.str();
}

std::string XmlEscape(std::string_view text, bool attribute) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += attribute ? "&quot;" : "\"";
        break;
      case '\'':
        out += attribute ? "&apos;" : "'";
        break;
      default: {
        // Control characters other than tab and newline are not allowed in XML 1.0.
        const bool control = static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n';
        out += control ? ' ' : c;
      }
    }
  }
  return out;
}

}  // namespace hybrid::gripper
