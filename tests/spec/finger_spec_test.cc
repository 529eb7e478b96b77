// The bundled finger model (spec/finger.ha) against the report's section 3 and the generator.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "hybrid/automaton/compiled_expression.h"
#include "hybrid/automaton/mode_graph.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;

Automaton Finger() {
  const System s = ParseModelFile(kSource + "/spec/finger.ha");
  EXPECT_EQ(s.components().size(), 1u);
  return s.components()[0].automaton;
}

int Slot(const Automaton& a, const std::string& name) { return *a.symbols().Find(name); }

double Param(const Automaton& a, const std::string& name) {
  return a.ParameterEnvironment()[Slot(a, name)];
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(FingerSpecTest, CommittedFileIsTheGeneratorOutput) {
  const std::string command = "python3 " + kSource + "/tools/generate_finger.py";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string generated;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) generated.append(buffer.data(), n);
  ASSERT_EQ(pclose(pipe), 0);
  EXPECT_EQ(generated, ReadAll(kSource + "/spec/finger.ha"))
      << "run: python3 tools/generate_finger.py > spec/finger.ha";
}

TEST(FingerSpecTest, SizeAndReachability) {
  const Automaton a = Finger();
  EXPECT_EQ(a.num_modes(), 31);
  EXPECT_EQ(a.num_transitions(), 106);
  const ModeGraph graph(a);
  EXPECT_EQ(graph.ReachableModes().size(), 31u);
  EXPECT_TRUE(graph.Warnings().empty());
  EXPECT_TRUE(graph.TerminalModes().empty());  // every state can be left when the motor reverses
}

// The report's constants and the breakpoints of section 4.1 follow from the joint ranges.
TEST(FingerSpecTest, ConstantsMatchTheReport) {
  const Automaton a = Finger();
  EXPECT_DOUBLE_EQ(Param(a, "m1"), 0.5);
  EXPECT_DOUBLE_EQ(Param(a, "m2"), 0.9);
  EXPECT_DOUBLE_EQ(Param(a, "m1") * 110, -Param(a, "theta3_min"));  // phase 1 -> 1' at g = 110
  EXPECT_DOUBLE_EQ(Param(a, "m1") * 140, Param(a, "theta1_max"));   // l1 at g = 140
  EXPECT_DOUBLE_EQ(Param(a, "m2") * 100, Param(a, "theta2_max"));   // l2 at g = 240
}

// The mode names spell the discrete state, and the report's law "no state has c_i = l_i = 1"
// holds for every mode and every transition target.
TEST(FingerSpecTest, DiscreteStatesAreConsistentAndNeverContactAtLimit) {
  const Automaton a = Finger();
  const std::array<std::string, 6> names = {"c1", "c2", "c3", "l1", "l2", "l3"};
  for (const Mode& m : a.modes()) {
    std::array<int, 6> v{};
    for (int i = 0; i < 6; ++i) v[i] = *m.DiscreteValueOf(Slot(a, names[i]));
    auto digit = [](int x) { return x == -1 ? std::string("n") : std::to_string(x); };
    EXPECT_EQ(m.name, "c" + digit(v[0]) + digit(v[1]) + digit(v[2]) + "_l" + digit(v[3]) +
                          digit(v[4]) + digit(v[5]));
    for (int i = 0; i < 3; ++i) {
      EXPECT_FALSE(v[i] == 1 && v[3 + i] == 1) << m.name;
    }
  }
}

// Flows of the free-space phases against the report's table (section 3), evaluated at u = 1.
TEST(FingerSpecTest, FlowsFollowThePhaseTable) {
  const Automaton a = Finger();
  std::vector<double> env = a.ParameterEnvironment();
  env[Slot(a, "u")] = 1.0;
  auto rate = [&](const std::string& mode, const std::string& var) {
    const auto flow = a.mode(*a.FindMode(mode)).FlowOf(Slot(a, var));
    return flow ? CompiledExpression(*flow)(env) : 0.0;
  };
  EXPECT_DOUBLE_EQ(rate("c000_l000", "theta1"), 0.5);
  EXPECT_DOUBLE_EQ(rate("c000_l000", "theta3"), -0.5);
  EXPECT_DOUBLE_EQ(rate("c000_l00n", "theta3"), 0.0);
  EXPECT_DOUBLE_EQ(rate("c000_l100", "theta2"), 0.9);
  EXPECT_DOUBLE_EQ(rate("c000_l100", "theta3"), -0.9);
  EXPECT_DOUBLE_EQ(rate("c000_l10n", "theta3"), 0.0);
  EXPECT_DOUBLE_EQ(rate("c000_l110", "theta1"), 0.0);
  EXPECT_DOUBLE_EQ(rate("c001_l000", "g"), 0.0);  // phase 4: the motor stops
  EXPECT_DOUBLE_EQ(rate("c000_l000", "g"), 1.0);
}

// Every transition of kind 3 sets exactly the l_i of the joint its guard tests.
TEST(FingerSpecTest, LimitTransitionsSetTheirLimitFlag) {
  const Automaton a = Finger();
  int count = 0;
  for (const Transition& t : a.transitions()) {
    if (t.name.rfind("t3_", 0) != 0) continue;
    ++count;
    ASSERT_EQ(t.guard.comparisons.size(), 2u);  // theta_i >= theta_i_max and rate > 0
    const std::string joint = t.guard.comparisons[0].lhs.symbol_name();  // theta_i
    const std::string flag = "l" + joint.substr(5);
    EXPECT_EQ(a.mode(t.source).DiscreteValueOf(Slot(a, flag)), 0) << t.name;
    EXPECT_EQ(a.mode(t.target).DiscreteValueOf(Slot(a, flag)), 1) << t.name;
  }
  EXPECT_GT(count, 0);
}

// Clash C1, pinned: section 3's m3(g) is not the rate of section 4's theta3 law, and the model
// follows section 4. Section 4: theta3(g) = theta3_min + c (g - g_s) / (255 - g) after link 2
// stops at g_s (c = theta3_max - theta3_min), so d theta3/dg = c (255 - g_s) / (255 - g)^2.
// Section 3: m3(g) = theta3_min + c / (255 - g), negative below g = 253.2, which would drive
// theta3 below its lower limit. The model's phase-3 flow, from (theta3_s, g_s) =
// (theta3_min, 240), is section 4's rate.
TEST(FingerSpecTest, Clash_Section3ThetaRate_ModelFollowsSection4) {
  const Automaton a = Finger();
  const auto flow = a.mode(*a.FindMode("c000_l110")).FlowOf(Slot(a, "theta3"));
  ASSERT_TRUE(flow.has_value());
  std::vector<double> env = a.ParameterEnvironment();
  env[Slot(a, "u")] = 1.0;
  const double th3_min = Param(a, "theta3_min");
  const double c = Param(a, "theta3_max") - th3_min;
  const double g_s = 240.0;
  env[Slot(a, "theta3_s")] = th3_min;
  env[Slot(a, "g_s")] = g_s;
  for (double g : {240.0, 245.0, 250.0}) {
    env[Slot(a, "g")] = g;
    const double model = flow->Evaluate(env);
    const double section3 = th3_min + c / (255 - g);
    const double section4 = c * (255 - g_s) / ((255 - g) * (255 - g));
    EXPECT_LT(section3, 0.0) << "section 3's m3 drives theta3 below its lower limit at g = " << g;
    EXPECT_GT(std::abs(section3 - section4), 1.0) << "g = " << g;
    EXPECT_NEAR(model, section4, 1e-12) << "g = " << g;
  }
}

// Every transition that blocks link 2 (contact 2 or its limit) records theta3_s and g_s, where
// the phase-3 law starts; every transition that releases it tests theta3 == theta3_s.
TEST(FingerSpecTest, Link2BlockRecordsThePhase3Start) {
  const Automaton a = Finger();
  const int c2 = Slot(a, "c2"), l2 = Slot(a, "l2");
  int blocks = 0, releases = 0;
  for (const Transition& t : a.transitions()) {
    const Mode& from = a.mode(t.source);
    const Mode& to = a.mode(t.target);
    const bool before = *from.DiscreteValueOf(c2) || *from.DiscreteValueOf(l2);
    const bool after = *to.DiscreteValueOf(c2) || *to.DiscreteValueOf(l2);
    if (!before && after) {
      ++blocks;
      std::set<std::string> reset;
      for (const auto& [slot, e] : t.resets) reset.insert(a.symbols()[slot].name);
      EXPECT_TRUE(reset.count("theta3_s") && reset.count("g_s")) << t.name;
    }
    if (before && !after) {
      ++releases;
      EXPECT_NE(t.guard.ToString().find("theta3 == theta3_s"), std::string::npos) << t.name;
    }
  }
  EXPECT_EQ(blocks, 10);  // contact 2 from phases 1, 1', 2, 2' (6 modes), limit 2 from 2, 2' (4)
  EXPECT_GT(releases, 0);
}

}  // namespace
}  // namespace hybrid
