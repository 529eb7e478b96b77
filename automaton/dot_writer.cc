#include "hybrid/automaton/dot_writer.h"

#include <algorithm>
#include <map>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/printer.h"

namespace hybrid {
namespace {

// Escapes text for a double-quoted DOT string; "\l" ends left-justified lines.
std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (c == '\n') {
      out += "\\l";
      continue;
    }
    out.push_back(c);
  }
  return out;
}

// `line` broken at spaces into pieces of at most `width` characters, the continuations indented
// by four spaces and joined by newlines; a word longer than the room stays whole.
std::string WrapLine(std::string_view line, size_t width) {
  constexpr std::string_view kIndent = "    ";
  std::string out;
  for (size_t room = width;; room = width > kIndent.size() ? width - kIndent.size() : 1) {
    if (line.size() <= room) return out + std::string(line);
    size_t cut = line.rfind(' ', room);
    if (cut == std::string_view::npos || cut == 0) cut = line.find(' ', room);
    if (cut == std::string_view::npos) return out + std::string(line);
    out += std::string(line.substr(0, cut)) + "\n" + std::string(kIndent);
    line.remove_prefix(cut + 1);
  }
}

// `text` (lines ended by newlines) with every line but the first (a name, kept whole) longer
// than `width` characters wrapped (WrapLine); unchanged for a width of 0 or less.
std::string Wrapped(const std::string& text, int width) {
  if (width <= 0) return text;
  size_t start = text.find('\n');
  if (start == std::string::npos) return text;
  std::string out = text.substr(0, ++start);
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    out += WrapLine(std::string_view(text).substr(start, end - start), static_cast<size_t>(width));
    if (end < text.size()) out += "\n";
    start = end + 1;
  }
  return out;
}

// The DOT attributes of a node or edge whose full label is `full` and whose drawn label is
// `compact` in compact drawings: the label, and in compact drawings the full one as tooltip.
std::string LabelAttributes(const std::string& full, const std::string& compact,
                            const DotOptions& options) {
  if (!options.compact) return "label=\"" + Escape(Wrapped(full, options.wrap_width)) + "\"";
  return "label=\"" + Escape(compact) + "\", tooltip=\"" + Escape(full) + "\"";
}

// The mode's name (`name`) with its discrete values: "name (c1=0, l3=-1)".
std::string ModeName(const Automaton& a, const Mode& m, const std::string& name) {
  std::string text = name;
  if (!m.discrete_values.empty()) {
    text += " (";
    for (size_t i = 0; i < m.discrete_values.size(); ++i) {
      text += (i > 0 ? ", " : "") + a.symbols()[m.discrete_values[i].first].name + "=" +
              std::to_string(m.discrete_values[i].second);
    }
    text += ")";
  }
  return text;
}

std::string ModeLabel(const Automaton& a, const Mode& m, const std::string& name) {
  std::string text = ModeName(a, m, name) + "\n";
  for (const auto& [slot, rhs] : m.flows) {
    text += a.symbols()[slot].name + "'" + FlowText(rhs) + "\n";
  }
  if (!m.invariant.empty()) text += "inv " + m.invariant.ToString() + "\n";
  return text;
}

std::string TransitionLabel(const Automaton& a, const Transition& t) {
  std::string text = t.name;
  if (!t.label.empty()) text += " [" + t.label + "]";
  text += "\n";
  if (!t.guard.empty()) text += "guard " + t.guard.ToString() + "\n";
  for (const Reset& r : t.resets) {
    text += a.symbols()[r.slot].name + " := " + r.value.ToString() + "\n";
  }
  return text;
}

std::string InitLabel(const Automaton& a, const InitialState& s) {
  std::string text;
  for (const InitialValue& v : s.values) {
    text += a.symbols()[v.slot].name +
            (v.is_point ? " = " + v.range.lo.ToString()
                        : " in [" + v.range.lo.ToString() + ", " + v.range.hi.ToString() + "]") +
            "\n";
  }
  return text;
}

// The modes of `a`, one node each, in clusters by options.group (when set) applied to the modes
// of `grouped` (`a` itself, or the renamed automaton of the first of the instances drawn from
// `a`, their declaration: the same modes, so `--group-by A.c1` still finds A's variable).
// `names`: the modes' names to show, by id (empty: their own names).
void WriteModes(const Automaton& a, const Automaton& grouped, std::span<const std::string> names,
                const std::string& prefix, const std::string& indent, const DotOptions& options,
                std::ostream& out) {
  std::map<std::string, std::vector<int>> groups;  // by name: one cluster each, sorted
  for (int m = 0; m < a.num_modes(); ++m) {
    groups[options.group ? options.group(grouped, grouped.modes()[m]) : ""].push_back(m);
  }
  int cluster = 0;
  for (const auto& [name, modes] : groups) {
    std::string inner = indent;
    if (!name.empty()) {
      out << indent << "subgraph cluster_" << prefix << "g" << cluster++ << " {\n"
          << indent << "  label=\"" << Escape(name) << "\"; style=rounded; color=\"#999999\";\n";
      inner += "  ";
    }
    for (const int m : modes) {
      const Mode& mode = a.modes()[m];
      const std::string& shown = names.empty() ? mode.name : names[m];
      out << inner << prefix << "m" << m << " [shape=box, style=rounded, "
          << LabelAttributes(ModeLabel(a, mode, shown), shown, options) << "];\n";
    }
    if (!name.empty()) out << indent << "}\n";
  }
}

// A product mode's name: each component's mode, qualified by its instance, joined with "|".
std::string QualifiedModeName(const System& system, std::span<const int> tuple) {
  std::string out;
  for (size_t c = 0; c < tuple.size(); ++c) {
    out += (c > 0 ? "|" : "") + system.QualifiedModeName(static_cast<int>(c), ModeId(tuple[c]));
  }
  return out;
}

// `a`'s modes (grouped as those of `grouped`: WriteModes), initial states and transitions.
void WriteAutomaton(const Automaton& a, const Automaton& grouped,
                    std::span<const std::string> names, const std::string& prefix,
                    const std::string& indent, const DotOptions& options, std::ostream& out) {
  WriteModes(a, grouped, names, prefix, indent, options, out);
  for (size_t i = 0; i < a.initial_states().size(); ++i) {
    const InitialState& s = a.initial_states()[i];
    out << indent << prefix << "init" << i << " [shape=point, width=0.12];\n";
    out << indent << prefix << "init" << i << " -> " << prefix << "m" << s.mode.value() << " ["
        << LabelAttributes(InitLabel(a, s), "", options) << "];\n";
  }
  for (const Transition& t : a.transitions()) {
    out << indent << prefix << "m" << t.source.value() << " -> " << prefix << "m"
        << t.target.value() << " [" << LabelAttributes(TransitionLabel(a, t), t.label, options);
    if (t.urgency == Urgency::kLazy) out << ", style=dashed";
    out << "];\n";
  }
}

// The components drawn in one cluster each: with `merge`, the instances of one automaton
// declared alike (equal Component::source, non-empty instance names) together, in the order of
// their first member; otherwise each alone.
std::vector<std::vector<int>> ClusterMembers(std::span<const Component> components, bool merge) {
  std::vector<std::vector<int>> clusters;
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    const Component& comp = components[static_cast<size_t>(c)];
    const auto alike = [&](const std::vector<int>& cluster) {
      const Component& first = components[static_cast<size_t>(cluster.front())];
      return !first.instance.empty() && first.source == comp.source;
    };
    const auto it = merge && !comp.instance.empty()
                        ? std::find_if(clusters.begin(), clusters.end(), alike)
                        : clusters.end();
    if (it == clusters.end()) {
      clusters.push_back({c});
    } else {
      it->push_back(c);
    }
  }
  return clusters;
}

// The names of `comp`'s automaton as declared (symbols and transition labels) that do not stand
// for INSTANCE.NAME in the system: shared and bound ones, with the System names they stand for.
std::map<std::string, std::string> NamesNotQualified(const Component& comp) {
  std::map<std::string, std::string> out;
  const auto note = [&](const std::string& declared, const std::string& in_system) {
    if (!declared.empty() && in_system != comp.instance + "." + declared) {
      out[declared] = in_system;
    }
  };
  // Renaming keeps slots and transitions in order (System::AddComponent).
  for (int s = 0; s < comp.source.symbols().size(); ++s) {
    note(comp.source.symbols()[s].name, comp.automaton.symbols()[s].name);
  }
  for (size_t t = 0; t < comp.source.transitions().size(); ++t) {
    note(comp.source.transitions()[t].label, comp.automaton.transitions()[t].label);
  }
  return out;
}

// The label of the one cluster of the instances `members` (two or more) of one automaton: the
// instances and the automaton, how its names are read in each instance, the names every
// instance shares and, per instance, those bound to other names.
std::string MergedClusterLabel(std::span<const Component> components,
                               const std::vector<int>& members) {
  std::string instances, qualified;
  std::vector<std::map<std::string, std::string>> others;
  for (const int m : members) {
    const Component& comp = components[static_cast<size_t>(m)];
    instances += (instances.empty() ? "" : ", ") + comp.instance;
    qualified += (qualified.empty() ? "" : ", ") + comp.instance + ".x";
    others.push_back(NamesNotQualified(comp));
  }
  const Component& first = components[static_cast<size_t>(members.front())];
  std::string text =
      instances + ": " + first.source.name() + "\n" + "x stands for " + qualified + "\n";
  std::string shared;
  std::set<std::string> shared_names;
  for (const auto& [key, in_system] : others.front()) {
    const std::string& name = key;  // Clang 14 cannot capture a structured binding.
    const auto kept = [&](const auto& o) { return o.count(name) > 0 && o.at(name) == name; };
    if (in_system == name && std::all_of(others.begin(), others.end(), kept)) {
      shared += (shared.empty() ? "" : ", ") + name;
      shared_names.insert(name);
    }
  }
  if (!shared.empty()) text += "shared: " + shared + "\n";
  for (size_t k = 0; k < members.size(); ++k) {
    std::string bound;
    for (const auto& [name, in_system] : others[k]) {
      if (shared_names.count(name) == 0) {
        bound += (bound.empty() ? "" : ", ") + name + " = " + in_system;
      }
    }
    if (!bound.empty()) {
      text += components[static_cast<size_t>(members[k])].instance + ": " + bound + "\n";
    }
  }
  return text;
}

}  // namespace

std::string WriteDot(const System& system, const DotOptions& options) {
  std::ostringstream out;
  const auto components = system.components();
  // The newer ranking keeps a large graph's ranks compact, and clusters inside clusters
  // (components, then groups) need it; it spreads the groups of one automaton, though.
  const bool newrank = !options.group || (!options.product && components.size() > 1);
  out << "digraph \"" << Escape(system.name()) << "\" {\n"
      << "  rankdir=LR;\n"
      << (newrank ? "  newrank=true;\n" : "") << "  node [fontname=\"Helvetica\", fontsize=10];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=9];\n";
  if (options.product) {
    // Product modes shown as the simulator and the verifier name them: "P1.idle|P2.req".
    std::vector<std::vector<int>> tuples;
    const Automaton a = system.Product(options.max_product_modes, &tuples);
    std::vector<std::string> names;
    for (const std::vector<int>& tuple : tuples) names.push_back(QualifiedModeName(system, tuple));
    WriteAutomaton(a, a, names, "", "  ", options, out);
  } else if (components.size() == 1) {
    WriteAutomaton(components[0].automaton, components[0].automaton, {}, "", "  ", options, out);
  } else {
    for (const std::vector<int>& members : ClusterMembers(components, options.merge_instances)) {
      const int c = members.front();
      const Component& comp = components[static_cast<size_t>(c)];
      const bool merged = members.size() > 1;
      const std::string label =
          merged
              ? Escape(Wrapped(MergedClusterLabel(components, members), options.wrap_width))
              : Escape((comp.instance.empty() ? "" : comp.instance + ": ") + comp.automaton.name());
      out << "  subgraph cluster_" << c << " {\n    label=\"" << label << "\";\n";
      WriteAutomaton(merged ? comp.source : comp.automaton, comp.automaton, {},
                     "c" + std::to_string(c) + "_", "    ", options, out);
      out << "  }\n";
    }
  }
  out << "}\n";
  return out.str();
}

}  // namespace hybrid
