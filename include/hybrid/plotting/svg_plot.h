#pragma once

#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hybrid::plotting {

// ---------------------------------------------------------------------------------------------
// Text and numbers. Every function here is deterministic: the same value gives the same text on
// every platform (std::to_chars and printf's "%.*f" / "%.*e", no locale).

/// `text` escaped for XML: & < > always, and " ' too when `attribute` (text content needs no
/// quote escaping); control characters other than tab and newline (not allowed in XML 1.0)
/// become spaces. Other bytes (UTF-8 included) are kept.
std::string XmlEscape(std::string_view text, bool attribute = false);

/// `value` in fixed notation with exactly `decimals` (0 to 17) decimals, e.g. FormatFixed(2.5, 2)
/// is "2.50"; a result that reads as zero never has a minus sign (-0.001 gives "0.00", not
/// "-0.00"). Non-finite values give "inf", "-inf" or "nan".
std::string FormatFixed(double value, int decimals);

/// `value` in the shortest decimal form that parses back to the same double ("110", "62.5",
/// "1e+20"); non-finite values give "inf", "-inf" or "nan".
std::string FormatShortest(double value);

/// `value` rounded to `decimals` (0 to 15) decimals, half away from zero, then written shortest:
/// FormatRounded(62.499, 2) is "62.5", FormatRounded(110, 2) is "110". Never "-0".
std::string FormatRounded(double value, int decimals);

/// `value` with at most `digits` (1 to 9) significant digits, no trailing zeros and no exponent
/// for magnitudes in [1e-6, 1e15) (FormatSignificant(1234.5678, 4) is "1235",
/// FormatSignificant(0.000123456, 4) is "0.0001235"); outside them "%.<digits-1>e"
/// ("1.235e+15"). Zero and non-finite values give "0".
std::string FormatSignificant(double value, int digits);

/// The label of a tick at `value` on an axis whose ticks are `step` apart: as many decimals as
/// the step needs (step 0.2 gives "0.4", step 50 gives "150"), "0" for any rounded zero ("-0.0"
/// included); magnitudes of 1e15 and more as FormatSignificant(value, 4).
std::string FormatTick(double value, double step);

/// An axis title with its unit: "quantity (unit)", or just `quantity` if `unit` is empty.
std::string WithUnit(std::string_view quantity, std::string_view unit);

// ---------------------------------------------------------------------------------------------
// Ranges and ticks.

/// A closed interval [lo, hi] of data values (lo < hi for a drawable axis).
struct Range {
  double lo = -1.0;
  double hi = 1.0;
};

/// The smallest range holding the finite values added to it (non-finite ones are ignored).
class Extent {
 public:
  void Add(double value);
  /// True until a finite value has been added.
  bool empty() const { return !(lo_ <= hi_); }
  /// The values' range widened by `fraction` of its width on each side; [v - 1, v + 1] if all
  /// values equal v (or the width overflows), and [-1, 1] if there are none.
  Range Padded(double fraction = 0.05) const;

 private:
  double lo_ = std::numeric_limits<double>::infinity();
  double hi_ = -std::numeric_limits<double>::infinity();
};

/// A "nice" tick step, 1, 2 or 5 times a power of ten, for about `target_count` (>= 1; smaller
/// counts as 1) intervals over `range`: the raw step (width / count) rounded to 1 below 1.5, to 2
/// below 3.5, to 5 below 7.5, else to 10 (times its power of ten). 1 for an empty, reversed or
/// non-finite range. E.g. NiceStep({0, 10}, 5) = 2, NiceStep({0, 1}, 4) = 0.2.
double NiceStep(const Range& range, int target_count);

/// The largest length of the form 1, 2 or 5 times a power of ten that is at most `limit` (> 0,
/// finite), e.g. 0.05 for 0.07 and 200 for 499 (a scale bar's length).
double NiceLengthAtMost(double limit);

/// The multiples of `step` (> 0) in `range`, ascending, at most `max_count` of them: from the
/// first multiple at or above range.lo up to range.hi (plus 1e-9 step, so a bound that is a
/// multiple up to rounding is included); a tick within 1e-9 step of zero is exactly 0.
std::vector<double> Ticks(const Range& range, double step, int max_count = 50);

// ---------------------------------------------------------------------------------------------
// The document.

/// A point in pixels.
struct Point {
  double x = 0.0;
  double y = 0.0;
};

/// A plot area in pixels (left, top, width, height; pixel rows grow down) and the data ranges it
/// shows: x from x.lo at the left to x.hi at the right, y from y.lo at the bottom to y.hi at the
/// top.
struct PlotArea {
  double left = 0.0, top = 0.0, width = 0.0, height = 0.0;
  Range x, y;
  /// The pixel column of data value `v`: left + (v - x.lo) / (x.hi - x.lo) * width.
  double X(double v) const { return left + (v - x.lo) / (x.hi - x.lo) * width; }
  /// The pixel row of data value `v`: top + height - (v - y.lo) / (y.hi - y.lo) * height.
  double Y(double v) const { return top + height - (v - y.lo) / (y.hi - y.lo) * height; }
  double bottom() const { return top + height; }
};

/// How a document writes its numbers (coordinates, sizes).
enum class NumberStyle {
  kFixed2,        ///< FormatFixed(value, 2): "12.50", "0.00".
  kSignificant4,  ///< FormatSignificant(value, 4): "12.5", "1235", "0".
};

/// Where an element's presentation attributes (a preformatted string such as
/// `class="tick" stroke="black"`) go in the element helpers of a document.
enum class AttributePlacement {
  kBeforeGeometry,  ///< <line class="tick" x1="..." .../>
  kAfterGeometry,   ///< <line x1="..." ... class="tick"/>
};

/// The key of a legend entry.
enum class LegendKey {
  kLine,    ///< a horizontal line, key_length long, from the entry's x on the key line
  kSquare,  ///< a 5-pixel square from 8 pixels into the entry, centred on the key line
};

/// One entry of a legend: its key, drawn with `key_attributes` (e.g. `stroke="#1f77b4"
/// stroke-width="2"`; for a square e.g. `fill="#1f77b4"`), and its label, as markup (already
/// escaped, so it may hold character references such as "&#952;").
struct LegendEntry {
  LegendKey key = LegendKey::kLine;
  std::string key_attributes;
  std::string label;
};

/// Where a legend's pieces go, in pixels, relative to each entry's origin (the left end of its
/// key line).
struct LegendLayout {
  /// Entries one under the other, `spacing` apart; otherwise side by side.
  bool vertical = false;
  /// The length of a line key.
  double key_length = 22.0;
  /// The label's x (its start) and baseline relative to the key line's left end.
  double label_offset = 27.0;
  double label_drop = 3.5;
  /// From one entry's origin to the next's; side by side, plus `per_character` pixels per byte
  /// of the previous label (a width estimate, so that labels of any length fit).
  double spacing = 51.0;
  double per_character = 6.5;
  /// Presentation attributes of the labels' <text> (none when empty).
  std::string label_attributes;
};

/// The look of Axes(): which ticks to draw and where the y title goes.
struct AxesStyle {
  /// About how many intervals NiceStep() aims for on each axis; 0 draws no ticks on that axis.
  int x_ticks = 8;
  int y_ticks = 5;
  /// The x of the rotated y title's centre (its y is the middle of the area).
  double y_title_x = 14.0;
};

/// An SVG document written element by element, with deterministic numbers (its NumberStyle) and
/// escaped text: the writer shared by every figure (the gripper's drawings and angle plots, the
/// diagnosis report).
///
/// Two layers:
/// - a tag builder that writes attributes in the order it is called (Start, Attribute,
///   Attributes, then EndEmpty, EndStart or Content), for any element, the root <svg> included;
/// - element helpers (Line, Rect, Text, Polyline, Group, ...) and plot pieces (Axes, Series,
///   Marker, Legend) that put their presentation attributes where the document's
///   AttributePlacement says: written after a space when not empty, nothing when empty (the one
///   exception, PlainLine, is spelled out).
/// Finish() closes the root element. The writer does not check nesting: the caller opens the
/// root with the builder and closes every group it opens. Nothing here throws apart from
/// std::bad_alloc.
class SvgPlot {
 public:
  explicit SvgPlot(NumberStyle numbers,
                   AttributePlacement placement = AttributePlacement::kBeforeGeometry);

  /// `value` as this document writes numbers.
  std::string Number(double value) const;

  // The tag builder.
  /// Writes "<" and `element`.
  SvgPlot& Start(std::string_view element);
  /// Writes ` name="<Number(value)>"`.
  SvgPlot& Attribute(std::string_view name, double value);
  /// Writes ` name="<text>"`, `text` escaped for an attribute (quotes included).
  SvgPlot& Attribute(std::string_view name, std::string_view text);
  /// Writes a space and `attributes` verbatim (preformatted), even when `attributes` is empty.
  SvgPlot& Attributes(std::string_view attributes);
  /// Ends an element without content: "/>" and a newline.
  SvgPlot& EndEmpty();
  /// Ends a start tag whose children follow: ">" and a newline (close with End(element)).
  SvgPlot& EndStart();
  /// Ends a start tag, writes `markup` verbatim and the end tag: ">markup</element>" and a
  /// newline.
  SvgPlot& Content(std::string_view element, std::string_view markup);
  /// Writes "</element>" and a newline.
  SvgPlot& End(std::string_view element);

  // Element helpers.
  /// <line> from (x1, y1) to (x2, y2).
  SvgPlot& Line(double x1, double y1, double x2, double y2, std::string_view attributes = {});
  /// A <line> with no attributes of its own, styled by its enclosing group, written
  /// `<line x1=".." y1=".." x2=".." y2=".." />` (with a space before "/>", unlike Line()).
  SvgPlot& PlainLine(double x1, double y1, double x2, double y2);
  /// <rect> with its top left corner at (x, y).
  SvgPlot& Rect(double x, double y, double width, double height, std::string_view attributes = {});
  /// <text> at (x, y) holding `text`, escaped (quotes included).
  SvgPlot& Text(double x, double y, std::string_view text, std::string_view attributes = {});
  /// <text> at (x, y) holding `markup` verbatim (escape it with XmlEscape).
  SvgPlot& TextMarkup(double x, double y, std::string_view markup,
                      std::string_view attributes = {});
  /// <polyline points="x,y x,y ..."> through `points` (in pixels), the points after (before) the
  /// attributes for kBeforeGeometry (kAfterGeometry).
  SvgPlot& Polyline(std::span<const Point> points, std::string_view attributes = {});
  /// "<g attributes>" and a newline, or "<g>" when `attributes` is empty; close with EndGroup.
  SvgPlot& Group(std::string_view attributes);
  /// "</g>" and a newline.
  SvgPlot& EndGroup();

  // Plot pieces.
  /// The frame of `area` (a <rect> with `fill="none" stroke="#444" stroke-width="0.8"`), its
  /// ticks (NiceStep, Ticks), pointing 4 pixels out of the frame, in a group with the same
  /// stroke, the ticks' numbers (FormatTick; font size 10, x numbers centred 14 pixels below the
  /// frame, y numbers right-aligned 6 pixels left of it) in a second group, the x title centred
  /// 28 pixels below the frame and the y title rotated by -90 degrees, centred at
  /// (style.y_title_x, middle of the area). Empty titles are not drawn. The tick lines are
  /// PlainLine()s.
  void Axes(const PlotArea& area, std::string_view x_title, std::string_view y_title,
            const AxesStyle& style = {});
  /// One <polyline> (with `attributes`) per stretch of consecutive points (xs[i], ys[i]), mapped
  /// through `area`, whose coordinates are both finite; an index beyond the shorter vector is a
  /// missing point. Nothing for no finite point.
  void Series(const PlotArea& area, std::span<const double> xs, std::span<const double> ys,
              std::string_view attributes = {});
  /// A dot, <circle cx=".." cy=".." r=".."/>, at (x, y) pixels (style it with a group).
  void Marker(double x, double y, double radius);
  /// A legend whose first entry's key line starts at (x, y); every entry is its key (LegendKey)
  /// and then its label at (origin x + label_offset, origin y + label_drop).
  void Legend(double x, double y, std::span<const LegendEntry> entries,
              const LegendLayout& layout = {});

  /// The document so far.
  const std::string& text() const { return out_; }
  /// Closes the root element ("</svg>" and a newline) and returns the document; the writer is
  /// left empty.
  std::string Finish();

 private:
  // Writes " attributes" if `attributes` is not empty and `before` matches the placement.
  void Presentation(std::string_view attributes, bool before);

  NumberStyle numbers_;
  AttributePlacement placement_;
  std::string out_;
};

}  // namespace hybrid::plotting
