// SVG figures of the finger and the hand: the drawings in small multiples and the joint angles
// against g.
#include "hybrid/gripper/svg_figures.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/test_utilities/svg_scan.h"
#include "tests/test_utilities/text_count.h"

namespace hybrid::gripper {
namespace {

using testing::Count;

// The basic shape of a standalone document: one root, balanced groups, nothing non-finite.
void ExpectWellShaped(const std::string& svg) {
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  ASSERT_GE(svg.size(), 7u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(Count(svg, "<svg"), 1);
  EXPECT_EQ(Count(svg, "</svg>"), 1);
  EXPECT_EQ(Count(svg, "<g ") + Count(svg, "<g>"), Count(svg, "</g>"));
  EXPECT_EQ(Count(svg, "<text"), Count(svg, "</text>"));
  EXPECT_EQ(Count(svg, "<title>"), 1);
  EXPECT_EQ(Count(svg, "</title>"), 1);
  EXPECT_FALSE(
      std::regex_search(svg, std::regex("(^|[^a-z])(nan|inf)([^a-z]|$)", std::regex::icase)))
      << "non-finite number in the output";
}

std::vector<std::pair<double, FingerConfiguration>> Frames(const FingerClosedForm& closed_form,
                                                           const std::vector<double>& gs) {
  std::vector<std::pair<double, FingerConfiguration>> frames;
  for (double g : gs) frames.emplace_back(g, closed_form.At(g));
  return frames;
}

struct PixelLine {
  double x1, y1, x2, y2;
};

// The <line> elements whose attributes start with `prefix` (e.g. `class="link l1"`).
std::vector<PixelLine> Lines(const std::string& svg, const std::string& prefix) {
  std::vector<PixelLine> lines;
  const std::regex pattern("<line " + prefix +
                           "[^>]* x1=\"([-0-9.]+)\" y1=\"([-0-9.]+)\" x2=\"([-0-9.]+)\" "
                           "y2=\"([-0-9.]+)\"/>");
  for (std::sregex_iterator it(svg.begin(), svg.end(), pattern), end; it != end; ++it) {
    lines.push_back(
        {std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4])});
  }
  return lines;
}

// The points of the <polyline class="NAME" ...> element.
std::vector<std::array<double, 2>> Polyline(const std::string& svg, const std::string& name) {
  const std::size_t start = svg.find("<polyline class=\"" + name + "\"");
  if (start == std::string::npos) return {};
  const std::size_t end = svg.find("/>", start);
  if (end == std::string::npos) return {};
  const auto points = testing::AttributeValues(svg.substr(start, end - start), "points");
  return points.empty() ? std::vector<std::array<double, 2>>{} : testing::PointPairs(points[0]);
}

// The pixel row of the horizontal gridline at `theta` degrees, the column of the one at `g`.
double GridY(const std::string& svg, const std::string& theta) {
  const auto lines = Lines(svg, "class=\"grid\" data-theta=\"" + theta + "\"");
  EXPECT_EQ(lines.size(), 1u) << theta;
  return lines.empty() ? NAN : lines[0].y1;
}
double GridX(const std::string& svg, const std::string& g) {
  const auto lines = Lines(svg, "class=\"grid\" data-g=\"" + g + "\"");
  EXPECT_EQ(lines.size(), 1u) << g;
  return lines.empty() ? NAN : lines[0].x1;
}

// The basic hand closing on one cylinder (spread angle 1.27 degrees), built once.
const Hand& CylinderHand() {
  static const Hand hand({Obstacle::Circle({0.0, 0.06}, 0.02)},
                         Hand::SpreadPosition(SpreadMode::kBasic), {255, 255, 255});
  return hand;
}

std::vector<HandFrame> HandFrames(const Hand& hand, const std::vector<double>& gs) {
  std::vector<HandFrame> frames;
  for (double g : gs) frames.push_back({g, {hand.At(0, g), hand.At(1, g), hand.At(2, g)}});
  return frames;
}

// The contents of every <g class="finger <name>"> group, concatenated (side views and views
// from above).
std::string FingerGroups(const std::string& svg, const std::string& name) {
  std::string out;
  const std::regex pattern("<g class=\"finger " + name + "\"[^>]*>([^<]*(<line[^>]*>[^<]*)*)</g>");
  for (std::sregex_iterator it(svg.begin(), svg.end(), pattern), end; it != end; ++it) {
    out += (*it)[1];
  }
  return out;
}

TEST(FingerDrawingSvgTest, OnePanelPerFrameWithThreeLinksAndTheirJoints) {
  const FingerClosedForm closed_form;
  const FingerGeometry geometry;
  const std::vector<Obstacle> objects = {Obstacle::Circle({0.06, 0.09}, 0.01),
                                         Obstacle::Bar({0.08, 0.0}, {0.1, 0.04}, 0.004)};
  const auto frames = Frames(closed_form, {0, 30, 70, 110, 150});
  const std::string svg = FingerDrawingSvg(geometry, objects, frames);
  ExpectWellShaped(svg);
  EXPECT_EQ(Count(svg, "<g class=\"panel\""), 5);
  EXPECT_EQ(Lines(svg, "class=\"link ").size(), 3u * frames.size());
  EXPECT_EQ(Count(svg, "<circle class=\"joint\""), 15);
  EXPECT_EQ(Count(svg, "<rect class=\"palm\""), 5);
  EXPECT_EQ(Count(svg, "<circle class=\"object\""), 5);
  EXPECT_EQ(Lines(svg, "class=\"object\"").size(), 5u);
  EXPECT_NE(svg.find(">g = 0, phase 1</text>"), std::string::npos);
  EXPECT_NE(svg.find(">g = 110, phase 1</text>"), std::string::npos);  // breakpoint: phase 1
  EXPECT_NE(svg.find(">g = 150, phase 2'</text>"), std::string::npos);
  EXPECT_NE(svg.find("<title>Finger configurations at g = 0, 30, 70, 110, 150</title>"),
            std::string::npos);
  EXPECT_EQ(svg, FingerDrawingSvg(geometry, objects, frames));  // deterministic
}

TEST(FingerDrawingSvgTest, SameScaleEverywhereUpIsUpAtMostFourPanelsPerRow) {
  const FingerClosedForm closed_form;
  const FingerGeometry geometry;
  const std::string svg =
      FingerDrawingSvg(geometry, {}, Frames(closed_form, {0, 30, 70, 110, 150, 200, 255}));
  // Link 1 has the same length in pixels in every panel.
  const auto link1 = Lines(svg, "class=\"link l1\"");
  ASSERT_EQ(link1.size(), 7u);
  const auto length = [](const PixelLine& l) { return std::hypot(l.x2 - l.x1, l.y2 - l.y1); };
  for (const PixelLine& l : link1) EXPECT_NEAR(length(l), length(link1[0]), 0.02);
  // The open finger points up the page (smaller pixel y) and closes to the right.
  EXPECT_NEAR(link1[0].x2, link1[0].x1, 0.01);
  EXPECT_LT(link1[0].y2, link1[0].y1);
  EXPECT_GT(link1[1].x2, link1[1].x1);
  // Seven panels: four columns, two rows.
  std::set<std::string> xs, ys;
  const std::regex translate("<g class=\"panel\" transform=\"translate\\(([-0-9.]+),([-0-9.]+)\\)");
  for (std::sregex_iterator it(svg.begin(), svg.end(), translate), end; it != end; ++it) {
    xs.insert((*it)[1]);
    ys.insert((*it)[2]);
  }
  EXPECT_EQ(xs.size(), 4u);
  EXPECT_EQ(ys.size(), 2u);
  ExpectWellShaped(svg);
}

TEST(FingerDrawingSvgTest, RejectsNoFramesAndNonFiniteValues) {
  const FingerGeometry geometry;
  try {
    FingerDrawingSvg(geometry, {}, {});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("finger drawing: ", 0), 0u) << e.what();
  }
  FingerConfiguration bad;
  bad.theta[1] = NAN;
  EXPECT_THROW(FingerDrawingSvg(geometry, {}, {{10.0, bad}}), std::invalid_argument);
  EXPECT_THROW(FingerDrawingSvg(geometry, {}, {{INFINITY, FingerConfiguration()}}),
               std::invalid_argument);
}

TEST(AnglePlotSvgTest, FreeSpaceCurvesAxesAndStop) {
  const std::string svg = AnglePlotSvg(FingerClosedForm(), "Free space");
  ExpectWellShaped(svg);
  // Every multiple of 0.5 in [0, 255]; the breakpoints 110, 140 and 240 are among them.
  for (const std::string name : {"theta1", "theta2", "theta3"}) {
    EXPECT_EQ(Polyline(svg, name).size(), 511u) << name;
  }
  const double x0 = GridX(svg, "0"), x250 = GridX(svg, "250");
  const auto x_of = [&](double g) { return x0 + g / 250.0 * (x250 - x0); };
  const double y60 = GridY(svg, "60"), y80 = GridY(svg, "80");
  const auto y_of = [&](double theta) { return y60 + (theta - 60.0) / 20.0 * (y80 - y60); };
  // Ticks every 50 counts and every 20 degrees over [-60, 100].
  EXPECT_EQ(Lines(svg, "class=\"grid\" data-g=").size(), 6u);
  EXPECT_EQ(Lines(svg, "class=\"grid\" data-theta=").size(), 9u);
  EXPECT_NEAR(GridY(svg, "-60"), y_of(-60), 0.02);
  EXPECT_NEAR(GridY(svg, "100"), y_of(100), 0.02);
  // theta1 rises from 0 to its limit, 70 degrees, and stays there.
  const auto theta1 = Polyline(svg, "theta1");
  ASSERT_FALSE(theta1.empty());
  EXPECT_NEAR(theta1.front()[0], x_of(0), 0.02);
  EXPECT_NEAR(theta1.front()[1], y_of(0), 0.02);
  EXPECT_NEAR(theta1.back()[0], x_of(255), 0.02);
  EXPECT_NEAR(theta1.back()[1], y_of(70), 0.02);
  // theta3 reaches -55 at g = 110 (a sample, since 110 is a multiple of 0.5).
  const auto theta3 = Polyline(svg, "theta3");
  ASSERT_EQ(theta3.size(), 511u);
  EXPECT_NEAR(theta3[220][0], x_of(110), 0.02);
  EXPECT_NEAR(theta3[220][1], y_of(-55), 0.02);
  // The motor stops at 240 (decision D3).
  const auto stop = Lines(svg, "class=\"stop\"");
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_NEAR(stop[0].x1, x_of(240), 0.02);
  EXPECT_NE(svg.find(">motor stops (g = 240)</text>"), std::string::npos);
  EXPECT_EQ(Count(svg, "<polyline"), 3);
}

// Measured runs over the curves (figures 5.2 and 5.4): one dot per present sample in range and
// joint, at its g and angle; the y range widens for an angle below -60; g_ob is marked.
TEST(AnglePlotSvgTest, MeasuredRunsAreDotsAndTheContactIsMarked) {
  FingerContacts contacts;
  contacts.gob[0] = 80.0;
  MeasuredSeries run;
  run.g = {0, 100, 200, 300};  // 300 lies outside the range: left out
  run.theta = {std::vector<double>{0, 40, 40, 40}, std::vector<double>{0, 18, NAN, 90},
               std::vector<double>{0, -70, 10, 0}};
  const std::string svg = AnglePlotSvg(FingerClosedForm(contacts), "gob1 = 80", {run});
  ExpectWellShaped(svg);
  EXPECT_EQ(Count(svg, "<circle"), 3 + 2 + 3);
  EXPECT_NE(svg.find(">dots: measured</text>"), std::string::npos);
  EXPECT_NE(svg.find(">(1 run)</text>"), std::string::npos);
  EXPECT_EQ(Lines(svg, "class=\"grid\" data-theta=\"-80\"").size(), 1u);  // widened for -70
  const auto gob = Lines(svg, "class=\"gob\"");
  ASSERT_EQ(gob.size(), 1u);
  const double x0 = GridX(svg, "0"), x250 = GridX(svg, "250");
  EXPECT_NEAR(gob[0].x1, x0 + 80.0 / 250.0 * (x250 - x0), 0.02);
  EXPECT_NE(svg.find(">g_ob link 1 = 80</text>"), std::string::npos);
  // Without measured runs: no dots.
  EXPECT_EQ(Count(AnglePlotSvg(FingerClosedForm(contacts), "t"), "<circle"), 0);
}

TEST(AnglePlotSvgTest, BreakpointsOffTheGridAreSampledSoCornersAreExact) {
  // Link 1 blocked at 123.3: phase 2' to 223.3, phase 3 until theta3_max at 239.15.
  FingerContacts contacts;
  contacts.gob[0] = 123.3;
  const FingerClosedForm closed_form(contacts);
  const std::string svg = AnglePlotSvg(closed_form, "Link 1 blocked");
  ExpectWellShaped(svg);
  const auto theta2 = Polyline(svg, "theta2");
  EXPECT_EQ(theta2.size(), 511u + 3u);
  EXPECT_EQ(Polyline(svg, "theta1").size(), theta2.size());
  EXPECT_EQ(Polyline(svg, "theta3").size(), theta2.size());
  for (size_t i = 1; i < theta2.size(); ++i) EXPECT_GT(theta2[i][0], theta2[i - 1][0]) << i;
  // The corner of theta2 at 123.3 is a vertex: theta2 is still 0 there.
  const double x0 = GridX(svg, "0"), x250 = GridX(svg, "250"), y0 = GridY(svg, "0");
  const double corner = x0 + 123.3 / 250.0 * (x250 - x0);
  bool found = false;
  for (const auto& p : theta2) found = found || (std::abs(p[0] - corner) < 0.006 && p[1] == y0);
  EXPECT_TRUE(found);
  EXPECT_NE(svg.find(">motor stops (g = 239.15)</text>"), std::string::npos);
}

TEST(AnglePlotSvgTest, NoStopLineWhileStillMovingAndTitleIsEscaped) {
  FingerParameters parameters;
  parameters.motor_max = 200.0;  // link 2 would reach its limit only at 240
  const FingerClosedForm closed_form({}, parameters);
  ASSERT_FALSE(std::isfinite(closed_form.stop()));
  const std::string svg = AnglePlotSvg(closed_form, "a < b & \"c\"");
  ExpectWellShaped(svg);
  EXPECT_EQ(Count(svg, "class=\"stop\""), 0);
  EXPECT_EQ(Polyline(svg, "theta1").size(), 401u);
  EXPECT_EQ(Lines(svg, "class=\"grid\" data-g=").size(), 5u);  // 0, 50, ..., 200
  EXPECT_NE(svg.find("<title>a &lt; b &amp; \"c\"</title>"), std::string::npos);
}

TEST(HandDrawingSvgTest, OnePanelPerFrameNineLinksEachAndCaptions) {
  const Hand& hand = CylinderHand();
  const auto frames = HandFrames(hand, {0, 80, 160, 255});
  const std::string svg = HandDrawingSvg(hand, frames);
  ExpectWellShaped(svg);
  EXPECT_EQ(Count(svg, "<g class=\"panel\""), 4);
  // Side view: 3 fingers x 3 links per frame, three joints per finger; the same from above.
  EXPECT_EQ(Lines(svg, "class=\"link ").size(), 9u * frames.size());
  EXPECT_EQ(Lines(svg, "class=\"top ").size(), 9u * frames.size());
  EXPECT_EQ(Count(svg, "<circle class=\"joint\""), 36);
  for (const std::string name : {"A", "B", "C"}) {
    const std::string group = FingerGroups(svg, name);
    EXPECT_EQ(Count(svg, "<g class=\"finger " + name + "\""), 8) << name;  // side and above
    for (const std::string link : {"l1", "l2", "l3"}) {
      EXPECT_EQ(Lines(group, "class=\"link " + link + "\"").size(), 4u) << name << link;
      EXPECT_EQ(Lines(group, "class=\"top " + link + "\"").size(), 4u) << name << link;
    }
    EXPECT_NE(svg.find(">finger " + name + "</text>"), std::string::npos) << name;  // legend
  }
  EXPECT_EQ(Count(svg, "<g class=\"top-view\""), 4);
  EXPECT_EQ(Count(svg, "<rect class=\"palm\""), 8);
  EXPECT_EQ(Count(svg, "<circle class=\"object\""), 4);  // side views
  EXPECT_EQ(Count(svg, "<rect class=\"object\""), 4);    // the cylinder's band from above
  for (const std::string g : {"0", "80", "160", "255"}) {
    EXPECT_EQ(Count(svg, ">g = " + g + "</text>"), 1) << g;
  }
  EXPECT_NE(svg.find(">phases A 1, B 1, C 1</text>"), std::string::npos);
  EXPECT_NE(svg.find("<title>Hand configurations at g = 0, 80, 160, 255 (spread angle 1.27 "
                     "deg)</title>"),
            std::string::npos);
  EXPECT_NE(svg.find(">Hand configurations (spread angle 1.27 deg)</text>"), std::string::npos);
  EXPECT_EQ(svg, HandDrawingSvg(hand, frames));  // deterministic
}

TEST(HandDrawingSvgTest, SideViewFromAboveAndPanelLayout) {
  const Hand& hand = CylinderHand();
  const std::string svg = HandDrawingSvg(hand, HandFrames(hand, {0, 40, 80, 120, 160}));
  ExpectWellShaped(svg);
  const std::string a = FingerGroups(svg, "A"), b = FingerGroups(svg, "B"),
                    c = FingerGroups(svg, "C");
  // Side view: link 1 of A has the same length in pixels in every panel; open, it points up the
  // page. A stands left of B and C, which coincide (basic spread: symmetric).
  const auto a1 = Lines(a, "class=\"link l1\""), b1 = Lines(b, "class=\"link l1\""),
             c1 = Lines(c, "class=\"link l1\"");
  ASSERT_EQ(a1.size(), 5u);
  ASSERT_EQ(b1.size(), 5u);
  ASSERT_EQ(c1.size(), 5u);
  const auto length = [](const PixelLine& l) { return std::hypot(l.x2 - l.x1, l.y2 - l.y1); };
  for (const PixelLine& l : a1) EXPECT_NEAR(length(l), length(a1[0]), 0.02);
  EXPECT_NEAR(a1[0].x2, a1[0].x1, 0.01);
  EXPECT_LT(a1[0].y2, a1[0].y1);
  EXPECT_LT(a1[0].x1, b1[0].x1);
  EXPECT_GT(a1[1].x2, a1[1].x1);  // A closes to the right, B to the left
  EXPECT_LT(b1[1].x2, b1[1].x1);
  for (size_t i = 0; i < b1.size(); ++i) {
    EXPECT_NEAR(c1[i].x1, b1[i].x1, 0.01);
    EXPECT_NEAR(c1[i].y2, b1[i].y2, 0.01);
  }
  // From above (z down the page): C at -z above A (z = 0) above B at +z.
  const auto a_top = Lines(a, "class=\"top l1\""), b_top = Lines(b, "class=\"top l1\""),
             c_top = Lines(c, "class=\"top l1\"");
  ASSERT_EQ(a_top.size(), 5u);
  ASSERT_EQ(b_top.size(), 5u);
  ASSERT_EQ(c_top.size(), 5u);
  EXPECT_LT(c_top[0].y1, a_top[0].y1);
  EXPECT_LT(a_top[0].y1, b_top[0].y1);
  EXPECT_NEAR(a_top[0].x1, a1[0].x1, 0.01);  // the views share their x axis
  // The palm spans the finger bases.
  std::smatch palm;
  ASSERT_TRUE(std::regex_search(
      svg, palm,
      std::regex("<rect class=\"palm\" x=\"([-0-9.]+)\" y=\"[-0-9.]+\" width=\"([-0-9.]+)\"")));
  EXPECT_LT(std::stod(palm[1]), a1[0].x1);
  EXPECT_GT(std::stod(palm[1]) + std::stod(palm[2]), b1[0].x1);
  // Five panels: four columns, two rows.
  std::set<std::string> xs, ys;
  const std::regex translate("<g class=\"panel\" transform=\"translate\\(([-0-9.]+),([-0-9.]+)\\)");
  for (std::sregex_iterator it(svg.begin(), svg.end(), translate), end; it != end; ++it) {
    xs.insert((*it)[1]);
    ys.insert((*it)[2]);
  }
  EXPECT_EQ(xs.size(), 4u);
  EXPECT_EQ(ys.size(), 2u);
}

TEST(HandDrawingSvgTest, RejectsNoFramesAndNonFiniteValues) {
  const Hand& hand = CylinderHand();
  try {
    HandDrawingSvg(hand, {});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("hand drawing: ", 0), 0u) << e.what();
  }
  auto frames = HandFrames(hand, {0, 100});
  frames[1].fingers[2].theta[0] = NAN;
  EXPECT_THROW(HandDrawingSvg(hand, frames), std::invalid_argument);
  frames = HandFrames(hand, {0, 100});
  frames[0].g = INFINITY;
  EXPECT_THROW(HandDrawingSvg(hand, frames), std::invalid_argument);
}

// Every kind of figure is well-formed XML with an <svg> root, as python3's xml.etree parses it
// (one python3 run for all of them, to keep the test fast; skipped without python3).
TEST(SvgFiguresTest, FiguresParseAsXml) {
  FingerContacts contacts;
  contacts.gob[0] = 123.3;
  const FingerClosedForm free, blocked(contacts);
  const std::vector<std::string> figures = {
      FingerDrawingSvg(
          FingerGeometry(),
          {Obstacle::Circle({0.06, 0.09}, 0.01), Obstacle::Bar({0.08, 0.0}, {0.1, 0.04}, 0.004)},
          Frames(free, {0, 30, 70, 110, 150})),
      AnglePlotSvg(free, "Free space"), AnglePlotSvg(blocked, "Link 1 blocked"),
      AnglePlotSvg(free, "a < b & \"c\" 'd' \x01"),
      HandDrawingSvg(CylinderHand(), HandFrames(CylinderHand(), {0, 80, 160, 255}))};
  std::string command =
      "python3 -c \"import sys, xml.etree.ElementTree as E\n"
      "for path in sys.argv[1:]:\n"
      "  root = E.parse(path).getroot()\n"
      "  assert root.tag == '{http://www.w3.org/2000/svg}svg', root.tag\n"
      "print(len(sys.argv) - 1)\"";
  std::vector<std::filesystem::path> paths;
  for (size_t i = 0; i < figures.size(); ++i) {
    paths.push_back(
        std::filesystem::temp_directory_path() /
        ("svg_figures_test_" + std::to_string(getpid()) + "_" + std::to_string(i) + ".svg"));
    std::ofstream(paths.back()) << figures[i];
    command += " '" + paths.back().string() + "'";
  }
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  for (const auto& path : paths) std::filesystem::remove(path);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) GTEST_SKIP() << "no python3: " << output;
  EXPECT_EQ(status, 0) << output;
  EXPECT_EQ(output, std::to_string(figures.size()) + "\n");
}

}  // namespace
}  // namespace hybrid::gripper
