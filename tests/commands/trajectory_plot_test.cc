// Tests of `hybrid simulate --plot` (commands/trajectory_plot.h) on runs whose shape is known by
// hand: a clock rising at rate 1 (its polyline's points lie on one straight line), a two-mode
// automaton jumping at known times (one dashed line per jump, one mode segment per stay), inputs
// drawn as panels, the panel cap, determinism.

#include "commands/trajectory_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
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
  EXPECT_EQ(Count(modes.substr(0, modes.find("</g>")), "<rect"), 3);
  // x = t on [0, 1]: the first points of the first polyline are on one straight line.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, std::regex("points=\"([^\"]*)\"")));
  std::vector<double> xs, ys;
  std::istringstream in(m[1].str());
  std::string pair;
  while (in >> pair && xs.size() < 3) {
    xs.push_back(std::stod(pair.substr(0, pair.find(','))));
    ys.push_back(std::stod(pair.substr(pair.find(',') + 1)));
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
