// Tests of `hybrid simulate --plot` (commands/trajectory_plot.h) on runs whose shape is known by
// hand: a clock rising at rate 1 (its polyline's points lie on one straight line), a two-mode
// automaton jumping at known times (one dashed line per jump, one named mode band per stay),
// inputs drawn as panels, the panel cap, determinism; the bouncing ball drawn from a run with
// PlotOptions follows the analytic parabolas between its first bounces; jump labels never overlap
// (their boxes computed from the SVG's positions, rotations and texts); the mode strip has a row
// per component, names where they fit and a legend for the others.

#include "commands/trajectory_plot.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "tests/test_utilities/svg_scan.h"
#include "tests/test_utilities/text_count.h"

namespace hybrid::cli {
namespace {

using testing::Count;

// x' = 1 from 0; a jump a -> b at x = 1 and b -> a at x = 2 (reset x := 0 there): over 2.5 time
// units the modes are a [0, 1], b [1, 2], a [2, 2.5]: two jumps, three stays.
constexpr const char* kTwoModes = R"(
automaton two {
  var x [s];
  input u in [0, 5];
  mode a { x' = 1; }
  mode b { x' = 1; }
  transition go: a -> b { guard x >= 1; }
  transition back: b -> a { guard x >= 2; reset x := 0; }
  init a { x = 0; }
}
)";

TEST(TrajectoryPlot, DrawsPanelsJumpsAndModes) {
  const System system = ParseModel(kTwoModes, "two.ha");
  const Simulator sim(system);
  SimulationOptions options;
  options.until = 2.5;
  options.sample_step = 0.5;
  InputSignal u;
  u.slot = *system.symbols().Find("u");
  u.points = {{0.0, 1.0}, {1.5, 4.0}};
  const std::vector<InputSignal> signals = {u};
  const SimulationResult r = sim.Run(options, signals);
  ASSERT_EQ(r.events.size(), 2u);
  const std::string svg = TrajectoryPlotSvg(sim, r, signals, "two");
  EXPECT_EQ(svg, TrajectoryPlotSvg(sim, r, signals, "two"));  // deterministic
  EXPECT_NE(svg.find("two (completed)"), std::string::npos);
  EXPECT_NE(svg.find(">x (s)<"), std::string::npos) << "the unit on the axis";
  EXPECT_NE(svg.find(">input u<"), std::string::npos);
  EXPECT_EQ(Count(svg, "stroke-width=\"1.4\""), 2) << "one series per variable and input";
  EXPECT_NE(svg.find(">go<"), std::string::npos);
  EXPECT_NE(svg.find(">back<"), std::string::npos);
  const std::string jumps = svg.substr(svg.find("class=\"jumps\""));
  EXPECT_EQ(Count(jumps.substr(0, jumps.find("</g>")), "<line"), 2);
  const std::string modes = svg.substr(svg.find("class=\"modes\""));
  const std::string strip = modes.substr(0, modes.find("</g>"));
  EXPECT_EQ(Count(strip, "<rect"), 3);
  // Each band named, with its stay's times in its tooltip.
  EXPECT_EQ(Count(strip, ">a</text>"), 2) << strip;
  EXPECT_EQ(Count(strip, ">b</text>"), 1) << strip;
  EXPECT_NE(strip.find("<title>a: t = 0 to 1</title>"), std::string::npos) << strip;
  EXPECT_NE(strip.find("<title>b: t = 1 to 2</title>"), std::string::npos) << strip;
  EXPECT_NE(strip.find("<title>a: t = 2 to 2.5</title>"), std::string::npos) << strip;
  EXPECT_EQ(svg.find("class=\"mode-legend\""), std::string::npos) << "every name fits";
  // x = t on [0, 1]: the first points of the first polyline are on one straight line.
  const std::vector<std::string> polylines = testing::AttributeValues(svg, "points");
  ASSERT_FALSE(polylines.empty());
  std::vector<double> xs, ys;
  for (const auto& [x, y] : testing::PointPairs(polylines.front())) {
    if (xs.size() == 3) break;
    xs.push_back(x);
    ys.push_back(y);
  }
  ASSERT_EQ(xs.size(), 3u);
  EXPECT_NEAR((ys[1] - ys[0]) * (xs[2] - xs[0]), (ys[2] - ys[0]) * (xs[1] - xs[0]), 0.5);
}

TEST(TrajectoryPlot, DrawsAtMostTwelvePanels) {
  std::string text = "automaton many {\n";
  for (int i = 0; i < 14; ++i) text += "  var v" + std::to_string(i) + ";\n";
  text += "  mode m {}\n  init m {";
  for (int i = 0; i < 14; ++i) text += " v" + std::to_string(i) + " = " + std::to_string(i) + ";";
  text += " }\n}\n";
  const System system = ParseModel(text, "many.ha");
  const Simulator sim(system);
  SimulationOptions options;
  options.until = 1.0;
  const SimulationResult r = sim.Run(options);
  const std::string svg = TrajectoryPlotSvg(sim, r, {}, "many");
  EXPECT_EQ(Count(svg, "stroke-width=\"1.4\""), kMaxPlotPanels);
  EXPECT_NE(svg.find("2 more variables or inputs not drawn"), std::string::npos);
}

}  // namespace
}  // namespace hybrid::cli

namespace hybrid::cli {
namespace {

using testing::Count;

// The points of the `index`-th polyline of `svg`, in pixels.
std::vector<std::array<double, 2>> PolylinePoints(const std::string& svg, int index) {
  const std::vector<std::string> polylines = testing::AttributeValues(svg, "points");
  if (index >= static_cast<int>(polylines.size())) return {};
  return testing::PointPairs(polylines[index]);
}

System BouncingBall() {
  System ball = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/bouncing_ball.ha");
  ball.SetParameter("g", 9.81);
  ball.SetParameter("e", 0.8);
  ball.SetParameter("h0", 10);
  return ball;
}

// The ball drawn without samples of its own (the plot's run, PlotOptions) follows the free fall
// h = h0 - g t^2 / 2 up to the first impact t1 = sqrt(2 h0 / g), then the rise and fall
// h = v1 (t - t1) - g (t - t1)^2 / 2, v1 = e g t1, up to t2 = t1 + 2 v1 / g: facts of mechanics,
// not of the simulator. The polyline's pixels are mapped back to (t, h) by its own end points:
// the first is (0, h0), the last is at the horizon, the lowest is h = 0.
TEST(TrajectoryPlot, BallWithoutSamplesFollowsTheParabolas) {
  constexpr double g = 9.81, e = 0.8, h0 = 10, until = 20;
  const System ball = BouncingBall();
  const Simulator sim(ball);
  SimulationOptions options;
  options.until = until;
  const SimulationOptions plotted = PlotOptions(options, until);
  EXPECT_DOUBLE_EQ(plotted.sample_step, until / kPlotSamples);
  const SimulationResult r = sim.Run(plotted);
  ASSERT_EQ(r.status, SimulationStatus::kCompleted);
  const auto h = PolylinePoints(TrajectoryPlotSvg(sim, r, {}, "ball"), 0);
  ASSERT_GT(h.size(), static_cast<size_t>(kPlotSamples));
  double floor_y = h.front()[1];
  for (const auto& p : h) floor_y = std::max(floor_y, p[1]);
  const double x0 = h.front()[0], x1 = h.back()[0], top_y = h.front()[1];
  const double t1 = std::sqrt(2 * h0 / g), v1 = e * g * t1, t2 = t1 + 2 * v1 / g;
  int falling = 0, rising = 0;
  for (const auto& p : h) {
    const double t = (p[0] - x0) / (x1 - x0) * until;
    const double height = (floor_y - p[1]) / (floor_y - top_y) * h0;
    if (t < t1) {
      EXPECT_NEAR(height, h0 - g * t * t / 2, 0.01) << "t = " << t;
      ++falling;
    } else if (t > t1 + 1e-3 && t < t2 - 1e-3) {
      EXPECT_NEAR(height, v1 * (t - t1) - g * (t - t1) * (t - t1) / 2, 0.01) << "t = " << t;
      ++rising;
    }
  }
  // About kPlotSamples * t / until points on each arc, not just its ends.
  EXPECT_GE(falling, 30);
  EXPECT_GE(rising, 50);
  // A run of its own samples is plotted as it is.
  options.sample_step = 0.5;
  EXPECT_EQ(PlotOptions(options, until).sample_step, 0.5);
}

// A jump label as drawn: its text's box, from the SVG's anchor, rotation and text, with a
// sans-serif font's extent at most 0.6 em per character, 0.8 em above the baseline and 0.25 em
// below it.
using Corners = std::array<std::array<double, 2>, 4>;

std::vector<Corners> JumpLabelBoxes(const std::string& svg, double font) {
  const std::string group = svg.substr(svg.find("class=\"jump-labels\""));
  const std::string labels = group.substr(0, group.find("</g>"));
  const std::regex text(
      "<text transform=\"rotate\\(([-0-9.]+) ([-0-9.]+) ([-0-9.]+)\\)\" x=\"([-0-9.]+)\" "
      "y=\"([-0-9.]+)\">([^<]*)</text>");
  std::vector<Corners> boxes;
  for (auto it = std::sregex_iterator(labels.begin(), labels.end(), text);
       it != std::sregex_iterator(); ++it) {
    const double angle = std::stod((*it)[1]) * std::numbers::pi / 180;
    const double x = std::stod((*it)[4]), y = std::stod((*it)[5]);
    const double length = 0.6 * font * static_cast<double>((*it)[6].length());
    const double c = std::cos(angle), s = std::sin(angle);
    Corners box;
    int k = 0;
    // Text frame (along, down) to the page: along (c, s), down (-s, c).
    for (const double along : {0.0, length}) {
      for (const double down : {-0.8 * font, 0.25 * font}) {
        box[static_cast<size_t>(k++)] = {x + along * c - down * s, y + along * s + down * c};
      }
    }
    std::swap(box[2], box[3]);  // in order around the rectangle
    boxes.push_back(box);
  }
  return boxes;
}

// Whether two convex quadrilaterals overlap: no edge normal of either separates them.
bool Intersect(const Corners& a, const Corners& b) {
  for (const Corners* poly : {&a, &b}) {
    for (size_t i = 0; i < 4; ++i) {
      const auto& p = (*poly)[i];
      const auto& q = (*poly)[(i + 1) % 4];
      const double nx = q[1] - p[1], ny = p[0] - q[0];
      double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
      for (const auto& v : a) {
        a_lo = std::min(a_lo, nx * v[0] + ny * v[1]);
        a_hi = std::max(a_hi, nx * v[0] + ny * v[1]);
      }
      for (const auto& v : b) {
        b_lo = std::min(b_lo, nx * v[0] + ny * v[1]);
        b_hi = std::max(b_hi, nx * v[0] + ny * v[1]);
      }
      if (a_hi <= b_lo || b_hi <= a_lo) return false;
    }
  }
  return true;
}

// Checks that the jump labels of `svg` (with `events` jumps) overlap neither each other nor the
// title (their tops below y = 22) and stay inside the figure's width; returns how many there are.
size_t CheckJumpLabels(const std::string& svg, size_t events) {
  const std::vector<Corners> boxes = JumpLabelBoxes(svg, 9);
  for (size_t i = 0; i < boxes.size(); ++i) {
    for (const auto& corner : boxes[i]) {
      EXPECT_GE(corner[1], 22) << "label " << i << " reaches the title";
      EXPECT_LE(corner[0], 760) << "label " << i << " leaves the figure";
    }
    for (size_t j = i + 1; j < boxes.size(); ++j) {
      EXPECT_FALSE(Intersect(boxes[i], boxes[j])) << "labels " << i << " and " << j;
    }
  }
  EXPECT_EQ(Count(svg, "<text transform=\"rotate(-35"), static_cast<int>(boxes.size()));
  if (boxes.size() < events) {
    EXPECT_NE(
        svg.find(std::to_string(events) + " jumps, " + std::to_string(boxes.size()) + " labelled"),
        std::string::npos);
  } else {
    EXPECT_EQ(svg.find("class=\"jump-count\""), std::string::npos);
  }
  return boxes.size();
}

TEST(TrajectoryPlot, JumpLabelsDoNotOverlap) {
  // The ball's bounces crowd towards t = 12.8 (34 jumps); the finger behind its controller
  // jumps twice within 0.15 s with long transition names.
  const System ball = BouncingBall();
  const Simulator ball_sim(ball);
  SimulationOptions options;
  options.until = 20;
  const SimulationResult bounces = ball_sim.Run(options);
  ASSERT_EQ(bounces.events.size(), 34u);
  const size_t labelled = CheckJumpLabels(TrajectoryPlotSvg(ball_sim, bounces, {}, "ball"), 34);
  EXPECT_GE(labelled, 5u);
  EXPECT_LT(labelled, 34u);
  const System finger =
      ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/controlled_finger.ha");
  const Simulator finger_sim(finger);
  const SimulationResult run = finger_sim.Run({});
  ASSERT_GE(run.events.size(), 5u);
  EXPECT_GE(CheckJumpLabels(TrajectoryPlotSvg(finger_sim, run, {}, "finger"), run.events.size()),
            4u);
}

// Two components: a lamp whose first mode has a long name and lasts 0.05 of 2 time units (a
// band 16 pixels wide), and a clock in one mode.
constexpr const char* kLampAndClock = R"(
automaton lamp {
  var t;
  mode warming_up_before_switching_on { t' = 1; }
  mode on { t' = 1; }
  transition warming_up_before_switching_on -> on { guard t >= 0.05; }
  init warming_up_before_switching_on { t = 0; }
}
automaton clock {
  var c;
  mode run { c' = 1; }
  init run { c = 0; }
}
system both {
  instance L = lamp;
  instance C = clock;
}
)";

TEST(TrajectoryPlot, ModeStripHasARowPerComponentAndALegend) {
  const System system = ParseModel(kLampAndClock, "both.ha");
  const Simulator sim(system);
  SimulationOptions options;
  options.until = 2;
  const SimulationResult r = sim.Run(options);
  ASSERT_EQ(r.events.size(), 1u);
  const std::string svg = TrajectoryPlotSvg(sim, r, {}, "both");
  const std::string modes = svg.substr(svg.find("class=\"modes\""));
  const std::string strip = modes.substr(0, modes.find("</g>"));
  EXPECT_EQ(Count(strip, "<rect"), 3) << "two stays of L, one of C";
  EXPECT_NE(strip.find(">L</text>"), std::string::npos) << "rows titled by instance";
  EXPECT_NE(strip.find(">C</text>"), std::string::npos);
  EXPECT_NE(strip.find(">on</text>"), std::string::npos);
  EXPECT_NE(strip.find(">run</text>"), std::string::npos);
  EXPECT_EQ(strip.find(">warming_up_before_switching_on</text>"), std::string::npos)
      << "too long for its band";
  EXPECT_NE(strip.find("<title>warming_up_before_switching_on: t = 0 to 0.05</title>"),
            std::string::npos);
  const std::string legend = svg.substr(svg.find("class=\"mode-legend\""));
  EXPECT_NE(legend.substr(0, legend.find("</g>")).find(">L: warming_up_before_switching_on<"),
            std::string::npos);
  EXPECT_EQ(legend.find(">L: on<"), std::string::npos) << "named in the strip already";
}

}  // namespace
}  // namespace hybrid::cli
