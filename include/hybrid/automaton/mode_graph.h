#pragma once

#include <boost/graph/adjacency_list.hpp>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/id.h"

namespace hybrid {

/// Vertex bundle of the mode graph: one vertex per mode.
struct ModeVertex {
  ModeId mode;
  std::string name;
};

/// Edge bundle of the mode graph: one edge per transition (parallel edges and self-loops kept).
struct TransitionEdge {
  TransitionId transition;
  std::string name;
  std::string label;
};

/// The mode graph: a Boost.Graph directed multigraph with vecS vertex storage, so that the vertex
/// descriptor of mode `m` is `m.value()`, and bidirectional so that in-edges are available.
/// Exposed read-only by ModeGraph::graph(); any Boost.Graph algorithm applies to it.
using ModeGraphType = boost::adjacency_list<boost::vecS, boost::vecS, boost::bidirectionalS,
                                            ModeVertex, TransitionEdge>;

/// The discrete structure of an automaton and the queries on it.
///
/// Reachability here is syntactic: a transition counts whatever its guard, so "reachable" is an
/// over-approximation of the modes a run can visit and "unreachable" is a proof that none can.
class ModeGraph {
 public:
  explicit ModeGraph(const Automaton& automaton);

  const ModeGraphType& graph() const { return graph_; }
  /// Modes reachable from the initial modes (initial modes included), sorted by id.
  std::vector<ModeId> ReachableModes() const;
  /// Modes not reachable from any initial mode, sorted by id.
  std::vector<ModeId> UnreachableModes() const;
  /// Modes that cannot be left: no transition to another mode (self-loops do not count).
  std::vector<ModeId> TerminalModes() const;
  /// Strongly connected components (Tarjan, boost::strong_components), each sorted by id, the
  /// list sorted by each component's smallest id.
  std::vector<std::vector<ModeId>> StronglyConnectedComponents() const;
  /// Human-readable warnings: unreachable modes, automata without transitions.
  std::vector<std::string> Warnings() const;

 private:
  std::string automaton_name_;
  ModeGraphType graph_;
  std::vector<ModeId> initial_;
};

}  // namespace hybrid
