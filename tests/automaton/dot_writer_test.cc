// Tests of WriteDot: labels, escaping, styles, clusters and product drawings, and that Graphviz
// accepts the output (`dot -Tsvg`).

#include "hybrid/automaton/dot_writer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;

System Finger() { return ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha"); }

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

// Renders `dot_text` with Graphviz to SVG; returns the SVG, or "" (and a failure) if `dot` fails.
std::string RenderSvg(const std::string& dot_text) {
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("hybrid_dot_test_" + std::to_string(rd()));
  fs::create_directories(dir);
  const fs::path in = dir / "graph.dot", out = dir / "graph.svg", err = dir / "stderr.txt";
  std::ofstream(in, std::ios::binary) << dot_text;
  const std::string command =
      "dot -Tsvg '" + in.string() + "' -o '" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(command.c_str());
  std::stringstream svg, messages;
  svg << std::ifstream(out).rdbuf();
  messages << std::ifstream(err).rdbuf();
  fs::remove_all(dir);
  EXPECT_EQ(status, 0) << command << "\n" << messages.str();
  EXPECT_EQ(messages.str(), "") << "Graphviz warnings";
  return status == 0 ? svg.str() : "";
}

const char* const kTwoComponents = R"(
automaton door {
  var t;
  mode closed { t' = 1; inv t <= 5; }
  mode open { t' = -1; }
  transition closed -> open { guard t >= 2; reset t := 0; label push; }
  transition open -> closed { guard t <= 0; lazy; }
  init closed { t in [0, 1]; }
}

automaton light {
  discrete on;
  var b;
  mode dark (on = 0) { b' = 0; }
  mode lit (on = 1) { b' = 1; }
  transition dark -> lit { label push; }
  init dark { b = 0; }
}

system house {
  share push;
  instance D = door;
  instance L = light;
}
)";

TEST(DotWriter, LabelsOfModesTransitionsAndInitialStates) {
  const std::string dot = WriteDot(ParseModel(R"(
automaton th {
  var T [C];
  discrete heater;
  param Tmax = 22;
  mode off (heater = 0) { T' = -0.1 * T; inv T >= 18; }
  mode on (heater = 1) { T' = 5 - 0.1 * T; inv T <= Tmax; }
  transition turn_on: off -> on { guard T <= 19; label switch; }
  transition on -> off { guard T >= 21; reset T := T - 0.5; lazy; }
  init off { T in [18, 20]; }
}
)",
                                              "th.ha"));
  EXPECT_TRUE(dot.starts_with("digraph \"th\" {\n")) << dot;
  EXPECT_TRUE(dot.ends_with("}\n"));
  // Modes: name with discrete values, then each flow and the invariant, left-justified lines.
  EXPECT_NE(dot.find("m0 [shape=box, style=rounded, label=\"off (heater=0)\\lT' = -0.1 * T\\l"
                     "inv T >= 18\\l\"];"),
            std::string::npos)
      << dot;
  EXPECT_NE(dot.find("label=\"on (heater=1)\\lT' = 5 - 0.1 * T\\linv T <= Tmax\\l\""),
            std::string::npos);
  // Transitions: name, label in brackets, guard, resets; lazy ones dashed.
  EXPECT_NE(dot.find("m0 -> m1 [label=\"turn_on [switch]\\lguard T <= 19\\l\"];"),
            std::string::npos)
      << dot;
  EXPECT_NE(dot.find("m1 -> m0 [label=\"on_to_off\\lguard T >= 21\\lT := T - 0.5\\l\", "
                     "style=dashed];"),
            std::string::npos)
      << dot;
  EXPECT_EQ(Count(dot, "style=dashed"), 1u);
  // Initial state: a point node with an edge labelled by the initial values.
  EXPECT_NE(dot.find("init0 [shape=point, width=0.12];"), std::string::npos);
  EXPECT_NE(dot.find("init0 -> m0 [label=\"T in [18, 20]\\l\"];"), std::string::npos) << dot;
  RenderSvg(dot);
}

TEST(DotWriter, EscapesQuotesAndBackslashes) {
  // Names from the API may contain anything; the DOT strings must stay well formed.
  Automaton a("say \"hi\"");
  a.AddVariable("x");
  a.AddMode(Mode{"a \"quoted\" mode", {}, {}, {}});
  a.AddMode(Mode{"back\\slash\\", {}, {}, {}});
  a.AddMode(Mode{"\\N \\G \\l", {}, {}, {}});
  Transition t;
  t.name = "go \"now\"";
  t.label = "l\\\"";
  t.source = ModeId(0);
  t.target = ModeId(1);
  a.AddTransition(t);
  a.AddInitialState({ModeId(0), {{0, {Expression::Constant(0), Expression::Constant(0)}}}});
  const std::string dot = WriteDot(System::Of(a));
  EXPECT_TRUE(dot.starts_with("digraph \"say \\\"hi\\\"\" {\n")) << dot;
  EXPECT_NE(dot.find("label=\"a \\\"quoted\\\" mode\\l\""), std::string::npos) << dot;
  EXPECT_NE(dot.find("label=\"back\\\\slash\\\\\\l\""), std::string::npos) << dot;
  // Graphviz escapes such as \N are written as a literal backslash.
  EXPECT_NE(dot.find("label=\"\\\\N \\\\G \\\\l\\l\""), std::string::npos) << dot;
  EXPECT_NE(dot.find("label=\"go \\\"now\\\" [l\\\\\\\"]\\l\""), std::string::npos) << dot;
  // No quote is left unescaped: outside escapes, quotes pair up on every line.
  std::istringstream lines(dot);
  for (std::string line; std::getline(lines, line);) {
    int quotes = 0;
    for (size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '\\') {
        ++i;
      } else if (line[i] == '"') {
        ++quotes;
      }
    }
    EXPECT_EQ(quotes % 2, 0) << line;
  }
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("a &quot;quoted&quot; mode"), std::string::npos);
  EXPECT_NE(svg.find("back\\slash\\"), std::string::npos);
  EXPECT_NE(svg.find("\\N \\G \\l"), std::string::npos);
}

TEST(DotWriter, ComposedSystemDrawsOneClusterPerComponent) {
  const System s = ParseModel(kTwoComponents, "house.ha");
  const std::string dot = WriteDot(s);
  EXPECT_EQ(Count(dot, "subgraph cluster_"), 2u);
  EXPECT_NE(dot.find("subgraph cluster_0 {\n    label=\"D: door\";"), std::string::npos) << dot;
  EXPECT_NE(dot.find("subgraph cluster_1 {\n    label=\"L: light\";"), std::string::npos);
  // Node names are prefixed per component so that they do not collide.
  EXPECT_NE(dot.find("c0_m0 -> c0_m1 [label=\"closed_to_open [push]\\lguard D.t >= 2\\l"
                     "D.t := 0\\l\"];"),
            std::string::npos)
      << dot;
  EXPECT_NE(dot.find("c1_m0 [shape=box, style=rounded, label=\"dark (L.on=0)\\lL.b' = 0\\l\"];"),
            std::string::npos)
      << dot;
  EXPECT_NE(dot.find("c0_init0 -> c0_m0 [label=\"D.t in [0, 1]\\l\"];"), std::string::npos);
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("D: door"), std::string::npos);
}

TEST(DotWriter, ProductDrawing) {
  const System s = ParseModel(kTwoComponents, "house.ha");
  const std::string dot = WriteDot(s, {.product = true});
  EXPECT_EQ(Count(dot, "subgraph"), 0u);
  EXPECT_EQ(Count(dot, "[shape=box"), static_cast<size_t>(s.Product().num_modes()));
  // Product modes named as the simulator names them: instance.mode joined with "|".
  EXPECT_NE(dot.find("label=\"D.closed|L.dark (L.on=0)\\l"), std::string::npos) << dot;
  EXPECT_NE(dot.find("label=\"D.open|L.lit (L.on=1)\\l"), std::string::npos) << dot;
  EXPECT_NE(dot.find("[push]"), std::string::npos);
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
}

TEST(DotWriter, ProductLimitIsPassedOn) {
  const System s = ParseModel(kTwoComponents, "house.ha");
  DotOptions options;
  options.product = true;
  options.max_product_modes = 1;
  EXPECT_THROW(WriteDot(s, options), std::invalid_argument);
  options.product = false;
  EXPECT_NO_THROW(WriteDot(s, options));
}

TEST(DotWriter, FingerRendersWithGraphviz) {
  const System finger = Finger();
  const std::string dot = WriteDot(finger);
  EXPECT_EQ(Count(dot, "[shape=box"), 31u);
  EXPECT_EQ(Count(dot, " -> m"),
            static_cast<size_t>(finger.components()[0].automaton.num_transitions()) + 1);
  EXPECT_NE(dot.find("label=\"c000_l000 (c1=0, c2=0, c3=0, l1=0, l2=0, l3=0)\\l"
                     "theta1' = m1 * u\\l"),
            std::string::npos);
  EXPECT_NE(dot.find("[release3]"), std::string::npos);
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_EQ(Count(svg, "class=\"node\""), 32u);  // 31 modes and the initial point
}

TEST(DotWriter, FingerProductIsTheSameDrawing) {
  // A single component's product is the component itself (mode for mode), so only the
  // transition names differ.
  const System finger = Finger();
  const std::string product = WriteDot(finger, {.product = true});
  EXPECT_EQ(Count(product, "[shape=box"), 31u);
  EXPECT_NE(product.find("label=\"c000_l000 (c1=0, c2=0, c3=0, l1=0, l2=0, l3=0)\\l"),
            std::string::npos);
  EXPECT_NE(RenderSvg(product).find("<svg"), std::string::npos);
}

}  // namespace
}  // namespace hybrid

namespace hybrid {
namespace {

TEST(DotWriter, CompactLabelsAndGroupsClusterTheModes) {
  const System s = ParseModel(kTwoComponents, "house.ha");
  DotOptions options;
  options.compact = true;
  // Group the light's modes by whether it is on; the door's modes stay ungrouped.
  options.group = [](const Automaton& a, const Mode& m) -> std::string {
    for (const auto& [slot, value] : m.discrete_values) {
      if (a.symbols()[slot].name == "L.on") return value ? "lit" : "dark";
    }
    return "";
  };
  const std::string dot = WriteDot(s, options);
  EXPECT_EQ(Count(dot, "subgraph cluster_"), 4u) << dot;  // two components, two groups
  EXPECT_NE(dot.find("label=\"lit\"; style=rounded"), std::string::npos) << dot;
  EXPECT_NE(dot.find("newrank=true;"), std::string::npos);
  EXPECT_EQ(dot.find("guard"), std::string::npos) << "no guards in compact labels";
  EXPECT_EQ(dot.find("L.b'"), std::string::npos) << "no flows in compact labels";
  EXPECT_NE(dot.find("c0_m0 -> c0_m1 [label=\"push\"];"), std::string::npos) << dot;
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find(">lit<"), std::string::npos);
}

}  // namespace
}  // namespace hybrid
