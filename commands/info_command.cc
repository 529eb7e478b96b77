#include "commands/info_command.h"

#include <sstream>
#include <vector>

#include "automaton/rectangular_rate.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/mode_graph.h"
#include "hybrid/automaton/printer.h"

namespace hybrid::cli {
namespace {

using hybrid::Automaton;
using hybrid::ModeGraph;
using hybrid::ModeId;
using json = nlohmann::ordered_json;

json ModeList(const System& s, int c, const std::vector<ModeId>& modes) {
  json out = json::array();
  for (ModeId m : modes) out.push_back(s.QualifiedModeName(c, m));
  return out;
}

json PropertyJson(const hybrid::Property& p) {
  json j = {{"name", p.name},
            {"kind", std::string(hybrid::KindKeyword(p.kind))},
            {"predicate", p.predicate.ToString()}};
  if (p.horizon) j["within"] = *p.horizon;
  return j;
}

json ScenarioJson(const hybrid::Scenario& sc, const hybrid::SymbolTable& symbols) {
  json inputs = json::array();
  for (const auto& sig : sc.inputs) {
    json points = json::array();
    for (const auto& [t, v] : sig.points) points.push_back({t, v});
    inputs.push_back({{"input", symbols[sig.slot].name},
                      {"shape", sig.shape == hybrid::InputSignal::Shape::kStep ? "step" : "linear"},
                      {"points", points},
                      {"signal", hybrid::SignalText(sig)}});
  }
  return {{"until", sc.until}, {"inputs", inputs}};
}

json VariablesJson(const Automaton& a, const std::vector<double>& env) {
  const auto& sym = a.symbols();
  json variables = json::array();
  for (const auto& v : a.variables()) {
    json j = {{"name", sym[v.slot].name}, {"unit", sym[v.slot].unit}};
    if (v.domain) j["domain"] = {v.domain->lo.Evaluate(env), v.domain->hi.Evaluate(env)};
    variables.push_back(j);
  }
  return variables;
}

json InputsJson(const Automaton& a, const std::vector<double>& env) {
  const auto& sym = a.symbols();
  json inputs = json::array();
  for (const auto& in : a.inputs()) {
    inputs.push_back({{"name", sym[in.slot].name},
                      {"unit", sym[in.slot].unit},
                      {"bounds", {in.bounds.lo.Evaluate(env), in.bounds.hi.Evaluate(env)}}});
  }
  return inputs;
}

json ParametersJson(const Automaton& a, const std::vector<double>& env) {
  const auto& sym = a.symbols();
  json parameters = json::array();
  for (const auto& [slot, value] : a.parameters()) {
    json p = {{"name", sym[slot].name},
              {"unit", sym[slot].unit},
              {"value", env[slot]},
              {"expression", value.ToString()}};
    if (const auto range = a.ParameterRange(slot)) {
      p["range"] = {range->lo.Evaluate(env), range->hi.Evaluate(env)};
    }
    parameters.push_back(p);
  }
  return parameters;
}

json ModesJson(const Automaton& a) {
  const auto& sym = a.symbols();
  json modes = json::array();
  for (const auto& m : a.modes()) {
    json flows = json::object();
    for (const auto& [slot, rhs] : m.flows) {
      const std::optional<Range> rate = AsRectangularFlow(rhs);
      flows[sym[slot].name] = rate ? FlowText(rhs).substr(1) : rhs.ToString();
    }
    json values = json::object();
    for (const auto& [slot, v] : m.discrete_values) values[sym[slot].name] = v;
    modes.push_back({{"name", m.name},
                     {"discrete", values},
                     {"flows", flows},
                     {"invariant", m.invariant.ToString()}});
  }
  return modes;
}

json TransitionsJson(const Automaton& a) {
  const auto& sym = a.symbols();
  json transitions = json::array();
  for (const auto& t : a.transitions()) {
    json resets = json::object();
    for (const auto& r : t.resets) resets[sym[r.slot].name] = r.value.ToString();
    transitions.push_back({{"name", t.name},
                           {"source", a.mode(t.source).name},
                           {"target", a.mode(t.target).name},
                           {"label", t.label},
                           {"guard", t.guard.ToString()},
                           {"resets", resets},
                           {"urgency", t.urgency == hybrid::Urgency::kLazy ? "lazy" : "urgent"}});
  }
  return transitions;
}

json InitialStatesJson(const Automaton& a, const std::vector<double>& env) {
  const auto& sym = a.symbols();
  json initial = json::array();
  for (const auto& init : a.initial_states()) {
    json values = json::object();
    for (const auto& v : init.values) {
      values[sym[v.slot].name] = v.is_point
                                     ? json(v.range.lo.Evaluate(env))
                                     : json({v.range.lo.Evaluate(env), v.range.hi.Evaluate(env)});
    }
    initial.push_back({{"mode", a.mode(init.mode).name}, {"values", values}});
  }
  return initial;
}

// Component c of `s` as `hybrid info --json` reports it; its warnings are also appended to
// `warnings` (qualified by the instance name).
json ComponentJson(const System& s, int c, json& warnings) {
  const auto& comp = s.components()[c];
  const Automaton& a = comp.automaton;
  const auto& sym = a.symbols();
  const std::vector<double> env = a.ParameterEnvironment();
  json discrete = json::array();
  for (int d : a.discrete_variables()) discrete.push_back(sym[d].name);
  const ModeGraph graph(a);
  json sccs = json::array();
  for (const auto& scc : graph.StronglyConnectedComponents()) {
    if (scc.size() > 1) sccs.push_back(ModeList(s, c, scc));
  }
  json component_warnings = json::array();
  for (const std::string& w : graph.Warnings()) {
    const std::string qualified = comp.instance.empty() ? w : comp.instance + ": " + w;
    component_warnings.push_back(qualified);
    warnings.push_back(qualified);
  }
  json properties = json::array();
  for (const auto& p : a.properties()) properties.push_back(PropertyJson(p));
  json binds = json::object();
  for (const auto& [from, to] : comp.binds) binds[from] = to;
  return {{"instance", comp.instance},
          {"automaton", a.name()},
          {"binds", binds},
          {"variables", VariablesJson(a, env)},
          {"discrete_variables", discrete},
          {"inputs", InputsJson(a, env)},
          {"parameters", ParametersJson(a, env)},
          {"modes", ModesJson(a)},
          {"transitions", TransitionsJson(a)},
          {"initial_states", InitialStatesJson(a, env)},
          {"reachable_modes", ModeList(s, c, graph.ReachableModes())},
          {"unreachable_modes", ModeList(s, c, graph.UnreachableModes())},
          {"terminal_modes", ModeList(s, c, graph.TerminalModes())},
          {"cycles", sccs},
          {"properties", properties},
          {"warnings", component_warnings}};
}

}  // namespace

json InfoJson(const System& s, const std::string& file) {
  json components = json::array();
  json warnings = json::array();
  for (int c = 0; c < static_cast<int>(s.components().size()); ++c) {
    components.push_back(ComponentJson(s, c, warnings));
  }
  json properties = json::array();
  for (const auto& p : s.properties()) properties.push_back(PropertyJson(p));
  json shared = json::array();
  for (const auto& n : s.shared()) shared.push_back(n);
  json out = {{"file", file},
              {"name", s.name()},
              {"shared", shared},
              {"components", components},
              {"properties", properties},
              {"scenario", s.scenario() ? ScenarioJson(*s.scenario(), s.symbols()) : json()},
              {"warnings", warnings}};
  return out;
}

namespace {

std::string Join(const json& array, const std::string& sep = ", ") {
  std::string out;
  for (size_t i = 0; i < array.size(); ++i) {
    out +=
        (i > 0 ? sep : "") + (array[i].is_string() ? array[i].get<std::string>() : array[i].dump());
  }
  return out;
}

// The analysis of one component, as comments: its modes, which of them the transition graph
// reaches, which cannot be left, and its cycles.
void ComponentAnalysisText(const json& c, std::ostringstream& out) {
  const std::string instance = c["instance"].get<std::string>();
  const std::string automaton = c["automaton"].get<std::string>();
  out << "# " << (instance.empty() ? "automaton " + automaton : instance + " (" + automaton + ")")
      << "\n";
  json names = json::array();
  for (const auto& m : c["modes"]) names.push_back(m["name"]);
  out << "#   modes (" << names.size() << "): " << Join(names) << "\n";
  out << "#   reachable modes (" << c["reachable_modes"].size() << " of " << names.size()
      << "): " << Join(c["reachable_modes"]) << "\n";
  if (!c["unreachable_modes"].empty()) {
    out << "#   unreachable modes: " << Join(c["unreachable_modes"]) << "\n";
  }
  out << "#   terminal modes: "
      << (c["terminal_modes"].empty() ? "none" : Join(c["terminal_modes"])) << "\n";
  out << "#   cycles (strongly connected components with more than one mode): "
      << c["cycles"].size() << "\n";
}

// The scenario as options of `hybrid simulate` (--until and one --input per signal).
std::string ScenarioOptions(const json& scenario) {
  std::string text = "--until " + FormatNumber(scenario["until"].get<double>());
  for (const auto& in : scenario["inputs"]) {
    text +=
        " --input '" + in["input"].get<std::string>() + "=" + in["signal"].get<std::string>() + "'";
  }
  return text;
}

}  // namespace

std::string InfoText(const json& info, const System& system) {
  std::ostringstream out;
  out << "# model " << info["name"].get<std::string>() << " (" << info["file"].get<std::string>()
      << ")\n"
      << "# Below: the model as the language writes it (it parses back to the same model), then\n"
      << "# what the analysis of its mode graphs found, as comments.\n\n"
      << PrintSystem(system) << "\n# analysis\n";
  if (!info["shared"].empty()) out << "# shared variables: " << Join(info["shared"]) << "\n";
  for (const auto& c : info["components"]) ComponentAnalysisText(c, out);
  if (!info["scenario"].is_null()) {
    out << "# the scenario on the command line: hybrid simulate MODEL "
        << ScenarioOptions(info["scenario"]) << "\n";
  }
  out << "# warnings: "
      << (info["warnings"].empty() ? "none" : std::to_string(info["warnings"].size())) << "\n";
  for (const auto& w : info["warnings"]) out << "#   warning: " << w.get<std::string>() << "\n";
  return out.str();
}

}  // namespace hybrid::cli
