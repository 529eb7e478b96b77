#include "hybrid/automaton/dot_writer.h"

#include <map>
#include <span>
#include <sstream>
#include <string>
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

// The modes of `a`, one node each, in clusters by options.group (when set).
// `names`: the modes' names to show, by id (empty: their own names).
void WriteModes(const Automaton& a, std::span<const std::string> names, const std::string& prefix,
                const std::string& indent, const DotOptions& options, std::ostream& out) {
  std::map<std::string, std::vector<int>> groups;  // by name: one cluster each, sorted
  for (int m = 0; m < a.num_modes(); ++m) {
    groups[options.group ? options.group(a, a.modes()[m]) : ""].push_back(m);
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
      const std::string label = options.compact ? shown : ModeLabel(a, mode, shown);
      out << inner << prefix << "m" << m << " [shape=box, style=rounded, label=\"" << Escape(label)
          << "\"];\n";
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

void WriteAutomaton(const Automaton& a, std::span<const std::string> names,
                    const std::string& prefix, const std::string& indent, const DotOptions& options,
                    std::ostream& out) {
  WriteModes(a, names, prefix, indent, options, out);
  for (size_t i = 0; i < a.initial_states().size(); ++i) {
    const InitialState& s = a.initial_states()[i];
    out << indent << prefix << "init" << i << " [shape=point, width=0.12];\n";
    out << indent << prefix << "init" << i << " -> " << prefix << "m" << s.mode.value()
        << " [label=\"" << (options.compact ? "" : Escape(InitLabel(a, s))) << "\"];\n";
  }
  for (const Transition& t : a.transitions()) {
    const std::string label = options.compact ? t.label : TransitionLabel(a, t);
    out << indent << prefix << "m" << t.source.value() << " -> " << prefix << "m"
        << t.target.value() << " [label=\"" << Escape(label) << "\"";
    if (t.urgency == Urgency::kLazy) out << ", style=dashed";
    out << "];\n";
  }
}

}  // namespace

std::string WriteDot(const System& system, const DotOptions& options) {
  std::ostringstream out;
  out << "digraph \"" << Escape(system.name()) << "\" {\n"
      << "  rankdir=LR;\n"
      // Clusters inside clusters (components, then groups) need the newer ranking.
      << (options.group && !options.product && system.components().size() > 1 ? "  newrank=true;\n"
                                                                              : "")
      << "  node [fontname=\"Helvetica\", fontsize=10];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=9];\n";
  const auto components = system.components();
  if (options.product) {
    // Product modes shown as the simulator and the verifier name them: "P1.idle|P2.req".
    std::vector<std::vector<int>> tuples;
    const Automaton a = system.Product(options.max_product_modes, &tuples);
    std::vector<std::string> names;
    for (const std::vector<int>& tuple : tuples) names.push_back(QualifiedModeName(system, tuple));
    WriteAutomaton(a, names, "", "  ", options, out);
  } else if (components.size() == 1) {
    WriteAutomaton(components[0].automaton, {}, "", "  ", options, out);
  } else {
    for (size_t c = 0; c < components.size(); ++c) {
      const Component& comp = components[c];
      out << "  subgraph cluster_" << c << " {\n    label=\""
          << Escape((comp.instance.empty() ? "" : comp.instance + ": ") + comp.automaton.name())
          << "\";\n";
      WriteAutomaton(comp.automaton, {}, "c" + std::to_string(c) + "_", "    ", options, out);
      out << "  }\n";
    }
  }
  out << "}\n";
  return out.str();
}

}  // namespace hybrid
