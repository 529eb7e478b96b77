#include "hybrid/plotting/svg_plot.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace hybrid::plotting {
namespace {

// Enough for any double in fixed notation with up to 17 decimals (1.8e308 has 309 digits).
constexpr int kFixedBuffer = 400;

// The value at index i, NaN past the end (a missing point).
double At(std::span<const double> values, std::size_t i) {
  return i < values.size() ? values[i] : std::nan("");
}

}  // namespace

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

std::string FormatFixed(double value, int decimals) {
  char buffer[kFixedBuffer];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::fixed,
                                 std::clamp(decimals, 0, 17));
  if (ec != std::errc()) throw std::logic_error("cannot format a number in fixed notation");
  std::string out(buffer, end);
  // "-0.00" (a small negative value) reads as zero: no sign.
  if (out.size() > 1 && out[0] == '-' && out.find_first_not_of("0.", 1) == std::string::npos) {
    out.erase(0, 1);
  }
  return out;
}

std::string FormatShortest(double value) {
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  if (ec != std::errc()) throw std::logic_error("cannot format a number");
  return std::string(buffer, end);
}

std::string FormatRounded(double value, int decimals) {
  double scale = 1.0;  // 10^decimals, exact
  for (int k = 0; k < std::clamp(decimals, 0, 15); ++k) scale *= 10.0;
  // + 0.0 turns -0 into 0.
  return FormatShortest(std::round(value * scale) / scale + 0.0);
}

std::string FormatSignificant(double value, int digits) {
  if (!std::isfinite(value) || value == 0.0) return "0";
  digits = std::clamp(digits, 1, 9);
  char buffer[64];
  if (std::abs(value) >= 1e15 || std::abs(value) < 1e-6) {
    std::snprintf(buffer, sizeof buffer, "%.*e", digits - 1, value);
    return buffer;
  }
  const int integer_digits = static_cast<int>(std::floor(std::log10(std::abs(value)))) + 1;
  const int decimals = std::clamp(digits - integer_digits, 0, 9);
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  std::string s = buffer;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string FormatTick(double value, double step) {
  if (std::abs(value) >= 1e15) return FormatSignificant(value, 4);
  const int decimals = std::clamp(-static_cast<int>(std::floor(std::log10(step) + 1e-9)), 0, 9);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  std::string s = buffer;
  if (s.find_first_not_of("-0.") == std::string::npos) s = "0";
  return s;
}

std::string WithUnit(std::string_view quantity, std::string_view unit) {
  std::string title(quantity);
  if (!unit.empty()) title.append(" (").append(unit).append(")");
  return title;
}

void Extent::Add(double value) {
  if (!std::isfinite(value)) return;
  lo_ = std::min(lo_, value);
  hi_ = std::max(hi_, value);
}

Range Extent::Padded(double fraction) const {
  if (empty()) return {};
  if (!(hi_ - lo_ > 0.0) || !std::isfinite(hi_ - lo_)) return {lo_ - 1.0, lo_ + 1.0};
  const double pad = fraction * (hi_ - lo_);
  return {lo_ - pad, hi_ + pad};
}

double NiceStep(const Range& range, int target_count) {
  const double raw = (range.hi - range.lo) / std::max(target_count, 1);
  if (!(raw > 0.0) || !std::isfinite(raw)) return 1.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  const double nice = f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0;
  return nice * magnitude;
}

double NiceLengthAtMost(double limit) {
  const double decade = std::pow(10.0, std::floor(std::log10(limit)));
  for (double factor : {5.0, 2.0, 1.0}) {
    if (factor * decade <= limit) return factor * decade;
  }
  return decade;
}

std::vector<double> Ticks(const Range& range, double step, int max_count) {
  std::vector<double> ticks;
  const double first = std::ceil(range.lo / step) * step;
  for (int k = 0; k < max_count; ++k) {
    double v = first + k * step;
    if (v > range.hi + 1e-9 * step) break;
    if (std::abs(v) < 1e-9 * step) v = 0.0;
    ticks.push_back(v);
  }
  return ticks;
}

SvgPlot::SvgPlot(NumberStyle numbers, AttributePlacement placement)
    : numbers_(numbers), placement_(placement) {}

std::string SvgPlot::Number(double value) const {
  return numbers_ == NumberStyle::kFixed2 ? FormatFixed(value, 2) : FormatSignificant(value, 4);
}

SvgPlot& SvgPlot::Start(std::string_view element) {
  out_.append("<").append(element);
  return *this;
}

SvgPlot& SvgPlot::Attribute(std::string_view name, double value) {
  out_.append(" ").append(name).append("=\"").append(Number(value)).append("\"");
  return *this;
}

SvgPlot& SvgPlot::Attribute(std::string_view name, std::string_view text) {
  out_.append(" ").append(name).append("=\"").append(XmlEscape(text, true)).append("\"");
  return *this;
}

SvgPlot& SvgPlot::Attributes(std::string_view attributes) {
  out_.append(" ").append(attributes);
  return *this;
}

SvgPlot& SvgPlot::EndEmpty() {
  out_.append("/>\n");
  return *this;
}

SvgPlot& SvgPlot::EndStart() {
  out_.append(">\n");
  return *this;
}

SvgPlot& SvgPlot::Content(std::string_view element, std::string_view markup) {
  out_.append(">").append(markup).append("</").append(element).append(">\n");
  return *this;
}

SvgPlot& SvgPlot::End(std::string_view element) {
  out_.append("</").append(element).append(">\n");
  return *this;
}

void SvgPlot::Presentation(std::string_view attributes, bool before) {
  if (attributes.empty() || before != (placement_ == AttributePlacement::kBeforeGeometry)) return;
  Attributes(attributes);
}

SvgPlot& SvgPlot::Line(double x1, double y1, double x2, double y2, std::string_view attributes) {
  Start("line");
  Presentation(attributes, true);
  Attribute("x1", x1).Attribute("y1", y1).Attribute("x2", x2).Attribute("y2", y2);
  Presentation(attributes, false);
  return EndEmpty();
}

SvgPlot& SvgPlot::PlainLine(double x1, double y1, double x2, double y2) {
  Start("line").Attribute("x1", x1).Attribute("y1", y1).Attribute("x2", x2).Attribute("y2", y2);
  return Attributes("").EndEmpty();
}

SvgPlot& SvgPlot::Rect(double x, double y, double width, double height,
                       std::string_view attributes) {
  Start("rect");
  Presentation(attributes, true);
  Attribute("x", x).Attribute("y", y).Attribute("width", width).Attribute("height", height);
  Presentation(attributes, false);
  return EndEmpty();
}

SvgPlot& SvgPlot::Text(double x, double y, std::string_view text, std::string_view attributes) {
  return TextMarkup(x, y, XmlEscape(text, true), attributes);
}

SvgPlot& SvgPlot::TextMarkup(double x, double y, std::string_view markup,
                             std::string_view attributes) {
  Start("text");
  Presentation(attributes, true);
  Attribute("x", x).Attribute("y", y);
  Presentation(attributes, false);
  return Content("text", markup);
}

SvgPlot& SvgPlot::Polyline(std::span<const Point> points, std::string_view attributes) {
  Start("polyline");
  Presentation(attributes, true);
  out_.append(" points=\"");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i > 0) out_.append(" ");
    out_.append(Number(points[i].x)).append(",").append(Number(points[i].y));
  }
  out_.append("\"");
  Presentation(attributes, false);
  return EndEmpty();
}

SvgPlot& SvgPlot::Group(std::string_view attributes) {
  Start("g");
  if (!attributes.empty()) Attributes(attributes);
  return EndStart();
}

SvgPlot& SvgPlot::EndGroup() { return End("g"); }

void SvgPlot::Axes(const PlotArea& area, std::string_view x_title, std::string_view y_title,
                   const AxesStyle& style) {
  Rect(area.left, area.top, area.width, area.height,
       "fill=\"none\" stroke=\"#444\" stroke-width=\"0.8\"");
  const double x_step = NiceStep(area.x, style.x_ticks);
  const double y_step = NiceStep(area.y, style.y_ticks);
  const std::vector<double> x_ticks =
      style.x_ticks > 0 ? Ticks(area.x, x_step) : std::vector<double>();
  const std::vector<double> y_ticks =
      style.y_ticks > 0 ? Ticks(area.y, y_step) : std::vector<double>();
  const double bottom = area.bottom();
  Group("stroke=\"#444\" stroke-width=\"0.8\"");
  for (double v : x_ticks) PlainLine(area.X(v), bottom, area.X(v), bottom + 4);
  for (double v : y_ticks) PlainLine(area.left - 4, area.Y(v), area.left, area.Y(v));
  EndGroup();
  Group("fill=\"#222\" font-size=\"10\"");
  for (double v : x_ticks) {
    Text(area.X(v), bottom + 14, FormatTick(v, x_step), "text-anchor=\"middle\"");
  }
  for (double v : y_ticks) {
    Text(area.left - 6, area.Y(v) + 3.5, FormatTick(v, y_step), "text-anchor=\"end\"");
  }
  EndGroup();
  if (!x_title.empty()) {
    Text(area.left + area.width / 2, bottom + 28, x_title, "text-anchor=\"middle\"");
  }
  if (!y_title.empty()) {
    const double x = style.y_title_x, y = area.top + area.height / 2;
    Text(x, y, y_title,
         "text-anchor=\"middle\" transform=\"rotate(-90 " + Number(x) + " " + Number(y) + ")\"");
  }
}

void SvgPlot::Series(const PlotArea& area, std::span<const double> xs, std::span<const double> ys,
                     std::string_view attributes) {
  const std::size_t n = std::max(xs.size(), ys.size());
  std::vector<Point> stretch;
  for (std::size_t i = 0; i <= n; ++i) {
    const double x = At(xs, i), y = At(ys, i);  // i == n: NaN, ends the last stretch
    if (std::isfinite(x) && std::isfinite(y)) {
      stretch.push_back({area.X(x), area.Y(y)});
    } else if (!stretch.empty()) {
      Polyline(stretch, attributes);
      stretch.clear();
    }
  }
}

void SvgPlot::Marker(double x, double y, double radius) {
  Start("circle").Attribute("cx", x).Attribute("cy", y).Attribute("r", radius).EndEmpty();
}

void SvgPlot::Legend(double x, double y, std::span<const LegendEntry> entries,
                     const LegendLayout& layout) {
  constexpr double kSquare = 5.0, kSquareInset = 8.0;
  for (const LegendEntry& entry : entries) {
    if (entry.key == LegendKey::kLine) {
      Line(x, y, x + layout.key_length, y, entry.key_attributes);
    } else {
      Rect(x + kSquareInset, y - kSquare / 2, kSquare, kSquare, entry.key_attributes);
    }
    TextMarkup(x + layout.label_offset, y + layout.label_drop, entry.label,
               layout.label_attributes);
    if (layout.vertical) {
      y += layout.spacing;
    } else {
      x += layout.spacing + layout.per_character * static_cast<double>(entry.label.size());
    }
  }
}

std::string SvgPlot::Finish() {
  out_.append("</svg>\n");
  std::string document = std::move(out_);
  out_.clear();
  return document;
}

}  // namespace hybrid::plotting
