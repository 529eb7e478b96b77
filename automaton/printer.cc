#include "hybrid/automaton/printer.h"

#include <cmath>
#include <set>
#include <sstream>

#include "automaton/rectangular_rate.h"

namespace hybrid {
namespace {

std::string UnitSuffix(const Symbol& s) { return s.unit.empty() ? "" : " [" + s.unit + "]"; }

std::string RangeText(const Range& r) {
  std::string text = "[";  // appended piece by piece: GCC 12 warns (-Wrestrict) on the + chain
  text += r.lo.ToString();
  text += ", ";
  text += r.hi.ToString();
  text += "]";
  return text;
}

void PrintScenario(const Scenario& scenario, const SymbolTable& symbols, const std::string& indent,
                   std::ostream& out) {
  out << indent << "scenario {\n" << indent << "  until " << FormatNumber(scenario.until) << ";\n";
  for (const InputSignal& s : scenario.inputs) {
    out << indent << "  " << symbols[s.slot].name << " = " << SignalText(s) << ";\n";
  }
  out << indent << "}\n";
}

}  // namespace

std::string SignalText(const InputSignal& s) {
  if (s.shape == InputSignal::Shape::kStep && s.points.size() == 1 && s.points[0].first == 0.0 &&
      !std::signbit(s.points[0].first)) {
    return FormatNumber(s.points[0].second);
  }
  std::string text = s.shape == InputSignal::Shape::kStep ? "step(" : "linear(";
  for (size_t i = 0; i < s.points.size(); ++i) {
    text += i > 0 ? ", " : "";
    text += FormatNumber(s.points[i].first);
    text += ": ";
    text += FormatNumber(s.points[i].second);
  }
  return text + ")";
}

std::string FlowText(const Expression& flow) {
  std::string text = " = ";
  if (const std::optional<Range> rate = AsRectangularFlow(flow)) {
    text = " in ";
    text += RangeText(*rate);
  } else {
    text += flow.ToString();
  }
  return text;
}

namespace {

void PrintProperty(const Property& p, const std::string& indent, std::ostream& out) {
  out << indent << "property " << p.name << ": " << KindKeyword(p.kind) << " "
      << p.predicate.ToString();
  if (p.horizon) out << " within " << FormatNumber(*p.horizon);
  out << ";\n";
}

}  // namespace

namespace {

// The symbol declarations of `a` in slot order (rate inputs are declared by their variables'
// rectangular flows, not here).
void PrintDeclarations(const Automaton& a, std::ostream& out) {
  const SymbolTable& symbols = a.symbols();
  size_t var = 0, input = 0, param = 0;
  for (int s = 0; s < symbols.size(); ++s) {
    const Symbol& sym = symbols[s];
    switch (sym.kind) {
      case SymbolKind::kVariable: {
        const VariableInfo& info = a.variables()[var++];
        out << "  var " << sym.name << UnitSuffix(sym);
        if (info.domain) out << " in " << RangeText(*info.domain);
        out << ";\n";
        break;
      }
      case SymbolKind::kDiscrete:
        out << "  discrete " << sym.name << ";\n";
        break;
      case SymbolKind::kInput:
        if (IsRateInputName(sym.name)) {  // declared by its variable's rectangular flows
          ++input;
          break;
        }
        out << "  input " << sym.name << UnitSuffix(sym) << " in "
            << RangeText(a.inputs()[input++].bounds) << ";\n";
        break;
      case SymbolKind::kParameter: {
        out << "  param " << sym.name << UnitSuffix(sym) << " = "
            << a.parameters()[param++].second.ToString();
        if (const std::optional<Range> range = a.ParameterRange(s)) {
          out << " in " << RangeText(*range);
        }
        out << ";\n";
        break;
      }
    }
  }
}

}  // namespace

std::string PrintAutomaton(const Automaton& a) {
  std::ostringstream out;
  const SymbolTable& symbols = a.symbols();
  out << "automaton " << a.name() << " {\n";
  PrintDeclarations(a, out);
  for (const Mode& m : a.modes()) {
    out << "\n  mode " << m.name;
    if (!m.discrete_values.empty()) {
      out << " (";
      for (size_t i = 0; i < m.discrete_values.size(); ++i) {
        out << (i > 0 ? ", " : "") << symbols[m.discrete_values[i].first].name << " = "
            << m.discrete_values[i].second;
      }
      out << ")";
    }
    out << " {\n";
    for (const auto& [slot, rhs] : m.flows) {
      out << "    " << symbols[slot].name << "'" << FlowText(rhs) << ";\n";
    }
    if (!m.invariant.empty()) out << "    inv " << m.invariant.ToString() << ";\n";
    out << "  }\n";
  }
  for (const Transition& t : a.transitions()) {
    out << "\n  transition " << t.name << ": " << a.mode(t.source).name << " -> "
        << a.mode(t.target).name << " {\n";
    if (!t.guard.empty()) out << "    guard " << t.guard.ToString() << ";\n";
    if (!t.resets.empty()) {
      out << "    reset ";
      for (size_t i = 0; i < t.resets.size(); ++i) {
        out << (i > 0 ? ", " : "") << symbols[t.resets[i].slot].name
            << " := " << t.resets[i].value.ToString();
      }
      out << ";\n";
    }
    if (!t.label.empty()) out << "    label " << t.label << ";\n";
    if (t.urgency == Urgency::kLazy) out << "    lazy;\n";
    out << "  }\n";
  }
  if (!a.declared_labels().empty()) {  // labels in the alphabet that no transition takes
    out << "  label ";
    bool first = true;
    for (const std::string& label : a.declared_labels()) {
      out << (first ? "" : ", ") << label;
      first = false;
    }
    out << ";\n";
  }
  for (const InitialState& init : a.initial_states()) {
    out << "\n  init " << a.mode(init.mode).name << " {";
    for (const InitialValue& v : init.values) {
      out << " " << symbols[v.slot].name;
      if (v.is_point) {
        out << " = " << v.range.lo.ToString() << ";";
      } else {
        out << " in " << RangeText(v.range) << ";";
      }
    }
    out << " }\n";
  }
  if (a.scenario()) {
    out << "\n";
    PrintScenario(*a.scenario(), symbols, "  ", out);
  }
  if (!a.properties().empty()) out << "\n";
  for (const Property& p : a.properties()) PrintProperty(p, "  ", out);
  out << "}\n";
  return out.str();
}

std::string PrintSystem(const System& system) {
  const auto components = system.components();
  if (components.size() == 1 && components[0].instance.empty() &&
      components[0].source.name() == system.name() && system.shared().empty() &&
      components[0].binds.empty()) {
    return PrintAutomaton(components[0].source);
  }
  std::ostringstream out;
  std::set<std::string> printed;
  for (const Component& c : components) {
    if (printed.insert(c.source.name()).second) out << PrintAutomaton(c.source) << "\n";
  }
  out << "system " << system.name() << " {\n";
  if (!system.shared().empty()) {
    out << "  share ";
    bool first = true;
    for (const std::string& s : system.shared()) {
      out << (first ? "" : ", ") << s;
      first = false;
    }
    out << ";\n";
  }
  for (const Component& c : components) {
    out << "  instance ";
    if (!c.instance.empty()) out << c.instance << " = ";
    out << c.source.name();
    if (c.binds.empty()) {
      out << ";\n";
      continue;
    }
    out << " {";
    for (const auto& [from, to] : c.binds) out << " " << from << " = " << to << ";";
    out << " }\n";
  }
  if (system.scenario()) PrintScenario(*system.scenario(), system.symbols(), "  ", out);
  for (const Property& p : system.properties()) PrintProperty(p, "  ", out);
  out << "}\n";
  return out.str();
}

}  // namespace hybrid
