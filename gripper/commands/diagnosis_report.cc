#include "gripper/commands/diagnosis_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string_view>

#include "hybrid/gripper/finger_effects.h"
#include "hybrid/plotting/svg_plot.h"

namespace hybrid::cli {
namespace {

using plotting::AttributePlacement;
using plotting::AxesStyle;
using plotting::Extent;
using plotting::LegendEntry;
using plotting::LegendKey;
using plotting::NumberStyle;
using plotting::PlotArea;
using plotting::SvgPlot;
using plotting::WithUnit;
using Range = plotting::Range;

constexpr const char* kBlue = "#1f77b4";
constexpr const char* kRed = "#d62728";
constexpr const char* kGrey = "#888888";
constexpr const char* kDash = "6 4";
constexpr double kDot = 1.2;  // radius of a measured sample or a residual, in pixels

constexpr std::array<const char*, 3> kJoint = {"theta1", "theta2", "theta3"};

// A number in the report's text: at most 4 significant digits.
std::string Num(double x) { return plotting::FormatSignificant(x, 4); }

double At(const std::vector<double>& v, std::size_t i) {
  return i < v.size() ? v[i] : std::nan("");
}

// A report file: numbers with at most 4 significant digits, presentation attributes after the
// geometry; the root element (11-pixel sans-serif text) and a white page.
SvgPlot OpenReport(double width, double height) {
  SvgPlot svg(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  svg.Start("svg")
      .Attribute("xmlns", "http://www.w3.org/2000/svg")
      .Attribute("viewBox", "0 0 " + svg.Number(width) + " " + svg.Number(height))
      .Attribute("width", width)
      .Attribute("height", height)
      .Attribute("font-family", "sans-serif")
      .Attribute("font-size", "11")
      .EndStart();
  svg.Rect(0, 0, width, height, "fill=\"white\"");
  return svg;
}

// The file's title, centred at the top.
void Title(SvgPlot& svg, double width, const std::string& title) {
  svg.Text(width / 2, 22, title, "text-anchor=\"middle\" font-size=\"15\"");
}

// Legend keys: a square of colour (dots), a dashed or a solid line.
LegendEntry Square(const char* colour, std::string_view label) {
  return {LegendKey::kSquare, "fill=\"" + std::string(colour) + "\"",
          plotting::XmlEscape(label, true)};
}
LegendEntry Dashed(const char* colour, std::string_view label) {
  return {LegendKey::kLine,
          "stroke=\"" + std::string(colour) + "\" stroke-width=\"1.5\" stroke-dasharray=\"" +
              kDash + "\"",
          plotting::XmlEscape(label, true)};
}
LegendEntry Solid(const char* colour, std::string_view label) {
  return {LegendKey::kLine, "stroke=\"" + std::string(colour) + "\" stroke-width=\"1.5\"",
          plotting::XmlEscape(label, true)};
}

// A legend row from the left margin `left`, its labels' baseline at `baseline`.
void LegendRow(SvgPlot& svg, double left, double baseline, const std::vector<LegendEntry>& keys) {
  svg.Legend(left, baseline - plotting::LegendLayout().label_drop, keys);
}

std::string SanitisedLabel(const std::string& label, std::size_t index) {
  if (label.empty()) return std::to_string(index + 1);
  std::string s = label;
  for (char& c : s) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) c = '_';
  }
  return s;
}

std::size_t RunLength(const RunCurves& run) {
  std::size_t n = run.g.size();
  for (int j = 0; j < 3; ++j) {
    n = std::max({n, run.measured[j].size(), run.baseline[j].size(), run.extended[j].size()});
  }
  return n;
}

// A run's file (RunFile), in pixels: page width, margins, the three panels and the motor strip.
constexpr double kRunWidth = 800, kLeft = 64, kRight = 16, kRunPanel = 150, kRunGap = 40;
constexpr double kTop = 62, kStrip = 50;

// One panel of a run: joint j's measured samples as dots, the baseline model dashed and the
// extended model solid, against the request g (the report's figures; the curves retrace on
// reopening); samples without a finite g are left out.
void DrawRunPanel(SvgPlot& svg, const RunCurves& run, int j, const PlotArea& a,
                  const std::vector<double>& g) {
  svg.Group("class=\"panel\" id=\"" + std::string(kJoint[j]) + "\"");
  svg.Axes(a, j == 2 ? WithUnit("request g", "counts") : "", WithUnit(kJoint[j], "deg"));
  svg.Group("class=\"measured\" fill=\"" + std::string(kGrey) + "\"");
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double v = At(run.measured[j], i);
    if (std::isfinite(v) && std::isfinite(g[i])) svg.Marker(a.X(g[i]), a.Y(v), kDot);
  }
  svg.EndGroup();
  svg.Group("class=\"baseline\" fill=\"none\" stroke=\"" + std::string(kBlue) +
            "\" stroke-width=\"1.5\" stroke-dasharray=\"" + kDash +
            "\" stroke-linecap=\"round\" stroke-linejoin=\"round\"");
  svg.Series(a, g, run.baseline[j]);
  svg.EndGroup();
  svg.Group("class=\"extended\" fill=\"none\" stroke=\"" + std::string(kRed) +
            "\" stroke-width=\"1.5\" stroke-linecap=\"round\" stroke-linejoin=\"round\"");
  svg.Series(a, g, run.extended[j]);
  svg.EndGroup();
  svg.EndGroup();
}

// The strip under a run's panels: the protocol, the request g against the sample index.
void DrawMotorStrip(SvgPlot& svg, const RunCurves& run, const PlotArea& a,
                    const std::vector<double>& index) {
  svg.Group("class=\"motor\"");
  svg.Axes(a, "sample", WithUnit("g", "counts"), AxesStyle{8, 2, 14});
  svg.Group("fill=\"none\" stroke=\"#333333\" stroke-width=\"1.2\" stroke-linecap=\"round\"");
  svg.Series(a, index, run.g);
  svg.EndGroup();
  svg.EndGroup();
}

std::string RunFile(const RunCurves& run) {
  const double plot_width = kRunWidth - kLeft - kRight;
  const double strip_top = kTop + 3 * (kRunPanel + kRunGap);
  const double height = strip_top + kStrip + 44;
  const std::size_t n = RunLength(run);
  std::vector<double> index(n), g(n);
  Extent index_extent, g_extent;
  for (std::size_t i = 0; i < n; ++i) {
    index[i] = static_cast<double>(i);
    index_extent.Add(index[i]);
    g[i] = At(run.g, i);
    g_extent.Add(g[i]);
  }
  const Range x_range = g_extent.Padded();

  SvgPlot svg = OpenReport(kRunWidth, height);
  Title(svg, kRunWidth, "Run " + run.label);
  LegendRow(
      svg, kLeft, 44,
      {Square(kGrey, "measured"), Dashed(kBlue, "baseline model"), Solid(kRed, "extended model")});
  for (int j = 0; j < 3; ++j) {
    Extent y;
    for (std::size_t i = 0; i < n; ++i) {
      y.Add(At(run.measured[j], i));
      y.Add(At(run.baseline[j], i));
      y.Add(At(run.extended[j], i));
    }
    DrawRunPanel(svg, run, j,
                 PlotArea{kLeft, kTop + j * (kRunPanel + kRunGap), plot_width, kRunPanel, x_range,
                          y.Padded()},
                 g);
  }
  DrawMotorStrip(
      svg, run,
      PlotArea{kLeft, strip_top, plot_width, kStrip, index_extent.Padded(), g_extent.Padded()},
      index);
  return svg.Finish();
}

// The residuals' file (ResidualsFile), in pixels.
constexpr double kResidualsWidth = 800, kResidualsPanel = 170, kResidualsGap = 50;

// (g, residual) of the baseline ([0]) and the extended ([1]) model of joint j over all runs,
// where g, the measured angle and the model are finite.
std::array<std::vector<std::pair<double, double>>, 2> Residuals(const Diagnosis& d, int j) {
  std::array<std::vector<std::pair<double, double>>, 2> points;
  for (const RunCurves& run : d.curves) {
    const std::size_t n = RunLength(run);
    for (std::size_t i = 0; i < n; ++i) {
      const double g = At(run.g, i), m = At(run.measured[j], i);
      if (!std::isfinite(g) || !std::isfinite(m)) continue;
      const std::array<double, 2> model = {At(run.baseline[j], i), At(run.extended[j], i)};
      for (int k = 0; k < 2; ++k) {
        const double r = m - model[k];
        if (std::isfinite(r)) points[k].emplace_back(g, r);
      }
    }
  }
  return points;
}

// Joint j's panel: both models' residuals as dots, the zero line and the lines at +-2 noise
// standard deviations `sd` (none if sd is 0).
void DrawResidualPanel(SvgPlot& svg, const PlotArea& a, int j,
                       const std::array<std::vector<std::pair<double, double>>, 2>& points,
                       double sd) {
  svg.Group("class=\"panel\" id=\"" + std::string(kJoint[j]) + "\"");
  svg.Axes(a, "g (motor position)", WithUnit("residual " + std::string(kJoint[j]), "deg"));
  if (a.y.lo < 0 && a.y.hi > 0) {
    svg.Line(a.left, a.Y(0), a.left + a.width, a.Y(0), "stroke=\"#bbbbbb\" stroke-width=\"0.8\"");
  }
  const std::array<const char*, 2> color = {kBlue, kRed};
  const std::array<const char*, 2> name = {"baseline", "extended"};
  for (int k = 0; k < 2; ++k) {
    svg.Group("class=\"" + std::string(name[k]) + "\" fill=\"" + color[k] +
              "\" fill-opacity=\"0.6\"");
    for (const auto& [g, r] : points[k]) svg.Marker(a.X(g), a.Y(r), kDot);
    svg.EndGroup();
  }
  if (sd > 0) {
    svg.Group("class=\"noise\" stroke=\"" + std::string(kGrey) +
              "\" stroke-width=\"1\" stroke-dasharray=\"" + kDash + "\"");
    for (double s : {2 * sd, -2 * sd}) svg.PlainLine(a.left, a.Y(s), a.left + a.width, a.Y(s));
    svg.EndGroup();
  }
  svg.EndGroup();
}

std::string ResidualsFile(const Diagnosis& d) {
  const double height = kTop + 3 * (kResidualsPanel + kResidualsGap) - kResidualsGap + 44;
  Extent x;
  for (const RunCurves& run : d.curves) {
    for (double v : run.g) x.Add(v);
  }
  const Range x_range = x.Padded();

  SvgPlot svg = OpenReport(kResidualsWidth, height);
  Title(svg, kResidualsWidth, "Residuals (measured - model) against g");
  LegendRow(svg, kLeft, 44,
            {Square(kBlue, "baseline"), Square(kRed, "extended"), Dashed(kGrey, "±2 noise sd")});
  for (int j = 0; j < 3; ++j) {
    const auto points = Residuals(d, j);
    Extent y;
    for (const auto& model : points) {
      for (const auto& [g, r] : model) y.Add(r);
    }
    const double variance = d.noise.variance[j];
    const double sd = std::isfinite(variance) && variance > 0 ? std::sqrt(variance) : 0.0;
    if (sd > 0) {
      y.Add(2 * sd);
      y.Add(-2 * sd);
    }
    const PlotArea a{kLeft,
                     kTop + j * (kResidualsPanel + kResidualsGap),
                     kResidualsWidth - kLeft - kRight,
                     kResidualsPanel,
                     x_range,
                     y.Padded()};
    DrawResidualPanel(svg, a, j, points, sd);
  }
  return svg.Finish();
}

std::string Join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string s;
  for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? separator : "") + parts[i];
  return s;
}

// The summary's file (SummaryFile), in pixels.
constexpr double kSummaryWidth = 640, kSummaryHeight = 420, kSummaryLeft = 72, kSummaryTop = 86;
constexpr double kSummaryBottom = 60;

// The MSE axis: from 0 to 5% above the largest finite MSE or noise variance; [0, 1] if none is
// positive.
Range MseRange(const Diagnosis& d) {
  double top = 0;
  for (int j = 0; j < 3; ++j) {
    for (double v : {d.baseline_mse[j], d.extended_mse[j], d.noise.variance[j]}) {
      if (std::isfinite(v)) top = std::max(top, v);
    }
  }
  return top > 0 ? Range{0, 1.05 * top} : Range{0, 1};
}

// "name = value unit" of every fitted parameter, "?" for a value that is not finite.
std::vector<std::string> ParameterTexts(const Diagnosis& d) {
  std::vector<std::string> parameters;
  for (const auto& [p, value] : d.parameters) {
    const std::string unit(ParameterUnit(p));
    parameters.push_back(ParameterName(p) + " = " + (std::isfinite(value) ? Num(value) : "?") +
                         (unit.empty() ? "" : " " + unit));
  }
  return parameters;
}

// Joint j's bars (baseline left, extended right of the group's centre, each labelled with its
// MSE), the noise floor variance as a tick across them and the joint's name underneath.
void DrawJointBars(SvgPlot& svg, const PlotArea& a, const Diagnosis& d, int j) {
  const double group = a.width / 3, bar = group * 0.3;
  const double centre = a.left + group * (j + 0.5);
  svg.Group("class=\"joint\" id=\"" + std::string(kJoint[j]) + "\"");
  const std::array<double, 2> mse = {d.baseline_mse[j], d.extended_mse[j]};
  const std::array<const char*, 2> color = {kBlue, kRed};
  for (int k = 0; k < 2; ++k) {
    if (!std::isfinite(mse[k])) continue;
    const double x = centre + (k == 0 ? -bar : 0.0);
    const double y = a.Y(std::max(mse[k], 0.0));
    svg.Rect(x, y, bar, a.top + a.height - y, "fill=\"" + std::string(color[k]) + "\"");
    svg.Text(x + bar / 2, y - 3, Num(mse[k]), "text-anchor=\"middle\" font-size=\"9\"");
  }
  const double variance = d.noise.variance[j];
  if (std::isfinite(variance)) {
    const double y = a.Y(std::max(variance, 0.0));
    svg.Line(centre - bar * 1.3, y, centre + bar * 1.3, y,
             "class=\"noise\" stroke=\"#000000\" stroke-width=\"2\"");
  }
  svg.Text(centre, a.top + a.height + 16, kJoint[j], "text-anchor=\"middle\"");
  svg.EndGroup();
}

std::string SummaryFile(const Diagnosis& d) {
  const PlotArea a{kSummaryLeft,
                   kSummaryTop,
                   kSummaryWidth - kSummaryLeft - kRight,
                   kSummaryHeight - kSummaryTop - kSummaryBottom,
                   {0, 3},
                   MseRange(d)};
  SvgPlot svg = OpenReport(kSummaryWidth, kSummaryHeight);
  Title(svg, kSummaryWidth, "Cause: " + (d.cause.empty() ? "none" : Join(d.cause, ", ")));
  const std::vector<std::string> parameters = ParameterTexts(d);
  if (!parameters.empty()) {
    svg.Text(kSummaryWidth / 2, 40, Join(parameters, "; "), "text-anchor=\"middle\"");
  }
  LegendRow(svg, kSummaryLeft, 62,
            {Square(kBlue, "baseline"), Square(kRed, "extended"),
             Solid("#000000", "noise floor variance")});
  // The MSE axis only: the joints' names label the groups of bars.
  svg.Axes(a, "", WithUnit("held-out MSE", "deg^2"), AxesStyle{0, 5, 16});
  for (int j = 0; j < 3; ++j) DrawJointBars(svg, a, d, j);
  return svg.Finish();
}

}  // namespace

std::vector<std::pair<std::string, std::string>> DiagnosisReportFiles(const Diagnosis& d,
                                                                      const std::string& dir) {
  if (dir.empty()) throw std::invalid_argument("the report directory is empty");
  std::vector<std::pair<std::string, std::string>> files;
  std::set<std::string> used;
  for (std::size_t r = 0; r < d.curves.size(); ++r) {
    const std::string base = SanitisedLabel(d.curves[r].label, r);
    std::string name = base;
    for (int k = 2; used.count(name) > 0; ++k) name = base + "_" + std::to_string(k);
    used.insert(name);
    files.emplace_back(dir + "/run_" + name + ".svg", RunFile(d.curves[r]));
  }
  files.emplace_back(dir + "/residuals.svg", ResidualsFile(d));
  files.emplace_back(dir + "/summary.svg", SummaryFile(d));
  return files;
}

}  // namespace hybrid::cli
