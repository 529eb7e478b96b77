// Tests of WriteDot: labels, escaping, styles, clusters and product drawings, and that Graphviz
// accepts the output (`dot -Tsvg`); long label lines wrapped, compact labels with the full ones
// as tooltips, the instances of one automaton drawn once (the hand: 35 modes drawn instead of
// 97), the product drawn over its reachable modes only (counted here by hand).

#include "hybrid/automaton/dot_writer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

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

// The values of every attribute `name` of `dot`, in order (escapes kept).
std::vector<std::string> Values(const std::string& dot, const std::string& name) {
  const std::string key = name + "=\"";
  std::vector<std::string> out;
  for (size_t at = dot.find(key); at != std::string::npos; at = dot.find(key, at + 1)) {
    if (at == 0 || (dot[at - 1] != ' ' && dot[at - 1] != '[')) continue;
    size_t end = at + key.size();
    while (end < dot.size() && !(dot[end] == '"' && dot[end - 1] != '\\')) ++end;
    out.push_back(dot.substr(at + key.size(), end - at - key.size()));
  }
  return out;
}

std::vector<std::string> Labels(const std::string& dot) { return Values(dot, "label"); }

// Splits a DOT label into its "\l"-ended lines.
std::vector<std::string> Lines(const std::string& label) {
  std::vector<std::string> out;
  size_t start = 0;
  for (size_t at = label.find("\\l"); at != std::string::npos; at = label.find("\\l", start)) {
    out.push_back(label.substr(start, at - start));
    start = at + 2;
  }
  if (start < label.size()) out.push_back(label.substr(start));
  return out;
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
  for (const std::string& label : Labels(dot)) {
    EXPECT_EQ(label.find("guard"), std::string::npos) << "no guards in compact labels";
    EXPECT_EQ(label.find("L.b'"), std::string::npos) << "no flows in compact labels";
  }
  // The full labels stay as tooltips.
  EXPECT_NE(dot.find("c0_m0 -> c0_m1 [label=\"push\", tooltip=\"closed_to_open [push]\\l"
                     "guard D.t >= 2\\lD.t := 0\\l\"];"),
            std::string::npos)
      << dot;
  EXPECT_NE(dot.find("c1_m0 [shape=box, style=rounded, label=\"dark\", tooltip=\"dark (L.on=0)\\l"
                     "L.b' = 0\\l\"];"),
            std::string::npos)
      << dot;
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find(">lit<"), std::string::npos);
}

}  // namespace
}  // namespace hybrid

namespace hybrid {
namespace {

TEST(DotWriter, LongLinesWrapAtSpacesAndReadBackWhole) {
  const System finger = Finger();
  const std::string wrapped = WriteDot(finger);
  DotOptions whole;
  whole.wrap_width = 0;
  const std::string unwrapped = WriteDot(finger, whole);
  const std::vector<std::string> a = Labels(wrapped), b = Labels(unwrapped);
  ASSERT_EQ(a.size(), b.size());
  size_t broken = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    const std::vector<std::string> lines = Lines(a[k]);
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(lines.front(), Lines(b[k]).front()) << "the name line stays whole";
    std::string joined = lines.front();
    for (size_t i = 1; i < lines.size(); ++i) {
      const std::string& line = lines[i];
      // At most 40 characters, unless one word (after a continuation's indent) is longer.
      const std::string words = line.starts_with("    ") ? line.substr(4) : line;
      if (line.size() > 40) EXPECT_EQ(words.find(' '), std::string::npos) << line;
      if (line.starts_with("    ")) {
        joined += " " + words;
        ++broken;
      } else {
        joined += "\\l" + line;
      }
    }
    EXPECT_EQ(joined + (a[k].ends_with("\\l") ? "\\l" : ""), b[k]);
  }
  // Six modes' third-link flow (91 characters) in three lines each, at least.
  EXPECT_GE(broken, 12u);
  EXPECT_NE(RenderSvg(wrapped).find("</svg>"), std::string::npos);
}

TEST(DotWriter, CompactLabelsKeepTheFullOnesAsTooltips) {
  const System finger = Finger();
  DotOptions compact;
  compact.compact = true;
  const std::string dot = WriteDot(finger, compact);
  DotOptions whole;
  whole.wrap_width = 0;
  const std::vector<std::string> full = Labels(WriteDot(finger, whole));
  const std::vector<std::string> tooltips = Values(dot, "tooltip");
  EXPECT_EQ(tooltips, full);
  EXPECT_EQ(tooltips.size(), 31u + 1u + 106u);  // modes, the initial edge, transitions
  const std::string svg = RenderSvg(dot);
  EXPECT_NE(svg.find("xlink:title=\"c000_l000 (c1=0"), std::string::npos);
}

System Hand() { return ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/hand.ha"); }

// The hand: three instances A, B, C of the finger declared alike (31 modes each, counted on the
// finger's own file) and the spread (4 modes, counted on its component).
TEST(DotWriter, InstancesDeclaredAlikeAreDrawnOnce) {
  const System hand = Hand();
  const int finger_modes = Finger().components()[0].automaton.num_modes();
  ASSERT_EQ(hand.components().size(), 4u);
  const int spread_modes = hand.components()[3].automaton.num_modes();
  EXPECT_EQ(finger_modes, 31);
  EXPECT_EQ(spread_modes, 4);
  const std::string merged = WriteDot(hand);
  EXPECT_EQ(Count(merged, "[shape=box"), static_cast<size_t>(finger_modes + spread_modes));
  EXPECT_EQ(Count(merged, "subgraph cluster_"), 2u);
  EXPECT_NE(merged.find("label=\"A, B, C: finger\\lx stands for A.x, B.x, C.x\\lshared: u\\l\""),
            std::string::npos)
      << merged.substr(0, 400);
  // Drawn as declared: the finger's own names, not A's.
  EXPECT_NE(merged.find("theta1' = m1 * u"), std::string::npos);
  EXPECT_EQ(merged.find("A.theta1"), std::string::npos);
  EXPECT_NE(merged.find("label=\"S: spread\""), std::string::npos);
  DotOptions every;
  every.merge_instances = false;
  const std::string separate = WriteDot(hand, every);
  EXPECT_EQ(Count(separate, "[shape=box"), static_cast<size_t>(3 * finger_modes + spread_modes));
  EXPECT_EQ(Count(separate, "subgraph cluster_"), 4u);
  // An instance declared otherwise (another initial value) keeps a cluster of its own.
  System changed = Hand();
  changed.SetInitialValue("A.theta1", 5);
  const std::string two = WriteDot(changed);
  EXPECT_EQ(Count(two, "[shape=box"), static_cast<size_t>(2 * finger_modes + spread_modes));
  EXPECT_NE(two.find("label=\"A: finger\""), std::string::npos);
  EXPECT_NE(two.find("label=\"B, C: finger\\lx stands for B.x, C.x\\lshared: u\\l\""),
            std::string::npos);
  EXPECT_NE(RenderSvg(merged).find("</svg>"), std::string::npos);
  // A grouping by one instance's variable still applies to the one drawing of all three.
  DotOptions by_a;
  by_a.group = [](const Automaton& a, const Mode& m) -> std::string {
    for (const auto& [slot, value] : m.discrete_values) {
      if (a.symbols()[slot].name == "A.c1") return "A.c1=" + std::to_string(value);
    }
    return "";
  };
  const std::string grouped = WriteDot(hand, by_a);
  EXPECT_EQ(Count(grouped, "label=\"A.c1=0\"; style=rounded"), 1u) << grouped.substr(0, 600);
  EXPECT_EQ(Count(grouped, "label=\"A.c1=1\"; style=rounded"), 1u);
}

TEST(DotWriter, MergedInstancesListTheirBoundNames) {
  const System hand = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/controlled_hand.ha");
  const std::string dot = WriteDot(hand);
  EXPECT_NE(dot.find("label=\"ctlA, ctlB, ctlC: controller\\lx stands for ctlA.x, ctlB.x, "
                     "ctlC.x\\lshared: request\\lctlA: g = A.g, stall = A.stall, u = A.u\\l"
                     "ctlB: g = B.g, stall = B.stall, u = B.u\\lctlC: g = C.g, stall = C.stall, "
                     "u = C.u\\l\""),
            std::string::npos)
      << dot.substr(0, 2000);
  EXPECT_EQ(Count(dot, "subgraph cluster_"), 3u);  // fingers, controllers, spread
}

// The house's product: 2 x 2 mode pairs, of which (closed, dark) reaches (open, lit) by `push`
// together, then (closed, lit) by the door's unlabelled transition; (open, dark) is never
// reached, since the door opens only by `push`, which the light takes with it from dark to lit.
TEST(DotWriter, ProductDrawsItsReachableModesOnly) {
  const System s = ParseModel(kTwoComponents, "house.ha");
  const std::string dot = WriteDot(s, {.product = true});
  EXPECT_EQ(Count(dot, "[shape=box"), 3u);
  EXPECT_NE(dot.find("label=\"D.closed|L.dark (L.on=0)"), std::string::npos);
  EXPECT_NE(dot.find("label=\"D.open|L.lit (L.on=1)"), std::string::npos);
  EXPECT_NE(dot.find("label=\"D.closed|L.lit (L.on=1)"), std::string::npos);
  EXPECT_EQ(dot.find("D.open|L.dark"), std::string::npos);
}

}  // namespace
}  // namespace hybrid
