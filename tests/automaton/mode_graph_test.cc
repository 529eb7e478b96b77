// Tests of ModeGraph: reachability, terminal modes, strongly connected components and warnings on
// small hand-built automata, and the finger model.

#include "hybrid/automaton/mode_graph.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

// An automaton with one variable, modes `modes` (the first is initial unless `initial` names
// others) and unlabelled transitions `edges` (pairs of mode indices).
Automaton Graph(int modes, const std::vector<std::pair<int, int>>& edges,
                const std::vector<int>& initial = {0}, const std::string& name = "g") {
  Automaton a(name);
  a.AddVariable("x");
  for (int m = 0; m < modes; ++m) {
    Mode mode;
    mode.name = "m";
    mode.name += std::to_string(m);
    a.AddMode(mode);
  }
  int k = 0;
  for (const auto& [s, t] : edges) {
    Transition tr;
    tr.name = "t";
    tr.name += std::to_string(k++);
    tr.source = ModeId(s);
    tr.target = ModeId(t);
    a.AddTransition(tr);
  }
  for (int m : initial) {
    a.AddInitialState({ModeId(m), {{0, {Expression::Constant(0), Expression::Constant(0)}}}});
  }
  return a;
}

std::vector<ModeId> Ids(const std::vector<int>& ids) {
  std::vector<ModeId> out;
  for (int i : ids) out.emplace_back(i);
  return out;
}

std::vector<std::vector<ModeId>> Sccs(const std::vector<std::vector<int>>& sccs) {
  std::vector<std::vector<ModeId>> out;
  for (const auto& s : sccs) out.push_back(Ids(s));
  return out;
}

TEST(ModeGraph, BoostGraphMirrorsTheAutomaton) {
  // Parallel edges and self-loops are kept.
  const Automaton a = Graph(3, {{0, 1}, {0, 1}, {1, 1}, {1, 2}});
  const ModeGraph g(a);
  EXPECT_EQ(boost::num_vertices(g.graph()), 3u);
  EXPECT_EQ(boost::num_edges(g.graph()), 4u);
  EXPECT_EQ(g.graph()[2].name, "m2");
  EXPECT_EQ(g.graph()[2].mode, ModeId(2));
  EXPECT_EQ(boost::out_degree(0, g.graph()), 2u);
  EXPECT_EQ(boost::in_degree(1, g.graph()), 3u);
  for (auto e : boost::make_iterator_range(boost::edges(g.graph()))) {
    const Transition& t = a.transition(g.graph()[e].transition);
    EXPECT_EQ(g.graph()[e].name, t.name);
    EXPECT_EQ(boost::source(e, g.graph()), static_cast<size_t>(t.source.value()));
    EXPECT_EQ(boost::target(e, g.graph()), static_cast<size_t>(t.target.value()));
  }
}

TEST(ModeGraph, ChainWithAnUnreachableTail) {
  // 0 -> 1 -> 2, and 3 -> 4 not reachable from 0; 4 -> 4 is a self-loop.
  const ModeGraph g(Graph(5, {{0, 1}, {1, 2}, {3, 4}, {4, 4}}));
  EXPECT_EQ(g.ReachableModes(), Ids({0, 1, 2}));
  EXPECT_EQ(g.UnreachableModes(), Ids({3, 4}));
  EXPECT_EQ(g.TerminalModes(), Ids({2, 4}));  // self-loops do not leave the mode
  EXPECT_EQ(g.StronglyConnectedComponents(), Sccs({{0}, {1}, {2}, {3}, {4}}));
  EXPECT_EQ(g.Warnings(), (std::vector<std::string>{
                              "mode 'm3' is unreachable from the initial modes",
                              "mode 'm4' is unreachable from the initial modes",
                          }));
}

TEST(ModeGraph, CyclesFormStronglyConnectedComponents) {
  // Two cycles {1, 2, 3} and {4, 5} joined by 3 -> 4; 0 leads into the first.
  const ModeGraph g(Graph(6, {{0, 1}, {1, 2}, {2, 3}, {3, 1}, {3, 4}, {4, 5}, {5, 4}}));
  EXPECT_EQ(g.ReachableModes(), Ids({0, 1, 2, 3, 4, 5}));
  EXPECT_TRUE(g.UnreachableModes().empty());
  EXPECT_TRUE(g.TerminalModes().empty());
  EXPECT_EQ(g.StronglyConnectedComponents(), Sccs({{0}, {1, 2, 3}, {4, 5}}));
  EXPECT_TRUE(g.Warnings().empty());
}

TEST(ModeGraph, SeveralInitialModes) {
  // 0 -> 1, 2 -> 3; initial 0 and 2: everything but 4 is reachable.
  const ModeGraph g(Graph(5, {{0, 1}, {2, 3}, {4, 0}}, {0, 2}));
  EXPECT_EQ(g.ReachableModes(), Ids({0, 1, 2, 3}));
  EXPECT_EQ(g.UnreachableModes(), Ids({4}));
  // An initial mode reachable from another initial mode is visited once.
  const ModeGraph h(Graph(3, {{0, 1}, {1, 2}}, {0, 1, 0}));
  EXPECT_EQ(h.ReachableModes(), Ids({0, 1, 2}));
}

TEST(ModeGraph, EdgesIntoTheInitialModeDoNotMakeOthersReachable) {
  // 1 -> 0 and 2 -> 1: from 0 nothing else is reachable.
  const ModeGraph g(Graph(3, {{1, 0}, {2, 1}}));
  EXPECT_EQ(g.ReachableModes(), Ids({0}));
  EXPECT_EQ(g.UnreachableModes(), Ids({1, 2}));
  EXPECT_EQ(g.TerminalModes(), Ids({0}));
}

TEST(ModeGraph, NoTransitionsWarning) {
  const ModeGraph single(Graph(1, {}, {0}, "solo"));
  EXPECT_TRUE(single.Warnings().empty());
  EXPECT_EQ(single.TerminalModes(), Ids({0}));
  EXPECT_EQ(single.StronglyConnectedComponents(), Sccs({{0}}));

  const ModeGraph pair(Graph(2, {}, {0, 1}, "pair"));
  EXPECT_EQ(pair.Warnings(), (std::vector<std::string>{
                                 "automaton 'pair' has several modes but no transitions",
                             }));
  const ModeGraph stranded(Graph(2, {}, {0}, "stranded"));
  EXPECT_EQ(stranded.Warnings(), (std::vector<std::string>{
                                     "mode 'm1' is unreachable from the initial modes",
                                     "automaton 'stranded' has several modes but no transitions",
                                 }));
}

TEST(ModeGraph, ReachabilityIgnoresGuards) {
  // The guard `x >= 1 and x <= 0` can never hold, yet the target counts as reachable.
  const Automaton a = ParseAutomaton(R"(
automaton g {
  var x;
  mode a { x' = 1; }
  mode b { }
  transition a -> b { guard x >= 1 and x <= 0; }
  init a { x = 0; }
})",
                                     "g.ha");
  EXPECT_EQ(ModeGraph(a).ReachableModes(), Ids({0, 1}));
}

TEST(ModeGraph, FingerModesAreAllReachable) {
  const System s = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  const Automaton& a = s.components()[0].automaton;
  const ModeGraph g(a);
  EXPECT_EQ(boost::num_vertices(g.graph()), 31u);
  EXPECT_EQ(boost::num_edges(g.graph()), static_cast<size_t>(a.num_transitions()));
  EXPECT_EQ(g.ReachableModes().size(), 31u);
  EXPECT_TRUE(g.UnreachableModes().empty());
  EXPECT_TRUE(g.Warnings().empty());
  // Every mode is in some component, each exactly once.
  std::vector<int> seen(a.num_modes(), 0);
  for (const auto& scc : g.StronglyConnectedComponents()) {
    EXPECT_TRUE(std::is_sorted(scc.begin(), scc.end()));
    for (ModeId m : scc) ++seen[m.value()];
  }
  EXPECT_EQ(seen, std::vector<int>(a.num_modes(), 1));
  EXPECT_EQ(g.graph()[0].name, "c000_l000");
}

}  // namespace
}  // namespace hybrid
