#pragma once

#include <functional>
#include <string>

#include "hybrid/automaton/system.h"

namespace hybrid {

/// How WriteDot draws a composed system.
struct DotOptions {
  /// false: one cluster per component, each with its own modes and transitions.
  /// true: the product automaton (System::Product), one node per reachable tuple of modes.
  bool product = false;
  /// Largest product drawn; a larger one throws std::invalid_argument (a graph that size is not
  /// readable; draw the components as clusters instead).
  int max_product_modes = 2000;
  /// Short labels for a graph that fits a page: modes by name, transitions by their
  /// synchronisation label only (none without); no discrete values, flows, invariants, guards,
  /// resets or initial values.
  bool compact = false;
  /// Groups the modes of each automaton drawn into clusters named by this function's text (modes
  /// for which it returns "" stay outside any cluster); no grouping when empty.
  std::function<std::string(const Automaton&, const Mode&)> group;
  /// Full labels (not `compact`): a line after the first (the name, kept whole) longer than this
  /// many characters is broken at spaces, its continuations indented by four spaces (a longer
  /// word stays whole); 0 keeps every line whole. Narrow labels keep a large graph's ranks close
  /// together.
  int wrap_width = 40;
  /// A composed system drawn as clusters (not `product`): the instances of one automaton declared
  /// alike (equal Component::source, instance names non-empty) share one cluster drawn from the
  /// automaton as declared, labelled with the instances and what its names stand for in each
  /// (`x` is `A.x`, except shared and bound names, listed). false: one cluster per instance.
  bool merge_instances = true;
};

/// A Graphviz `digraph` of `system`. Nodes are modes, labelled with the mode name, each flow
/// (`x' = f`) and the invariant; edges are transitions, labelled with the name, the synchronising
/// label in brackets, the guard and the resets; lazy transitions are dashed. A point node marks
/// each initial mode, its edge labelled with the initial values. With `compact` labels every node
/// and edge keeps its full label as a tooltip (shown on hover in Graphviz's SVG). Ranked with
/// Graphviz's `newrank` unless modes are grouped in one automaton (it spreads those clusters).
/// All text is escaped for DOT strings, so any model renders. Throws what System::Product throws
/// when `product` is set.
std::string WriteDot(const System& system, const DotOptions& options = {});

}  // namespace hybrid
