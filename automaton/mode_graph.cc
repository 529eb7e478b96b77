#include "hybrid/automaton/mode_graph.h"

#include <algorithm>
#include <boost/graph/breadth_first_search.hpp>
#include <boost/graph/strong_components.hpp>
#include <map>

namespace hybrid {

ModeGraph::ModeGraph(const Automaton& automaton)
    : automaton_name_(automaton.name()), graph_(automaton.num_modes()) {
  for (int m = 0; m < automaton.num_modes(); ++m) {
    graph_[m] = {ModeId(m), automaton.modes()[m].name};
  }
  for (int t = 0; t < automaton.num_transitions(); ++t) {
    const Transition& tr = automaton.transitions()[t];
    boost::add_edge(tr.source.value(), tr.target.value(),
                    TransitionEdge{TransitionId(t), tr.name, tr.label}, graph_);
  }
  for (const InitialState& s : automaton.initial_states()) initial_.push_back(s.mode);
}

std::vector<ModeId> ModeGraph::ReachableModes() const {
  const auto n = boost::num_vertices(graph_);
  std::vector<boost::default_color_type> color(n, boost::white_color);
  auto color_map =
      boost::make_iterator_property_map(color.begin(), boost::get(boost::vertex_index, graph_));
  boost::queue<ModeGraphType::vertex_descriptor> queue;
  for (ModeId m : initial_) {
    if (color[m.value()] == boost::white_color) {
      boost::breadth_first_visit(graph_, m.value(), queue, boost::default_bfs_visitor(), color_map);
    }
  }
  std::vector<ModeId> reachable;
  for (size_t v = 0; v < n; ++v) {
    if (color[v] != boost::white_color) reachable.emplace_back(static_cast<int>(v));
  }
  return reachable;
}

std::vector<ModeId> ModeGraph::UnreachableModes() const {
  const std::vector<ModeId> reachable = ReachableModes();
  std::vector<ModeId> out;
  for (int m = 0; m < static_cast<int>(boost::num_vertices(graph_)); ++m) {
    if (!std::binary_search(reachable.begin(), reachable.end(), ModeId(m))) out.emplace_back(m);
  }
  return out;
}

std::vector<ModeId> ModeGraph::TerminalModes() const {
  std::vector<ModeId> out;
  for (auto v : boost::make_iterator_range(boost::vertices(graph_))) {
    bool leaves = false;
    for (auto e : boost::make_iterator_range(boost::out_edges(v, graph_))) {
      leaves = leaves || boost::target(e, graph_) != v;
    }
    if (!leaves) out.emplace_back(static_cast<int>(v));
  }
  return out;
}

std::vector<std::vector<ModeId>> ModeGraph::StronglyConnectedComponents() const {
  const auto n = boost::num_vertices(graph_);
  std::vector<int> component(n);
  const int count = boost::strong_components(
      graph_, boost::make_iterator_property_map(component.begin(),
                                                boost::get(boost::vertex_index, graph_)));
  std::vector<std::vector<ModeId>> out(count);
  for (size_t v = 0; v < n; ++v) out[component[v]].emplace_back(static_cast<int>(v));
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.front() < b.front(); });
  return out;
}

std::vector<std::string> ModeGraph::Warnings() const {
  std::vector<std::string> out;
  for (ModeId m : UnreachableModes()) {
    out.push_back("mode '" + graph_[m.value()].name + "' is unreachable from the initial modes");
  }
  if (boost::num_edges(graph_) == 0 && boost::num_vertices(graph_) > 1) {
    out.push_back("automaton '" + automaton_name_ + "' has several modes but no transitions");
  }
  return out;
}

}  // namespace hybrid
