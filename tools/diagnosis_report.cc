#include "tools/diagnosis_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string_view>
#include <tuple>

#include "gripper/svg_figures.h"
#include "gripper/finger_effects.h"

namespace hybrid::cli {
namespace {

constexpr const char* kBlue = "#1f77b4";
constexpr const char* kRed = "#d62728";
constexpr const char* kGrey = "#888888";
constexpr const char* kDash = "6 4";

/// `x` with at most 4 significant digits, no exponent for ordinary magnitudes and no trailing
/// zeros. Non-finite values (never written on purpose) become "0".
std::string Num(double x) {
  if (!std::isfinite(x) || x == 0.0) return "0";
  char buffer[64];
  if (std::abs(x) >= 1e15 || std::abs(x) < 1e-6) {
    std::snprintf(buffer, sizeof buffer, "%.3e", x);
    return buffer;
  }
  const int digits = static_cast<int>(std::floor(std::log10(std::abs(x)))) + 1;
  const int decimals = std::clamp(4 - digits, 0, 9);
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, x);
  std::string s = buffer;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string Escape(std::string_view text) { return gripper::XmlEscape(text, true); }

double At(const std::vector<double>& v, std::size_t i) {
  return i < v.size() ? v[i] : std::nan("");
}

struct Range {
  double lo = -1.0, hi = 1.0;
};

/// Accumulates the finite values of an axis.
struct Extent {
  double lo = INFINITY, hi = -INFINITY;
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  /// Padded 5% on each side; +-1 around a degenerate range, [-1, 1] when empty.
  Range Padded() const {
    if (!(lo <= hi)) return {};
    if (!(hi - lo > 0.0) || !std::isfinite(hi - lo)) return {lo - 1.0, lo + 1.0};
    const double pad = 0.05 * (hi - lo);
    return {lo - pad, hi + pad};
  }
};

/// A plot area in pixels and the data ranges it shows.
struct Axes {
  double left = 0, top = 0, width = 0, height = 0;
  Range x, y;
  double X(double v) const { return left + (v - x.lo) / (x.hi - x.lo) * width; }
  double Y(double v) const { return top + height - (v - y.lo) / (y.hi - y.lo) * height; }
};

/// "Nice" tick step (1, 2 or 5 times a power of ten) for about `target` ticks over `r`.
double TickStep(const Range& r, int target) {
  const double raw = (r.hi - r.lo) / std::max(target, 1);
  if (!(raw > 0.0) || !std::isfinite(raw)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  const double nice = f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0;
  return nice * magnitude;
}

std::vector<double> Ticks(const Range& r, double step) {
  std::vector<double> ticks;
  const double first = std::ceil(r.lo / step) * step;
  for (int k = 0; k < 50; ++k) {
    double v = first + k * step;
    if (v > r.hi + 1e-9 * step) break;
    if (std::abs(v) < 1e-9 * step) v = 0.0;
    ticks.push_back(v);
  }
  return ticks;
}

std::string TickLabel(double v, double step) {
  if (std::abs(v) >= 1e15) return Num(v);
  const int decimals = std::clamp(-static_cast<int>(std::floor(std::log10(step) + 1e-9)), 0, 9);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  std::string s = buffer;
  if (s.find_first_not_of("-0.") == std::string::npos) s = "0";
  return s;
}

/// SVG document builder.
class Svg {
 public:
  Svg(double width, double height) {
    out_ = "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 " + Num(width) + " " +
           Num(height) + "\" width=\"" + Num(width) + "\" height=\"" + Num(height) +
           "\" font-family=\"sans-serif\" font-size=\"11\">\n";
    out_ += "<rect x=\"0\" y=\"0\" width=\"" + Num(width) + "\" height=\"" + Num(height) +
            "\" fill=\"white\"/>\n";
  }

  void Open(const std::string& attributes) { out_ += "<g " + attributes + ">\n"; }
  void Close() { out_ += "</g>\n"; }

  void Text(double x, double y, std::string_view text, const std::string& attributes = "") {
    out_ += "<text x=\"" + Num(x) + "\" y=\"" + Num(y) + "\"";
    if (!attributes.empty()) out_ += " " + attributes;
    out_ += ">" + Escape(text) + "</text>\n";
  }

  void Line(double x1, double y1, double x2, double y2, const std::string& attributes) {
    out_ += "<line x1=\"" + Num(x1) + "\" y1=\"" + Num(y1) + "\" x2=\"" + Num(x2) + "\" y2=\"" +
            Num(y2) + "\" " + attributes + "/>\n";
  }

  void Rect(double x, double y, double w, double h, const std::string& attributes) {
    out_ += "<rect x=\"" + Num(x) + "\" y=\"" + Num(y) + "\" width=\"" + Num(w) + "\" height=\"" +
            Num(h) + "\" " + attributes + "/>\n";
  }

  void Dot(double x, double y) {
    out_ += "<circle cx=\"" + Num(x) + "\" cy=\"" + Num(y) + "\" r=\"1.2\"/>\n";
  }

  /// One <polyline> per stretch of consecutive points whose coordinates are both finite.
  void Polylines(const Axes& a, const std::vector<double>& xs, const std::vector<double>& ys) {
    const std::size_t n = std::max(xs.size(), ys.size());
    bool open = false;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = At(xs, i), y = At(ys, i);
      if (!std::isfinite(x) || !std::isfinite(y)) {
        if (open) out_ += "\"/>\n";
        open = false;
        continue;
      }
      out_ += open ? " " : "<polyline points=\"";
      out_ += Num(a.X(x)) + "," + Num(a.Y(y));
      open = true;
    }
    if (open) out_ += "\"/>\n";
  }

  /// Frame, ticks with numbers and axis labels of a panel.
  void Frame(const Axes& a, const std::string& x_label, const std::string& y_label, int x_ticks = 8,
             int y_ticks = 5) {
    Rect(a.left, a.top, a.width, a.height, "fill=\"none\" stroke=\"#444\" stroke-width=\"0.8\"");
    Open("stroke=\"#444\" stroke-width=\"0.8\"");
    const double xs = TickStep(a.x, x_ticks), ys = TickStep(a.y, y_ticks);
    const std::vector<double> xt = Ticks(a.x, xs), yt = Ticks(a.y, ys);
    const double bottom = a.top + a.height;
    for (double v : xt) Line(a.X(v), bottom, a.X(v), bottom + 4, "");
    for (double v : yt) Line(a.left - 4, a.Y(v), a.left, a.Y(v), "");
    Close();
    Open("fill=\"#222\" font-size=\"10\"");
    for (double v : xt) {
      Text(a.X(v), bottom + 14, TickLabel(v, xs), "text-anchor=\"middle\"");
    }
    for (double v : yt) {
      Text(a.left - 6, a.Y(v) + 3.5, TickLabel(v, ys), "text-anchor=\"end\"");
    }
    Close();
    if (!x_label.empty()) {
      Text(a.left + a.width / 2, bottom + 28, x_label, "text-anchor=\"middle\"");
    }
    if (!y_label.empty()) {
      const double x = 14, y = a.top + a.height / 2;
      Text(x, y, y_label,
           "text-anchor=\"middle\" transform=\"rotate(-90 " + Num(x) + " " + Num(y) + ")\"");
    }
  }

  /// A horizontal legend: each entry is a marker (drawn by `marker` at its x) and a label.
  enum class Marker { kSquare, kDashed, kSolid };
  void Legend(double x, double y,
              const std::vector<std::tuple<Marker, std::string, std::string>>& entries) {
    for (const auto& [marker, color, label] : entries) {
      switch (marker) {
        case Marker::kSquare:
          Rect(x + 8, y - 6, 5, 5, "fill=\"" + color + "\"");
          break;
        case Marker::kDashed:
          Line(x, y - 3.5, x + 22, y - 3.5,
               "stroke=\"" + color + "\" stroke-width=\"1.5\" stroke-dasharray=\"" + kDash + "\"");
          break;
        case Marker::kSolid:
          Line(x, y - 3.5, x + 22, y - 3.5, "stroke=\"" + color + "\" stroke-width=\"1.5\"");
          break;
      }
      Text(x + 27, y, label);
      x += 27 + 6.5 * static_cast<double>(label.size()) + 24;
    }
  }

  std::string Finish() {
    out_ += "</svg>\n";
    return std::move(out_);
  }

 private:
  std::string out_;
};

constexpr std::array<const char*, 3> kJoint = {"theta1", "theta2", "theta3"};

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

std::string RunFile(const RunCurves& run) {
  constexpr double kWidth = 800, kLeft = 64, kRight = 16, kPanel = 150, kGap = 40, kTop = 62;
  constexpr double kStrip = 50;
  const double plot_width = kWidth - kLeft - kRight;
  const double strip_top = kTop + 3 * (kPanel + kGap);
  const double height = strip_top + kStrip + 44;
  const std::size_t n = RunLength(run);
  std::vector<double> index(n);
  for (std::size_t i = 0; i < n; ++i) index[i] = static_cast<double>(i);
  Extent x_extent;
  if (n > 0) {
    x_extent.Add(0.0);
    x_extent.Add(static_cast<double>(n - 1));
  }
  const Range x_range = x_extent.Padded();

  Svg svg(kWidth, height);
  svg.Text(kWidth / 2, 22, "Run " + run.label, "text-anchor=\"middle\" font-size=\"15\"");
  svg.Legend(kLeft, 44,
             {{Svg::Marker::kSquare, kGrey, "measured"},
              {Svg::Marker::kDashed, kBlue, "baseline model"},
              {Svg::Marker::kSolid, kRed, "extended model"}});
  for (int j = 0; j < 3; ++j) {
    Extent y;
    for (std::size_t i = 0; i < n; ++i) {
      y.Add(At(run.measured[j], i));
      y.Add(At(run.baseline[j], i));
      y.Add(At(run.extended[j], i));
    }
    Axes a{kLeft, kTop + j * (kPanel + kGap), plot_width, kPanel, x_range, y.Padded()};
    svg.Open("class=\"panel\" id=\"" + std::string(kJoint[j]) + "\"");
    svg.Frame(a, "", std::string(kJoint[j]) + " (deg)");
    svg.Open("class=\"measured\" fill=\"" + std::string(kGrey) + "\"");
    for (std::size_t i = 0; i < n; ++i) {
      const double v = At(run.measured[j], i);
      if (std::isfinite(v)) svg.Dot(a.X(static_cast<double>(i)), a.Y(v));
    }
    svg.Close();
    svg.Open("class=\"baseline\" fill=\"none\" stroke=\"" + std::string(kBlue) +
             "\" stroke-width=\"1.5\" stroke-dasharray=\"" + kDash +
             "\" stroke-linecap=\"round\" stroke-linejoin=\"round\"");
    svg.Polylines(a, index, run.baseline[j]);
    svg.Close();
    svg.Open("class=\"extended\" fill=\"none\" stroke=\"" + std::string(kRed) +
             "\" stroke-width=\"1.5\" stroke-linecap=\"round\" stroke-linejoin=\"round\"");
    svg.Polylines(a, index, run.extended[j]);
    svg.Close();
    svg.Close();
  }
  Extent g;
  for (double v : run.g) g.Add(v);
  Axes a{kLeft, strip_top, plot_width, kStrip, x_range, g.Padded()};
  svg.Open("class=\"motor\"");
  svg.Frame(a, "sample", "g", 8, 2);
  svg.Open("fill=\"none\" stroke=\"#333333\" stroke-width=\"1.2\" stroke-linecap=\"round\"");
  svg.Polylines(a, index, run.g);
  svg.Close();
  svg.Close();
  return svg.Finish();
}

std::string ResidualsFile(const Diagnosis& d) {
  constexpr double kWidth = 800, kLeft = 64, kRight = 16, kPanel = 170, kGap = 50, kTop = 62;
  const double height = kTop + 3 * (kPanel + kGap) - kGap + 44;
  Extent x;
  for (const RunCurves& run : d.curves) {
    for (double v : run.g) x.Add(v);
  }
  const Range x_range = x.Padded();

  Svg svg(kWidth, height);
  svg.Text(kWidth / 2, 22, "Residuals (measured - model) against g",
           "text-anchor=\"middle\" font-size=\"15\"");
  svg.Legend(kLeft, 44,
             {{Svg::Marker::kSquare, kBlue, "baseline"},
              {Svg::Marker::kSquare, kRed, "extended"},
              {Svg::Marker::kDashed, kGrey, "±2 noise sd"}});
  for (int j = 0; j < 3; ++j) {
    // (g, residual) of both models over all runs.
    std::array<std::vector<std::pair<double, double>>, 2> points;
    Extent y;
    for (const RunCurves& run : d.curves) {
      const std::size_t n = RunLength(run);
      for (std::size_t i = 0; i < n; ++i) {
        const double g = At(run.g, i), m = At(run.measured[j], i);
        if (!std::isfinite(g) || !std::isfinite(m)) continue;
        const std::array<double, 2> model = {At(run.baseline[j], i), At(run.extended[j], i)};
        for (int k = 0; k < 2; ++k) {
          const double r = m - model[k];
          if (!std::isfinite(r)) continue;
          points[k].emplace_back(g, r);
          y.Add(r);
        }
      }
    }
    const double variance = d.noise.variance[j];
    const double sd = std::isfinite(variance) && variance > 0 ? std::sqrt(variance) : 0.0;
    if (sd > 0) {
      y.Add(2 * sd);
      y.Add(-2 * sd);
    }
    Axes a{kLeft, kTop + j * (kPanel + kGap), kWidth - kLeft - kRight, kPanel, x_range, y.Padded()};
    svg.Open("class=\"panel\" id=\"" + std::string(kJoint[j]) + "\"");
    svg.Frame(a, "g (motor position)", "residual " + std::string(kJoint[j]) + " (deg)");
    if (a.y.lo < 0 && a.y.hi > 0) {
      svg.Line(a.left, a.Y(0), a.left + a.width, a.Y(0), "stroke=\"#bbbbbb\" stroke-width=\"0.8\"");
    }
    const std::array<const char*, 2> color = {kBlue, kRed};
    const std::array<const char*, 2> name = {"baseline", "extended"};
    for (int k = 0; k < 2; ++k) {
      svg.Open("class=\"" + std::string(name[k]) + "\" fill=\"" + color[k] +
               "\" fill-opacity=\"0.6\"");
      for (const auto& [g, r] : points[k]) svg.Dot(a.X(g), a.Y(r));
      svg.Close();
    }
    if (sd > 0) {
      svg.Open("class=\"noise\" stroke=\"" + std::string(kGrey) +
               "\" stroke-width=\"1\" stroke-dasharray=\"" + kDash + "\"");
      for (double s : {2 * sd, -2 * sd}) svg.Line(a.left, a.Y(s), a.left + a.width, a.Y(s), "");
      svg.Close();
    }
    svg.Close();
  }
  return svg.Finish();
}

std::string Join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string s;
  for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? separator : "") + parts[i];
  return s;
}

std::string SummaryFile(const Diagnosis& d) {
  constexpr double kWidth = 640, kHeight = 420, kLeft = 72, kRight = 16, kTop = 86, kBottom = 60;
  Axes a{kLeft, kTop, kWidth - kLeft - kRight, kHeight - kTop - kBottom, {0, 3}, {}};
  double top = 0;
  for (int j = 0; j < 3; ++j) {
    for (double v : {d.baseline_mse[j], d.extended_mse[j], d.noise.variance[j]}) {
      if (std::isfinite(v)) top = std::max(top, v);
    }
  }
  a.y = top > 0 ? Range{0, 1.05 * top} : Range{0, 1};

  Svg svg(kWidth, kHeight);
  const std::string cause = d.cause.empty() ? "none" : Join(d.cause, ", ");
  svg.Text(kWidth / 2, 22, "Cause: " + cause, "text-anchor=\"middle\" font-size=\"15\"");
  std::vector<std::string> parameters;
  for (const auto& [p, value] : d.parameters) {
    const std::string unit(ParameterUnit(p));
    parameters.push_back(ParameterName(p) + " = " + (std::isfinite(value) ? Num(value) : "?") +
                         (unit.empty() ? "" : " " + unit));
  }
  if (!parameters.empty()) {
    svg.Text(kWidth / 2, 40, Join(parameters, "; "), "text-anchor=\"middle\"");
  }
  svg.Legend(kLeft, 62,
             {{Svg::Marker::kSquare, kBlue, "baseline"},
              {Svg::Marker::kSquare, kRed, "extended"},
              {Svg::Marker::kSolid, "#000000", "noise floor variance"}});
  svg.Rect(a.left, a.top, a.width, a.height, "fill=\"none\" stroke=\"#444\" stroke-width=\"0.8\"");
  const double step = TickStep(a.y, 5);
  const std::vector<double> ticks = Ticks(a.y, step);
  svg.Open("stroke=\"#444\" stroke-width=\"0.8\"");
  for (double v : ticks) svg.Line(a.left - 4, a.Y(v), a.left, a.Y(v), "");
  svg.Close();
  svg.Open("fill=\"#222\" font-size=\"10\"");
  for (double v : ticks)
    svg.Text(a.left - 6, a.Y(v) + 3.5, TickLabel(v, step), "text-anchor=\"end\"");
  svg.Close();
  {
    const double x = 16, y = a.top + a.height / 2;
    svg.Text(x, y, "held-out MSE (deg^2)",
             "text-anchor=\"middle\" transform=\"rotate(-90 " + Num(x) + " " + Num(y) + ")\"");
  }
  const double group = a.width / 3, bar = group * 0.3;
  for (int j = 0; j < 3; ++j) {
    const double centre = a.left + group * (j + 0.5);
    svg.Open("class=\"joint\" id=\"" + std::string(kJoint[j]) + "\"");
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
    svg.Close();
  }
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
