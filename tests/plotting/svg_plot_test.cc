// The SVG plotting module (include/hybrid/plotting/svg_plot.h) against expectations worked out by
// hand: XML escaping, number formats, the 1-2-5 rule of tick steps and scale bars, ticks, the plot
// area's mapping, the exact markup of every element helper in both attribute placements, series
// split at missing values, legends, axes, and well-formed documents (checked by a small tag parser:
// no std::regex, whose recursion overflows the stack under AddressSanitizer).
#include "hybrid/plotting/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace hybrid::plotting {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size())) {
    ++n;
  }
  return n;
}

// Checks that `svg` is one <svg> element with properly nested tags, quoted attributes and no raw
// '<' or unknown entity in text; returns an empty string or what is wrong.
std::string MarkupProblem(const std::string& svg) {
  std::vector<std::string> open;
  int roots = 0;
  for (std::size_t i = 0; i < svg.size();) {
    if (svg[i] == '&') {
      const std::size_t semicolon = svg.find(';', i);
      if (semicolon == std::string::npos) return "unterminated entity at " + std::to_string(i);
      const std::string entity = svg.substr(i, semicolon + 1 - i);
      const bool known = entity == "&amp;" || entity == "&lt;" || entity == "&gt;" ||
                         entity == "&quot;" || entity == "&apos;" ||
                         (entity.size() > 3 && entity[1] == '#');
      if (!known) return "unknown entity " + entity;
      i = semicolon + 1;
      continue;
    }
    if (svg[i] == '>') return "stray '>' at " + std::to_string(i);
    if (svg[i] != '<') {
      if (open.empty() && svg[i] != '\n') return "text outside the root at " + std::to_string(i);
      ++i;
      continue;
    }
    // A tag: scan to its '>' outside quotes.
    std::size_t j = i + 1;
    char quote = 0;
    for (; j < svg.size() && (quote != 0 || svg[j] != '>'); ++j) {
      if (quote == 0 && svg[j] == '<') return "'<' inside a tag at " + std::to_string(j);
      if (svg[j] == '"') quote = quote == 0 ? '"' : 0;
    }
    if (j == svg.size()) return "unterminated tag at " + std::to_string(i);
    const std::string tag = svg.substr(i + 1, j - i - 1);
    if (!tag.empty() && tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1)) return "unbalanced </" + tag.substr(1);
      open.pop_back();
    } else {
      const std::string name = tag.substr(0, tag.find_first_of(" /"));
      if (name.empty()) return "empty tag name at " + std::to_string(i);
      if (open.empty() && ++roots > 1) return "a second root <" + name + ">";
      if (open.empty() && name != "svg") return "root <" + name + ">, not <svg>";
      if (tag.back() != '/') open.push_back(name);
    }
    i = j + 1;
  }
  if (!open.empty()) return "unclosed <" + open.back() + ">";
  if (roots != 1) return "no root";
  return "";
}

TEST(XmlEscapeTest, EscapesMarkupAndQuotesOnlyInAttributes) {
  EXPECT_EQ(XmlEscape("<&>\"'"), "&lt;&amp;&gt;\"'");
  EXPECT_EQ(XmlEscape("<&>\"'", true), "&lt;&amp;&gt;&quot;&apos;");
  EXPECT_EQ(XmlEscape("a\x01"
                      "b\tc\nd\x1f"),
            "a b\tc\nd ");  // XML 1.0 forbids controls
  EXPECT_EQ(XmlEscape("\xc2\xb1"
                      "2 \xce\xb8"),
            "\xc2\xb1"
            "2 \xce\xb8");  // UTF-8 kept
  EXPECT_EQ(XmlEscape(""), "");
}

TEST(FormatTest, FixedHasExactDecimalsAndNoNegativeZero) {
  EXPECT_EQ(FormatFixed(2.5, 2), "2.50");
  EXPECT_EQ(FormatFixed(3.456, 2), "3.46");
  EXPECT_EQ(FormatFixed(-3.14159, 2), "-3.14");
  EXPECT_EQ(FormatFixed(-0.001, 2), "0.00");
  EXPECT_EQ(FormatFixed(-0.0, 2), "0.00");
  EXPECT_EQ(FormatFixed(-0.004, 0), "0");
  EXPECT_EQ(FormatFixed(12, 0), "12");
  EXPECT_EQ(FormatFixed(1e30, 1), "1000000000000000019884624838656.0");  // the exact double
}

TEST(FormatTest, ShortestAndRounded) {
  EXPECT_EQ(FormatShortest(110), "110");
  EXPECT_EQ(FormatShortest(0.1), "0.1");
  EXPECT_EQ(FormatShortest(62.5), "62.5");
  EXPECT_EQ(FormatShortest(1e20), "1e+20");
  EXPECT_EQ(FormatRounded(62.499, 2), "62.5");
  EXPECT_EQ(FormatRounded(110, 2), "110");
  EXPECT_EQ(FormatRounded(239.1500001, 2), "239.15");
  EXPECT_EQ(FormatRounded(1.23456, 3), "1.235");
  EXPECT_EQ(FormatRounded(-0.001, 2), "0");
  EXPECT_EQ(FormatRounded(2.5, 0), "3");  // half away from zero
}

TEST(FormatTest, SignificantHasAtMostTheGivenDigits) {
  EXPECT_EQ(FormatSignificant(1234.5678, 4), "1235");
  EXPECT_EQ(FormatSignificant(0.000123456, 4), "0.0001235");
  EXPECT_EQ(FormatSignificant(12.5, 4), "12.5");
  EXPECT_EQ(FormatSignificant(100, 4), "100");
  EXPECT_EQ(FormatSignificant(2.0 / 3.0, 4), "0.6667");
  EXPECT_EQ(FormatSignificant(-0.00001, 4), "-0.00001");
  EXPECT_EQ(FormatSignificant(123456, 4), "123456");  // no exponent below 1e15
  EXPECT_EQ(FormatSignificant(1e15, 4), "1.000e+15");
  EXPECT_EQ(FormatSignificant(1.5e-7, 4), "1.500e-07");
  EXPECT_EQ(FormatSignificant(3.14159, 2), "3.1");
  EXPECT_EQ(FormatSignificant(-0.00004, 1), "-0.00004");
  for (double zero_like : {0.0, -0.0, kNaN, kInf, -kInf}) {
    EXPECT_EQ(FormatSignificant(zero_like, 4), "0") << zero_like;
  }
}

TEST(FormatTest, TickLabelsHaveTheDecimalsOfTheirStep) {
  EXPECT_EQ(FormatTick(0.4, 0.2), "0.4");
  EXPECT_EQ(FormatTick(150, 50), "150");
  EXPECT_EQ(FormatTick(0.25, 0.05), "0.25");
  EXPECT_EQ(FormatTick(2, 0.5), "2.0");
  EXPECT_EQ(FormatTick(-0.0, 0.1), "0");
  EXPECT_EQ(FormatTick(-1e-17, 0.1), "0");
  EXPECT_EQ(FormatTick(-40, 20), "-40");
  EXPECT_EQ(FormatTick(2e15, 1e15), "2.000e+15");
}

TEST(FormatTest, AxisTitlesWithUnits) {
  EXPECT_EQ(WithUnit("joint angle", "degrees"), "joint angle (degrees)");
  EXPECT_EQ(WithUnit("sample", ""), "sample");
}

TEST(TicksTest, NiceStepFollowsTheOneTwoFiveRule) {
  EXPECT_DOUBLE_EQ(NiceStep({0, 10}, 5), 2.0);      // raw 2
  EXPECT_DOUBLE_EQ(NiceStep({0, 1}, 4), 0.2);       // raw 0.25: 2.5 < 3.5
  EXPECT_DOUBLE_EQ(NiceStep({0, 100}, 8), 10.0);    // raw 12.5: 1.25 < 1.5
  EXPECT_DOUBLE_EQ(NiceStep({0, 7}, 1), 5.0);       // raw 7 < 7.5
  EXPECT_DOUBLE_EQ(NiceStep({0, 8}, 1), 10.0);      // raw 8 >= 7.5
  EXPECT_DOUBLE_EQ(NiceStep({-60, 100}, 5), 20.0);  // raw 32: 3.2 < 3.5 gives 2, times 10
  EXPECT_DOUBLE_EQ(NiceStep({0, 0.003}, 1), 0.002);
  EXPECT_DOUBLE_EQ(NiceStep({0, 1}, 0), 1.0);  // a count below 1 counts as 1
  EXPECT_DOUBLE_EQ(NiceStep({1, 1}, 5), 1.0);  // empty
  EXPECT_DOUBLE_EQ(NiceStep({2, 1}, 5), 1.0);  // reversed
  EXPECT_DOUBLE_EQ(NiceStep({0, kInf}, 5), 1.0);
}

TEST(TicksTest, NiceLengthAtMostIsOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(0.07), 0.05);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(499), 200);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(1), 1);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(0.0199), 0.01);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(5.5), 5);
}

TEST(TicksTest, MultiplesOfTheStepInsideTheRange) {
  EXPECT_EQ(Ticks({-60, 100}, 20), (std::vector<double>{-60, -40, -20, 0, 20, 40, 60, 80, 100}));
  EXPECT_EQ(Ticks({0, 255}, 50), (std::vector<double>{0, 50, 100, 150, 200, 250}));
  EXPECT_EQ(Ticks({-5, 12}, 5), (std::vector<double>{-5, 0, 5, 10}));
  EXPECT_EQ(Ticks({0.5, 0.9}, 1), std::vector<double>{});
  const std::vector<double> tenths = Ticks({-0.3, 0.35}, 0.1);
  ASSERT_EQ(tenths.size(), 6u);  // -0.2 (-0.3 / 0.1 rounds above -3), ..., 0.3
  EXPECT_EQ(tenths[2], 0.0);
  EXPECT_NEAR(tenths[5], 0.3, 1e-15);
  EXPECT_EQ(Ticks({0, 1 - 1e-12}, 0.5).size(), 3u);  // the bound up to rounding
  EXPECT_EQ(Ticks({0, 1000}, 1).size(), 50u);
  EXPECT_EQ(Ticks({0, 1000}, 1, 7).size(), 7u);
}

TEST(ExtentTest, PaddedRangeOfTheFiniteValues) {
  Extent extent;
  EXPECT_TRUE(extent.empty());
  EXPECT_EQ(extent.Padded().lo, -1.0);
  EXPECT_EQ(extent.Padded().hi, 1.0);
  extent.Add(kNaN);
  extent.Add(kInf);
  EXPECT_TRUE(extent.empty());
  extent.Add(2.0);
  EXPECT_FALSE(extent.empty());
  EXPECT_EQ(extent.Padded().lo, 1.0);  // one value: +-1
  EXPECT_EQ(extent.Padded().hi, 3.0);
  extent.Add(12.0);
  extent.Add(-kInf);
  EXPECT_DOUBLE_EQ(extent.Padded().lo, 1.5);  // 5% of 10 on each side
  EXPECT_DOUBLE_EQ(extent.Padded().hi, 12.5);
  EXPECT_DOUBLE_EQ(extent.Padded(0.1).lo, 1.0);
}

TEST(PlotAreaTest, MapsDataToPixelsWithYUp) {
  const PlotArea area{10, 20, 100, 50, {0, 10}, {-1, 1}};
  EXPECT_DOUBLE_EQ(area.X(0), 10);
  EXPECT_DOUBLE_EQ(area.X(5), 60);
  EXPECT_DOUBLE_EQ(area.X(10), 110);
  EXPECT_DOUBLE_EQ(area.Y(1), 20);
  EXPECT_DOUBLE_EQ(area.Y(0), 45);
  EXPECT_DOUBLE_EQ(area.Y(-1), 70);
  EXPECT_DOUBLE_EQ(area.bottom(), 70);
}

TEST(SvgPlotTest, NumbersInTheDocumentsStyle) {
  EXPECT_EQ(SvgPlot(NumberStyle::kFixed2).Number(-0.001), "0.00");
  EXPECT_EQ(SvgPlot(NumberStyle::kFixed2).Number(1.2), "1.20");
  EXPECT_EQ(SvgPlot(NumberStyle::kSignificant4).Number(1.2), "1.2");
  EXPECT_EQ(SvgPlot(NumberStyle::kSignificant4).Number(kNaN), "0");
}

TEST(SvgPlotTest, TagBuilderWritesAttributesInCallOrder) {
  SvgPlot svg(NumberStyle::kFixed2);
  svg.Start("svg").Attribute("xmlns", "http://www.w3.org/2000/svg").Attribute("width", 10.0);
  svg.Attribute("viewBox", "0 0 " + svg.Number(10) + " " + svg.Number(5)).EndStart();
  svg.Start("title").Content("title", XmlEscape("a < b"));
  svg.Start("rect").Attribute("class", "x\"y").Attributes("fill=\"white\"").EndEmpty();
  svg.Start("line").Attribute("x1", 1.0).Attributes("").EndEmpty();
  EXPECT_EQ(svg.Finish(),
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10.00\" viewBox=\"0 0 10.00 "
            "5.00\">\n"
            "<title>a &lt; b</title>\n"
            "<rect class=\"x&quot;y\" fill=\"white\"/>\n"
            "<line x1=\"1.00\" />\n"
            "</svg>\n");
}

TEST(SvgPlotTest, ElementHelpersWithAttributesBeforeTheGeometry) {
  SvgPlot svg(NumberStyle::kFixed2, AttributePlacement::kBeforeGeometry);
  svg.Group("class=\"panel\"");
  svg.Line(1, 2, 3.456, -0.001, "class=\"a\"");
  svg.Rect(0, 0, 4, 5, "fill=\"none\"");
  svg.Text(1, 2, "x < \"y\"", "class=\"t\"");
  svg.TextMarkup(1, 2, "&#952;1", "class=\"k\"");
  const std::vector<Point> points = {{0, 1}, {2.5, 3}};
  svg.Polyline(points, "class=\"c\"");
  svg.EndGroup();
  EXPECT_EQ(svg.text(),
            "<g class=\"panel\">\n"
            "<line class=\"a\" x1=\"1.00\" y1=\"2.00\" x2=\"3.46\" y2=\"0.00\"/>\n"
            "<rect fill=\"none\" x=\"0.00\" y=\"0.00\" width=\"4.00\" height=\"5.00\"/>\n"
            "<text class=\"t\" x=\"1.00\" y=\"2.00\">x &lt; &quot;y&quot;</text>\n"
            "<text class=\"k\" x=\"1.00\" y=\"2.00\">&#952;1</text>\n"
            "<polyline class=\"c\" points=\"0.00,1.00 2.50,3.00\"/>\n"
            "</g>\n");
}

TEST(SvgPlotTest, ElementHelpersWithAttributesAfterTheGeometry) {
  SvgPlot svg(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  svg.Line(1, 2, 3, 4, "stroke=\"red\"");
  svg.Line(1, 2, 3, 4);
  svg.Rect(0.5, 0, 4, 5, "fill=\"none\"");
  svg.Text(1, 2, "a&b");
  svg.Text(1, 2, "a", "text-anchor=\"end\"");
  const std::vector<Point> points = {{0, 1}, {2.5, 3}};
  svg.Polyline(points);
  svg.Polyline(points, "class=\"c\"");
  svg.Marker(1, 2, 1.2);
  EXPECT_EQ(svg.text(),
            "<line x1=\"1\" y1=\"2\" x2=\"3\" y2=\"4\" stroke=\"red\"/>\n"
            "<line x1=\"1\" y1=\"2\" x2=\"3\" y2=\"4\"/>\n"
            "<rect x=\"0.5\" y=\"0\" width=\"4\" height=\"5\" fill=\"none\"/>\n"
            "<text x=\"1\" y=\"2\">a&amp;b</text>\n"
            "<text x=\"1\" y=\"2\" text-anchor=\"end\">a</text>\n"
            "<polyline points=\"0,1 2.5,3\"/>\n"
            "<polyline points=\"0,1 2.5,3\" class=\"c\"/>\n"
            "<circle cx=\"1\" cy=\"2\" r=\"1.2\"/>\n");
}

TEST(SvgPlotTest, SeriesHasOnePolylinePerFiniteStretch) {
  const PlotArea area{0, 0, 4, 4, {0, 4}, {0, 4}};  // x = v, y = 4 - v
  SvgPlot svg(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  const std::vector<double> xs = {0, 1, 2, 3, 4, 5};
  const std::vector<double> ys = {0, 1, kNaN, 3, kInf, 1, 2};  // the 7th has no x
  svg.Series(area, xs, ys);
  EXPECT_EQ(svg.text(),
            "<polyline points=\"0,4 1,3\"/>\n"
            "<polyline points=\"3,1\"/>\n"
            "<polyline points=\"5,3\"/>\n");
  SvgPlot none(NumberStyle::kSignificant4);
  none.Series(area, xs, std::vector<double>(6, kNaN));
  none.Series(area, {}, {});
  EXPECT_EQ(none.text(), "");
}

TEST(SvgPlotTest, LegendEntriesSideBySideAndOneUnderTheOther) {
  const std::vector<LegendEntry> entries = {{LegendKey::kSquare, "fill=\"#888\"", "dots"},
                                            {LegendKey::kLine, "stroke=\"red\"", "model"}};
  SvgPlot row(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  row.Legend(10, 40.5, entries);  // default layout: labels' baseline 3.5 below the key line
  // The second entry starts 51 + 6.5 * 4 = 77 pixels after the first.
  EXPECT_EQ(row.text(),
            "<rect x=\"18\" y=\"38\" width=\"5\" height=\"5\" fill=\"#888\"/>\n"
            "<text x=\"37\" y=\"44\">dots</text>\n"
            "<line x1=\"87\" y1=\"40.5\" x2=\"109\" y2=\"40.5\" stroke=\"red\"/>\n"
            "<text x=\"114\" y=\"44\">model</text>\n");
  LegendLayout layout;
  layout.vertical = true;
  layout.key_length = 24;
  layout.label_offset = 30;
  layout.label_drop = 4;
  layout.spacing = 22;
  layout.label_attributes = "class=\"key\"";
  SvgPlot column(NumberStyle::kFixed2, AttributePlacement::kBeforeGeometry);
  column.Legend(100, 60, std::vector<LegendEntry>{entries[1], entries[1]}, layout);
  EXPECT_EQ(column.text(),
            "<line stroke=\"red\" x1=\"100.00\" y1=\"60.00\" x2=\"124.00\" y2=\"60.00\"/>\n"
            "<text class=\"key\" x=\"130.00\" y=\"64.00\">model</text>\n"
            "<line stroke=\"red\" x1=\"100.00\" y1=\"82.00\" x2=\"124.00\" y2=\"82.00\"/>\n"
            "<text class=\"key\" x=\"130.00\" y=\"86.00\">model</text>\n");
}

TEST(SvgPlotTest, AxesHaveNiceTicksWithNumbersAndTitles) {
  // x in [0, 10] over 200 pixels, about 5 intervals: step 2, six ticks 40 pixels apart; y in
  // [0, 1] over 100 pixels: step 0.2.
  const PlotArea area{50, 10, 200, 100, {0, 10}, {0, 1}};
  SvgPlot svg(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  svg.Axes(area, "g", "theta1 (deg)", {5, 5, 14});
  const std::string& text = svg.text();
  EXPECT_EQ(text.rfind("<rect x=\"50\" y=\"10\" width=\"200\" height=\"100\" fill=\"none\"", 0),
            0u);
  EXPECT_EQ(Count(text, "<line "), 12);
  EXPECT_EQ(Count(text, " />"), 12);  // tick lines carry the group's stroke
  EXPECT_NE(text.find("<line x1=\"90\" y1=\"110\" x2=\"90\" y2=\"114\" />"), std::string::npos);
  EXPECT_NE(text.find("<line x1=\"46\" y1=\"30\" x2=\"50\" y2=\"30\" />"), std::string::npos);
  for (const char* label : {">0<", ">2<", ">10<", ">0.2<", ">0.8<", ">1.0<"}) {
    EXPECT_NE(text.find(label), std::string::npos) << label;
  }
  EXPECT_NE(text.find("<text x=\"90\" y=\"124\" text-anchor=\"middle\">2</text>"),
            std::string::npos);
  EXPECT_NE(text.find("<text x=\"44\" y=\"33.5\" text-anchor=\"end\">0.8</text>"),
            std::string::npos);
  EXPECT_NE(text.find("<text x=\"150\" y=\"138\" text-anchor=\"middle\">g</text>"),
            std::string::npos);
  EXPECT_NE(text.find("<text x=\"14\" y=\"60\" text-anchor=\"middle\" transform=\"rotate(-90 14 "
                      "60)\">theta1 (deg)</text>"),
            std::string::npos);
  // No x ticks and no titles.
  SvgPlot bare(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
  bare.Axes(area, "", "", {0, 5, 16});
  EXPECT_EQ(Count(bare.text(), "<line "), 6);
  EXPECT_EQ(Count(bare.text(), "<text"), 6);
  EXPECT_EQ(bare.text().find("text-anchor=\"middle\""), std::string::npos);
}

TEST(SvgPlotTest, DocumentsAreWellFormedAndDeterministic) {
  const auto document = [] {
    SvgPlot svg(NumberStyle::kSignificant4, AttributePlacement::kAfterGeometry);
    svg.Start("svg").Attribute("xmlns", "http://www.w3.org/2000/svg").EndStart();
    svg.Start("title").Content("title", XmlEscape("<&>\"' \x01"));
    const PlotArea area{40, 20, 300, 200, {-3, 7.5}, {-1e-3, 2e-3}};
    svg.Group("class=\"panel\" id=\"" + XmlEscape("a\"b", true) + "\"");
    svg.Axes(area, "x <unit>", "y & 'z'");
    svg.Series(area, std::vector<double>{-3, 0, 1, 7.5}, std::vector<double>{0, kNaN, 1e-3, 2e-3},
               "class=\"s\"");
    svg.Marker(area.X(0), area.Y(0), 1.2);
    const std::vector<LegendEntry> entries = {{LegendKey::kLine, "stroke=\"red\"", "a &amp; b"},
                                              {LegendKey::kSquare, "fill=\"blue\"", "&#952;1"}};
    svg.Legend(40, 10, entries);
    svg.EndGroup();
    return svg.Finish();
  };
  const std::string svg = document();
  EXPECT_EQ(MarkupProblem(svg), "") << svg;
  EXPECT_EQ(svg, document());
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
  // The checker itself finds what it should.
  EXPECT_NE(MarkupProblem("<svg><g></svg>"), "");
  EXPECT_NE(MarkupProblem("<svg><text>a < b</text></svg>"), "");
  EXPECT_NE(MarkupProblem("<svg>a & b</svg>"), "");
  EXPECT_NE(MarkupProblem("<svg/><svg/>"), "");
  EXPECT_EQ(MarkupProblem("<svg>\n<g a=\"x>y\">&lt;</g>\n</svg>\n"), "");
}

}  // namespace
}  // namespace hybrid::plotting
