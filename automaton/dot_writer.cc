#include "automaton/dot_writer.h"

#include <sstream>

#include "automaton/printer.h"

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

std::string ModeLabel(const Automaton& a, const Mode& m) {
  std::string text = m.name;
  if (!m.discrete_values.empty()) {
    text += " (";
    for (size_t i = 0; i < m.discrete_values.size(); ++i) {
      text += (i > 0 ? ", " : "") + a.symbols()[m.discrete_values[i].first].name + "=" +
              std::to_string(m.discrete_values[i].second);
    }
    text += ")";
  }
  text += "\n";
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

void WriteAutomaton(const Automaton& a, const std::string& prefix, const std::string& indent,
                    std::ostream& out) {
  for (int m = 0; m < a.num_modes(); ++m) {
    out << indent << prefix << "m" << m << " [shape=box, style=rounded, label=\""
        << Escape(ModeLabel(a, a.modes()[m])) << "\"];\n";
  }
  for (size_t i = 0; i < a.initial_states().size(); ++i) {
    const InitialState& s = a.initial_states()[i];
    out << indent << prefix << "init" << i << " [shape=point, width=0.12];\n";
    out << indent << prefix << "init" << i << " -> " << prefix << "m" << s.mode.value()
        << " [label=\"" << Escape(InitLabel(a, s)) << "\"];\n";
  }
  for (const Transition& t : a.transitions()) {
    out << indent << prefix << "m" << t.source.value() << " -> " << prefix << "m"
        << t.target.value() << " [label=\"" << Escape(TransitionLabel(a, t)) << "\"";
    if (t.urgency == Urgency::kLazy) out << ", style=dashed";
    out << "];\n";
  }
}

}  // namespace

std::string WriteDot(const System& system, const DotOptions& options) {
  std::ostringstream out;
  out << "digraph \"" << Escape(system.name()) << "\" {\n"
      << "  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=10];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=9];\n";
  const auto components = system.components();
  if (options.product || components.size() == 1) {
    const Automaton a =
        options.product ? system.Product(options.max_product_modes) : components[0].automaton;
    WriteAutomaton(a, "", "  ", out);
  } else {
    for (size_t c = 0; c < components.size(); ++c) {
      const Component& comp = components[c];
      out << "  subgraph cluster_" << c << " {\n    label=\""
          << Escape((comp.instance.empty() ? "" : comp.instance + ": ") + comp.automaton.name())
          << "\";\n";
      WriteAutomaton(comp.automaton, "c" + std::to_string(c) + "_", "    ", out);
      out << "  }\n";
    }
  }
  out << "}\n";
  return out.str();
}

}  // namespace hybrid
