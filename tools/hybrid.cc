// The `hybrid` command: inspect, draw (and, in later versions, simulate, check and diagnose)
// hybrid-automaton models written in the model language (docs/model_language.md).
//
// Exit codes (docs/cli.md): 0 success, 1 invalid model or data (parse or validation error,
// reported as FILE:LINE:COL: message), 2 usage error (bad options, named), 3 output error
// (cannot write a file), 4 out of memory or internal error.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "automaton/dot_writer.h"
#include "automaton/mode_graph.h"
#include "automaton/parser.h"
#include "automaton/system.h"
#include "gripper/measured_data.h"
#include "tools/check_command.h"
#include "tools/diagnose_command.h"
#include "tools/gripper_command.h"
#include "tools/options.h"
#include "tools/output.h"
#include "tools/simulate_command.h"
#include "tools/user_message.h"

namespace {

using hybrid::Automaton;
using hybrid::ModeGraph;
using hybrid::ModeId;
using hybrid::System;
using hybrid::cli::AddNumberListOption;
using hybrid::cli::AddNumberOption;
using hybrid::cli::OutputError;
using hybrid::cli::WriteOutput;
using json = nlohmann::ordered_json;

constexpr int kExitModelError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitOutput = 3;
constexpr int kExitInternal = 4;

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
                      {"points", points}});
  }
  return {{"until", sc.until}, {"inputs", inputs}};
}

// Everything `hybrid info` reports, as JSON; the text form is rendered from it.
json Info(const System& s, const std::string& file) {
  json components = json::array();
  json warnings = json::array();
  for (int c = 0; c < static_cast<int>(s.components().size()); ++c) {
    const auto& comp = s.components()[c];
    const Automaton& a = comp.automaton;
    const auto& sym = a.symbols();
    const std::vector<double> env = a.ParameterEnvironment();
    json variables = json::array();
    for (const auto& v : a.variables()) {
      json j = {{"name", sym[v.slot].name}, {"unit", sym[v.slot].unit}};
      if (v.domain) j["domain"] = {v.domain->lo.Evaluate(env), v.domain->hi.Evaluate(env)};
      variables.push_back(j);
    }
    json discrete = json::array();
    for (int d : a.discrete_variables()) discrete.push_back(sym[d].name);
    json inputs = json::array();
    for (const auto& in : a.inputs()) {
      inputs.push_back({{"name", sym[in.slot].name},
                        {"unit", sym[in.slot].unit},
                        {"bounds", {in.bounds.lo.Evaluate(env), in.bounds.hi.Evaluate(env)}}});
    }
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
    json modes = json::array();
    for (const auto& m : a.modes()) {
      json flows = json::object();
      for (const auto& [slot, rhs] : m.flows) flows[sym[slot].name] = rhs.ToString();
      json values = json::object();
      for (const auto& [slot, v] : m.discrete_values) values[sym[slot].name] = v;
      modes.push_back({{"name", m.name},
                       {"discrete", values},
                       {"flows", flows},
                       {"invariant", m.invariant.ToString()}});
    }
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
    components.push_back({{"instance", comp.instance},
                          {"automaton", a.name()},
                          {"variables", variables},
                          {"discrete_variables", discrete},
                          {"inputs", inputs},
                          {"parameters", parameters},
                          {"modes", modes},
                          {"transitions", transitions},
                          {"initial_states", initial},
                          {"reachable_modes", ModeList(s, c, graph.ReachableModes())},
                          {"unreachable_modes", ModeList(s, c, graph.UnreachableModes())},
                          {"terminal_modes", ModeList(s, c, graph.TerminalModes())},
                          {"cycles", sccs},
                          {"properties", properties},
                          {"warnings", component_warnings}});
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

std::string Join(const json& array, const std::string& sep = ", ") {
  std::string out;
  for (size_t i = 0; i < array.size(); ++i) {
    out +=
        (i > 0 ? sep : "") + (array[i].is_string() ? array[i].get<std::string>() : array[i].dump());
  }
  return out;
}

std::string InfoText(const json& info) {
  std::ostringstream out;
  out << "model " << info["name"].get<std::string>() << " (" << info["file"].get<std::string>()
      << ")\n";
  if (!info["shared"].empty()) out << "shared: " << Join(info["shared"]) << "\n";
  for (const auto& c : info["components"]) {
    const std::string instance = c["instance"].get<std::string>();
    out << "\n"
        << (instance.empty() ? "automaton " : "instance " + instance + " = automaton ")
        << c["automaton"].get<std::string>() << "\n";
    out << "  variables (" << c["variables"].size() << "):";
    for (const auto& v : c["variables"]) {
      out << " " << v["name"].get<std::string>();
      if (!v["unit"].get<std::string>().empty()) out << " [" << v["unit"].get<std::string>() << "]";
      if (v.contains("domain")) out << " in " << v["domain"].dump();
      out << ";";
    }
    out << "\n";
    if (!c["discrete_variables"].empty()) {
      out << "  discrete variables (" << c["discrete_variables"].size()
          << "): " << Join(c["discrete_variables"]) << "\n";
    }
    for (const auto& in : c["inputs"]) {
      out << "  input " << in["name"].get<std::string>() << " in " << in["bounds"].dump() << "\n";
    }
    out << "  parameters (" << c["parameters"].size() << "):";
    for (const auto& p : c["parameters"]) {
      out << " " << p["name"].get<std::string>() << " = " << p["value"].dump() << ";";
    }
    out << "\n  modes (" << c["modes"].size() << "): ";
    json names = json::array();
    for (const auto& m : c["modes"]) names.push_back(m["name"]);
    out << Join(names) << "\n";
    out << "  transitions (" << c["transitions"].size() << "):\n";
    for (const auto& t : c["transitions"]) {
      out << "    " << t["name"].get<std::string>() << ": " << t["source"].get<std::string>()
          << " -> " << t["target"].get<std::string>();
      if (!t["label"].get<std::string>().empty())
        out << " [" << t["label"].get<std::string>() << "]";
      out << " when " << t["guard"].get<std::string>();
      if (t["urgency"] == "lazy") out << " (lazy)";
      out << "\n";
    }
    for (const auto& init : c["initial_states"]) {
      out << "  initial: " << init["mode"].get<std::string>() << " " << init["values"].dump()
          << "\n";
    }
    out << "  reachable modes (" << c["reachable_modes"].size() << " of " << c["modes"].size()
        << "): " << Join(c["reachable_modes"]) << "\n";
    out << "  terminal modes: "
        << (c["terminal_modes"].empty() ? "none" : Join(c["terminal_modes"])) << "\n";
    out << "  cycles (strongly connected components with more than one mode): "
        << c["cycles"].size() << "\n";
    for (const auto& p : c["properties"]) {
      out << "  property " << p["name"].get<std::string>() << ": " << p["kind"].get<std::string>()
          << " " << p["predicate"].get<std::string>() << "\n";
    }
  }
  for (const auto& p : info["properties"]) {
    if (info["components"].size() == 1) break;  // single automaton: already listed
    out << "property " << p["name"].get<std::string>() << ": " << p["kind"].get<std::string>()
        << " " << p["predicate"].get<std::string>() << "\n";
  }
  if (!info["scenario"].is_null()) {
    out << "\nscenario: until " << info["scenario"]["until"].dump();
    for (const auto& in : info["scenario"]["inputs"]) {
      out << "; " << in["input"].get<std::string>() << " = " << in["shape"].get<std::string>()
          << in["points"].dump();
    }
    out << "\n";
  }
  out << "\nwarnings: "
      << (info["warnings"].empty() ? "none" : std::to_string(info["warnings"].size())) << "\n";
  for (const auto& w : info["warnings"]) out << "  warning: " << w.get<std::string>() << "\n";
  return out.str();
}

// The message and exit code of an exception from a command (docs/cli.md): a bad option value
// (UsageError) 2; bad input (InputError, ParseError, DataError) 1; an unwritable output 3;
// std::invalid_argument `invalid_code` (1 for a model that fails validation, 2 for a bad option
// value); exhausted memory and anything else 4. Messages never name C++ functions or types
// (tools/user_message.h).
int ExitFor(std::exception_ptr error, const std::string& prefix, int invalid_code) {
  using hybrid::cli::UserMessage;
  try {
    std::rethrow_exception(error);
  } catch (const hybrid::cli::UsageError& e) {
    std::cerr << "hybrid: " << UserMessage(e.what()) << "\n";
    return kExitUsage;
  } catch (const hybrid::cli::InputError& e) {
    std::cerr << prefix << ": " << UserMessage(e.what()) << "\n";
    return kExitModelError;
  } catch (const hybrid::ParseError& e) {
    std::cerr << UserMessage(e.what()) << "\n";
    return kExitModelError;
  } catch (const hybrid::DataError& e) {
    std::cerr << UserMessage(e.what()) << "\n";
    return kExitModelError;
  } catch (const OutputError& e) {
    std::cerr << "hybrid: " << UserMessage(e.what()) << "\n";
    return kExitOutput;
  } catch (const std::bad_alloc&) {
    std::cerr << "hybrid: out of memory: " << prefix
              << " needs more memory than the system could give; make the problem smaller (a "
                 "shorter horizon, fewer samples, runs or modes)\n";
  } catch (const std::length_error&) {
    std::cerr << "hybrid: out of memory: " << prefix
              << " asked for a block of memory larger than any the system can give; make the "
                 "problem smaller\n";
  } catch (const std::invalid_argument& e) {
    std::cerr << prefix << ": " << UserMessage(e.what()) << "\n";
    return invalid_code;
  } catch (const std::exception& e) {
    const std::string what = UserMessage(e.what());
    std::cerr << "hybrid: internal error"
              << (hybrid::cli::NamesCppInternals(what) ? std::string() : ": " + what)
              << " (a bug: please report it with the command that caused it)\n";
  } catch (...) {
    std::cerr << "hybrid: internal error (a bug: please report it with the command that caused "
                 "it)\n";
  }
  return kExitInternal;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hybrid: declare, inspect and draw hybrid automata (see docs/cli.md)", "hybrid"};
  app.footer(
      "Exit codes: 0 success; 1 invalid model or data (FILE:LINE:COL: message on stderr); 2 usage "
      "error (a bad option value, named); 3 cannot write output; 4 out of memory or internal "
      "error; 5 simulation stopped early; 6 check: a property violated; 7 check: a verdict "
      "unknown. Numbers, output files and limits: docs/cli.md.");
  app.require_subcommand(1);
  app.set_version_flag("--version", "hybrid 0.1.0");

  std::string model;
  bool as_json = false;
  auto* info = app.add_subcommand("info",
                                  "Summarise a model: variables, modes, transitions, "
                                  "reachable modes, cycles, warnings");
  info->add_option("MODEL", model, "Model file (.ha)")->required();
  info->add_flag("--json", as_json, "Machine-readable output");

  std::string output;
  bool product = false;
  auto* dot = app.add_subcommand("dot",
                                 "Write the mode graph in Graphviz DOT (render with "
                                 "`dot -Tsvg`)");
  dot->add_option("MODEL", model, "Model file (.ha)")->required();
  dot->add_option("-o,--output", output, "Output file (default: standard output)");
  dot->add_flag("--product", product,
                "Draw a composed model as its product automaton instead of one cluster per "
                "component");

  hybrid::cli::SimulateArgs sim_args;
  auto* simulate = app.add_subcommand(
      "simulate", "Simulate a model with exact event location (CVODE); default: its scenario");
  simulate->add_option("MODEL", sim_args.model, "Model file (.ha)")->required();
  simulate->add_option("--input", sim_args.inputs,
                       "NAME=SIGNAL, SIGNAL a number, step(t: v, ...) or linear(t: v, ...); "
                       "repeatable; overrides the scenario's signal for NAME");
  simulate->add_option("--set", sim_args.parameters,
                       "NAME=VALUE: give parameter NAME the value VALUE (e.g. gob1=80 for the "
                       "finger; A.gob1 in a system); repeatable");
  simulate->add_option("--input-csv", sim_args.input_csv,
                       "CSV with a 'time' column and one column per input");
  simulate->add_option("--csv-shape", sim_args.csv_shape,
                       "How CSV rows are joined: step (default) or linear");
  AddNumberOption(simulate, "--until", &sim_args.until,
                  "Horizon (default: the scenario's 'until')");
  AddNumberOption(simulate, "--sample", &sim_args.sample,
                  "Also record the state every DT (default: only the start, the end and "
                  "both sides of each event)");
  simulate->add_option("--out", sim_args.out, "Trajectory CSV: time, kind, mode, variables");
  simulate->add_option("--events", sim_args.events, "Event log CSV");
  simulate->add_flag("--json", sim_args.json, "JSON summary with every event on standard output");

  hybrid::cli::CheckArgs check_args;
  auto* check = app.add_subcommand(
      "check",
      "Prove a model's properties for every input (--method prove: SMT bounded model checking "
      "and k-induction) or search for counterexamples (--method sample); every trace found is "
      "replayed by the simulator");
  check->add_option("MODEL", check_args.model, "Model file (.ha)")->required();
  check->add_option("--property", check_args.properties,
                    "Check only this property (repeatable; default: every declared property, "
                    "components' ones named INSTANCE.NAME)");
  check->add_option("--method", check_args.method, "prove or sample")->capture_default_str();
  check->add_flag("--json", check_args.json, "Machine-readable output");
  check->add_flag("--modes", check_args.modes,
                  "Also report which modes (discrete states) some run reaches");
  AddNumberOption(check, "--depth", &check_args.depth,
                  "prove: longest counterexample or witness searched, in steps (flow segments "
                  "and jumps)");
  AddNumberOption(check, "--induction", &check_args.induction, "prove: largest k of k-induction");
  AddNumberOption(check, "--budget", &check_args.budget,
                  "prove: one solver budget for the whole command (properties, then --modes), "
                  "in budget seconds of Z3 resource units (docs/verification.md)");
  AddNumberOption(check, "--runs", &check_args.runs, "sample: random runs per property");
  AddNumberOption(check, "--seed", &check_args.seed, "sample: random seed");

  // The gripper (gripper/): closed form, objects by geometry, the hand.
  const std::string default_finger = std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha";
  const std::string default_hand = std::string(HYBRID_SOURCE_DIR) + "/spec/hand.ha";
  hybrid::cli::FingerArgs finger_args;
  finger_args.model = default_finger;
  auto* finger = app.add_subcommand(
      "finger",
      "One Robotiq finger, closed form (report section 4): joint angles at motor position G, "
      "against objects given by contact positions or by geometry");
  AddNumberOption(finger, "--g", &finger_args.g, "Motor position in [0, 255]");
  for (int i = 0; i < 3; ++i) {
    AddNumberOption(finger, "--gob" + std::to_string(i + 1), &finger_args.gob[i],
                    "Motor position where link " + std::to_string(i + 1) +
                        " is blocked by an object (the report's g_ob)");
  }
  finger->add_option("--object", finger_args.objects,
                     "An object in the finger plane (metres; x towards the palm centre, y along "
                     "the open finger, origin at joint 1): circle:X,Y,R or "
                     "segment:X1,Y1,X2,Y2[,R]; repeatable");
  finger->add_flag("--json", finger_args.json, "Machine-readable output");
  finger->add_option("--draw", finger_args.draw, "Write an SVG drawing of the finger (see --at)");
  AddNumberListOption(finger, "--at", &finger_args.draw_at,
                      "Motor positions drawn by --draw (default 0,30,70,110,150,180,210,255)");
  finger->add_option("--plot", finger_args.plot,
                     "Write an SVG plot of theta1..3 against g (as the report's figure 5.4)");
  finger->add_flag("--simulate", finger_args.simulate,
                   "Also simulate the finger automaton closing (u = 1 to g = 255) and compare it "
                   "with the closed form (exit 5 if they differ by more than 1e-6 degrees)");
  finger->add_option("--model", finger_args.model, "Finger automaton for --simulate")
      ->capture_default_str();

  hybrid::cli::HandArgs hand_args;
  hand_args.model = default_hand;
  auto* hand = app.add_subcommand(
      "hand", "The three-finger hand closing on objects: fingers A, B, C and the spread modes");
  hand->add_option("--object", hand_args.objects,
                   "An object in the palm's x-y plane, extruded across the hand (metres; x from "
                   "finger A towards B and C, y the palm normal, origin between the fingers at "
                   "the height of joint 1): circle:X,Y,R or segment:X1,Y1,X2,Y2[,R]; repeatable");
  hand->add_option("--mode", hand_args.mode, "Operating mode: basic, wide, pinch or scissor")
      ->capture_default_str();
  AddNumberOption(hand, "--spread", &hand_args.spread,
                  "Spread motor position in [0, 255] (overrides --mode)");
  AddNumberOption(hand, "--g", &hand_args.g, "One motor command for all fingers, in [0, 255]");
  AddNumberOption(hand, "--g-a", &hand_args.g_a,
                  "Motor command of finger A (one command per finger)");
  AddNumberOption(hand, "--g-b", &hand_args.g_b, "Motor command of finger B");
  AddNumberOption(hand, "--g-c", &hand_args.g_c, "Motor command of finger C");
  hand->add_flag("--json", hand_args.json, "Machine-readable output");
  hand->add_option("--draw", hand_args.draw, "Write an SVG drawing of the hand (see --at)");
  AddNumberListOption(hand, "--at", &hand_args.draw_at,
                      "Motor positions drawn by --draw (default 0,30,70,110,150,180,210,255)");
  hand->add_flag("--simulate", hand_args.simulate,
                 "Also simulate the composed finger automata and compare with the closed form");
  hand->add_option("--model", hand_args.model, "Hand model for --simulate")->capture_default_str();

  hybrid::cli::DiagnoseArgs diagnose_args;
  diagnose_args.model = default_finger;
  auto* diagnose = app.add_subcommand(
      "diagnose",
      "Compare measured finger data with the model: residuals per joint, mode and direction, "
      "the physical cause (backlash, motor_offset, joint_range, sensor_bias, compliance, "
      "theta3_law, none or unexplained), an extended model and its held-out gain");
  diagnose
      ->add_option("DATA", diagnose_args.data,
                   "CSV: run,g,theta1,theta2,theta3[,gob,contact_link] (docs/diagnosis.md)")
      ->required();
  diagnose->add_option("--model", diagnose_args.model, "Finger automaton")->capture_default_str();
  diagnose->add_flag("--json", diagnose_args.json, "Machine-readable output");
  diagnose->add_option("--out-model", diagnose_args.out_model,
                       "Write the extended model (accepted by simulate, dot and check)");
  diagnose->add_option("--report", diagnose_args.report,
                       "Write diagnosis.json and SVG plots (measured, baseline, extended) here");
  AddNumberOption(diagnose, "--significance", &diagnose_args.significance,
                  "Held-out gain (chi-square units) needed to name a cause");
  AddNumberOption(diagnose, "--threads", &diagnose_args.threads, "Worker threads");

  hybrid::cli::SynthesizeArgs synth_args;
  synth_args.model = default_finger;
  auto* synthesize = app.add_subcommand(
      "synthesize",
      "Write SYNTHETIC finger data (the model plus hidden effects, the report's noise and "
      "outliers) in the CSV format of `hybrid diagnose`");
  synthesize
      ->add_option("--effect", synth_args.effects,
                   "NAME=VALUE: a hidden effect, e.g. backlash=6, theta3_bias=2.5, "
                   "ripple_amplitude=3; repeatable")
      ->take_all();
  AddNumberOption(synthesize, "--seed", &synth_args.seed, "Random seed");
  AddNumberOption(synthesize, "--free-runs", &synth_args.free_runs, "Runs without an object");
  AddNumberOption(synthesize, "--samples", &synth_args.samples, "Samples per run (even)");
  synthesize->add_option("--model", synth_args.model, "Finger automaton")->capture_default_str();
  synthesize->add_option("-o,--out", synth_args.out, "Output CSV (default: standard output)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }

  if (finger->parsed() || hand->parsed()) {
    const std::string name = finger->parsed() ? "hybrid finger" : "hybrid hand";
    try {
      return finger->parsed() ? hybrid::cli::RunFinger(finger_args)
                              : hybrid::cli::RunHand(hand_args);
    } catch (...) {
      return ExitFor(std::current_exception(), name, kExitUsage);
    }
  }

  if (diagnose->parsed() || synthesize->parsed()) {
    // Bad data (DataError) and bad models (ParseError) exit 1; a bad option value 2.
    try {
      return diagnose->parsed() ? hybrid::cli::RunDiagnose(diagnose_args)
                                : hybrid::cli::RunSynthesize(synth_args);
    } catch (...) {
      return ExitFor(std::current_exception(),
                     diagnose->parsed() ? "hybrid diagnose" : "hybrid synthesize", kExitUsage);
    }
  }

  if (check->parsed()) {
    // The model is validated by the parser (ParseError: exit 1); std::invalid_argument here is
    // a bad option value (exit 2).
    try {
      return hybrid::cli::RunCheck(check_args);
    } catch (...) {
      return ExitFor(std::current_exception(), "hybrid check", kExitUsage);
    }
  }

  try {
    if (simulate->parsed()) {
      model = sim_args.model;
      return hybrid::cli::RunSimulate(sim_args);
    }
    if (dot->parsed()) {
      hybrid::cli::CheckDistinctFiles({{"MODEL", model}}, {{"-o", output}});
      hybrid::cli::CheckOutputPlaces({{"-o", output}});
    }
    const System system = hybrid::ParseModelFile(model);
    if (info->parsed()) {
      const json report = Info(system, model);
      for (const auto& w : report["warnings"]) {
        if (!as_json) continue;
        std::cerr << model << ": warning: " << w.get<std::string>() << "\n";
      }
      // The file name may be any bytes: replace invalid UTF-8 rather than throw.
      WriteOutput("-", as_json ? report.dump(2, ' ', false, json::error_handler_t::replace) + "\n"
                               : InfoText(report));
    } else if (dot->parsed()) {
      std::string text;
      try {
        text = hybrid::WriteDot(system, {.product = product});
      } catch (const std::invalid_argument& e) {
        std::cerr << model << ": cannot draw the product: " << hybrid::cli::UserMessage(e.what())
                  << " (omit --product to draw one cluster per component)\n";
        return kExitModelError;
      }
      WriteOutput(output, text);
    }
  } catch (...) {
    return ExitFor(std::current_exception(), model, kExitModelError);
  }
  return 0;
}
