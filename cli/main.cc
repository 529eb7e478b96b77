// The `hybrid` program: inspect, draw, import, simulate and check hybrid-automaton models written
// in the model language (docs/model_language.md), and the gripper's commands. The commands are
// the command libraries' (commands/, gripper/commands/); this file parses the command line, the
// only place that names flags (with cli/flag_names.h), and turns what a command returns or
// throws into an exit code (commands/exit_code.h, docs/cli.md "Exit codes"; cli/error_report.h).

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "cli/error_report.h"
#include "cli/options.h"
#include "commands/bundled_files.h"
#include "commands/check_command.h"
#include "commands/closest_name.h"
#include "commands/diagnose_model_command.h"
#include "commands/exit_code.h"
#include "commands/info_command.h"
#include "commands/mode_groups.h"
#include "commands/model_file.h"
#include "commands/output.h"
#include "commands/simulate_command.h"
#include "gripper/commands/diagnose_command.h"
#include "gripper/commands/gripper_command.h"
#include "gripper/commands/phase_groups.h"
#include "hybrid/automaton/dot_writer.h"
#include "hybrid/automaton/log.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/system.h"
#include "hybrid/model_diagnosis/trace_data.h"
#include "hybrid/spaceex/spaceex_import.h"

namespace {

using hybrid::System;
using hybrid::cli::AddNumberListOption;
using hybrid::cli::AddNumberOption;
using hybrid::cli::ExitCode;
using hybrid::cli::WriteOutput;
using json = nlohmann::ordered_json;

constexpr const char* kModelHelp = "Model file (.ha, or a SpaceEx .xml read with its .cfg)";
constexpr const char* kConfigHelp =
    "SpaceEx configuration of a SpaceEx MODEL (.xml), read in place of the .cfg of the same "
    "name: initial states, forbidden set, time-horizon";

// The options of every command, filled by CLI11, and the subcommands that parse them.
struct Commands {
  CLI::App* info = nullptr;
  CLI::App* dot = nullptr;
  CLI::App* import = nullptr;
  CLI::App* simulate = nullptr;
  CLI::App* check = nullptr;
  CLI::App* finger = nullptr;
  CLI::App* hand = nullptr;
  CLI::App* diagnose = nullptr;
  CLI::App* synthesize = nullptr;
  std::string model;  // info, dot and import
  bool as_json = false;
  std::string output;
  std::string config;  // --config: import, info, dot, diagnose
  bool product = false;
  bool compact = false;  // dot
  std::string group_by;  // dot
  hybrid::cli::SimulateArgs simulate_args;
  hybrid::cli::CheckArgs check_args;
  hybrid::cli::FingerArgs finger_args;
  hybrid::cli::HandArgs hand_args;
  hybrid::cli::DiagnoseArgs diagnose_args;
  std::string diagnose_first, diagnose_data;  // MODEL DATA, or DATA alone
  std::vector<std::string> diagnose_noise;    // --noise NAME=SD (any model)
  hybrid::cli::SynthesizeArgs synthesize_args;
  std::string log;  // --log LEVEL: debug, info or warning; empty: no log
};

// `hybrid info` and `hybrid dot`.
void AddModelCommands(CLI::App& app, Commands& c) {
  c.info = app.add_subcommand("info",
                              "Show a model: every declaration in the model language (units, "
                              "ranges, horizons, scenario), then its reachable modes, cycles and "
                              "warnings as comments; --json for the JSON report");
  c.info->add_option("MODEL", c.model, kModelHelp)->required();
  c.info->add_flag("--json", c.as_json, "Machine-readable output");
  c.info->add_option("--config", c.config, kConfigHelp);

  c.dot = app.add_subcommand("dot",
                             "Write the mode graph in Graphviz DOT (render with "
                             "`dot -Tsvg`)");
  c.dot->add_option("MODEL", c.model, kModelHelp)->required();
  c.dot->add_option("-o,--output", c.output, "Output file (default: standard output)");
  c.dot->add_option("--config", c.config, kConfigHelp);
  c.dot->add_flag("--product", c.product,
                  "Draw a composed model as its product automaton instead of one cluster per "
                  "component");
  c.dot->add_flag("--compact", c.compact,
                  "Short labels (mode and transition names only) for a graph that fits a page");
  c.dot->add_option("--group-by", c.group_by,
                    "Cluster the modes: 'phase' (a finger's phases 1, 1', 2, 2', 3, 4) or "
                    "discrete variables V1,V2,...");

  c.import = app.add_subcommand(
      "import",
      "Translate a SpaceEx model (SX XML and its .cfg: initial states, forbidden set) into the "
      "model language (docs/spaceex.md)");
  c.import->add_option("MODEL", c.model, "SpaceEx model (.xml)")->required();
  c.import->add_option("--config", c.config,
                       "SpaceEx configuration (default: MODEL with the extension .cfg, if it "
                       "exists)");
  c.import->add_option("-o,--output", c.output, "Output file (default: standard output)");
}

// `hybrid simulate`.
void AddSimulate(CLI::App& app, Commands& c) {
  hybrid::cli::SimulateArgs& a = c.simulate_args;
  CLI::App* simulate = c.simulate = app.add_subcommand(
      "simulate", "Simulate a model with exact event location (CVODE); default: its scenario");
  simulate->add_option("MODEL", a.model, kModelHelp)->required();
  simulate->add_option("--input", a.inputs,
                       "NAME=SIGNAL, SIGNAL a number, step(t: v, ...) or linear(t: v, ...); "
                       "repeatable; overrides the scenario's signal for NAME");
  simulate->add_option("--set", a.parameters,
                       "NAME=VALUE: give parameter NAME the value VALUE (e.g. gob1=80 for the "
                       "finger; A.gob1 in a system); repeatable");
  simulate->add_option("--init", a.init,
                       "NAME=VALUE: start continuous variable NAME at VALUE in this run (A.x in "
                       "a system); repeatable");
  simulate->add_option("--config", a.config, kConfigHelp);
  simulate->add_option("--input-csv", a.input_csv,
                       "CSV with a 'time' column and one column per input");
  simulate->add_option("--csv-shape", a.csv_shape,
                       "How CSV rows are joined: step (default) or linear");
  AddNumberOption(simulate, "--until", &a.until, "Horizon (default: the scenario's 'until')");
  AddNumberOption(simulate, "--sample", &a.sample,
                  "Also record the state every DT (default: only the start, the end and "
                  "both sides of each event)");
  simulate->add_option("-o,--output,--out", a.out,
                       "Trajectory CSV: time, kind, mode, variables (--out: the old spelling)");
  simulate->add_option("--plot", a.plot,
                       "SVG plot of the run: each variable and input against time, jumps and "
                       "modes marked");
  simulate->add_option("--events", a.events, "Event log CSV");
  simulate->add_flag("--json", a.json, "JSON summary with every event on standard output");
}

// `hybrid check`.
// --quiet and --progress of a long-running command: its progress report on standard error, by
// default while it runs when standard error is a terminal.
void AddProgressOptions(CLI::App* command, hybrid::cli::ProgressMode* mode) {
  using hybrid::cli::ProgressMode;
  *mode = ProgressMode::kAuto;
  CLI::Option* quiet = command->add_flag_callback(
      "--quiet", [mode] { *mode = ProgressMode::kOff; },
      "No progress report on standard error (default: one line while running, when standard "
      "error is a terminal)");
  command
      ->add_flag_callback(
          "--progress", [mode] { *mode = ProgressMode::kOn; },
          "Progress reports on standard error even when it is not a terminal (one line each)")
      ->excludes(quiet);
}

void AddCheck(CLI::App& app, Commands& c) {
  hybrid::cli::CheckArgs& a = c.check_args;
  CLI::App* check = c.check = app.add_subcommand(
      "check",
      "Prove a model's properties for every input (--method reach: exact polyhedral "
      "reachability for linear hybrid automata; --method flowpipe: Taylor flowpipes for affine "
      "and polynomial dynamics; --method prove: SMT bounded model checking and k-induction; "
      "--method auto, the default, tries them in that order and then samples for a "
      "counterexample) or search for counterexamples (--method sample); every trace found is "
      "replayed by the simulator");
  check->add_option("MODEL", a.model, kModelHelp)->required();
  check->add_option("--property", a.properties,
                    "Check only this property (repeatable; default: every declared property, "
                    "components' ones named INSTANCE.NAME)");
  check->add_option("--init", a.init,
                    "NAME=VALUE: check from the initial states with continuous variable NAME at "
                    "VALUE (A.x in a system); repeatable");
  check->add_option("--config", a.config, kConfigHelp);
  check
      ->add_option("--method", a.method,
                   "auto (reach for linear hybrid automata, then flowpipe, prove, and sample for "
                   "counterexamples on what is left), reach (exact polyhedral reachability), "
                   "flowpipe (Taylor flowpipes, affine and polynomial flows), prove (SMT "
                   "k-induction) or sample")
      ->capture_default_str();
  check->add_flag("--json", a.json, "Machine-readable output");
  check->add_flag("--modes", a.modes, "Also report which modes (discrete states) some run reaches");
  AddProgressOptions(check, &a.progress);
  AddNumberOption(check, "--depth", &a.depth,
                  "prove: longest counterexample or witness searched, in steps (flow segments "
                  "and jumps)");
  AddNumberOption(check, "--induction", &a.induction, "prove: largest k of k-induction");
  AddNumberOption(check, "--budget", &a.budget,
                  "prove, reach and flowpipe: each one's budget for the whole command (prove: "
                  "properties, then --modes), in budget seconds (docs/verification.md)");
  AddNumberOption(check, "--runs", &a.runs, "sample: random runs per property");
  AddNumberOption(check, "--order", &a.order, "flowpipe: Taylor order, 1 to 12");
  AddNumberOption(check, "--step", &a.step,
                  "flowpipe: time step (0, the default: automatic, 0.2 divided by the Jacobian's "
                  "norm, rounded down to "
                  "a power of two)");
  check->add_option("--plot-reach", a.plot_reach,
                    "Write an SVG of the flowpipe projected on --axes, with the property bounds "
                    "and the traces found (docs/verification.md)");
  check->add_option("--axes", a.axes, "The two variables of --plot-reach, as X,Y");
  AddNumberOption(check, "--seed", &a.seed, "sample: random seed");
}

// `hybrid finger` (gripper/): the closed form, objects by geometry.
void AddFinger(CLI::App& app, Commands& c) {
  hybrid::cli::FingerArgs& a = c.finger_args;
  CLI::App* finger = c.finger = app.add_subcommand(
      "finger",
      "One Robotiq finger, closed form (report section 4): joint angles at motor position G, "
      "against objects given by contact positions or by geometry");
  AddNumberOption(finger, "--g", &a.g,
                  "Motor position in [0, 255] (default 255, the fully closing command, when "
                  "neither --queries, --g-range, --requests, --draw nor --plot is given)");
  for (int i = 0; i < 3; ++i) {
    AddNumberOption(finger, "--gob" + std::to_string(i + 1), &a.gob[i],
                    "Motor position where link " + std::to_string(i + 1) +
                        " is blocked by an object (the report's g_ob)");
  }
  finger->add_option("--object", a.objects,
                     "An object in the finger plane (metres; x towards the palm centre, y along "
                     "the open finger, origin at joint 1): circle:X,Y,R or "
                     "segment:X1,Y1,X2,Y2[,R]; repeatable");
  AddNumberListOption(finger, "--requests", &a.requests,
                      "A history of position requests R1,R2,... (each in [0, 255]): the settled "
                      "motor position, controller status and angles after each, as the gripper's "
                      "controller drives the motor (it stops where the finger stalls)");
  finger->add_option("--queries", a.queries,
                     "Batch: a file of motor positions (header 'g', one per line); answers one "
                     "CSV row (or JSON record) per position: g, motor, theta1..3, phase, mode");
  finger->add_option("--g-range", a.g_range,
                     "Batch: START:STOP:COUNT, COUNT positions evenly spaced from START to STOP");
  finger->add_option("-o,--output", a.output,
                     "Where a batch's answers go (default: standard output)");
  finger->add_flag("--json", a.json, "Machine-readable output (a batch: a JSON array, else CSV)");
  finger->add_option("--draw", a.draw, "Write an SVG drawing of the finger (see --at)");
  AddNumberListOption(finger, "--at", &a.draw_at,
                      "Motor positions drawn by --draw (default 0,30,70,110,150,180,210,255)");
  finger->add_option("--plot", a.plot,
                     "Write an SVG plot of theta1..3 against g (as the report's figure 5.4)");
  finger->add_option("--data", a.data,
                     "Measured runs (the CSV of `hybrid diagnose`) to overlay on --plot: the runs "
                     "whose object is the finger's (--gobN; free runs without)");
  finger->add_flag("--simulate", a.simulate,
                   "Also simulate the finger automaton closing (u = 1 to g = 255) and compare it "
                   "with the closed form (exit 5 if they differ by more than 1e-6 degrees)");
  finger->add_option("--model", a.model,
                     "Finger automaton: its joint ranges and theta3_fraction set the closed form, "
                     "and --simulate simulates it (default: the bundled finger.ha)");
}

// `hybrid hand` (gripper/): the three fingers and the spread.
void AddHand(CLI::App& app, Commands& c) {
  hybrid::cli::HandArgs& a = c.hand_args;
  CLI::App* hand = c.hand = app.add_subcommand(
      "hand", "The three-finger hand closing on objects: fingers A, B, C and the spread modes");
  hand->add_option("--object", a.objects,
                   "An object in the palm's x-y plane, extruded across the hand (metres; x from "
                   "finger A towards B and C, y the palm normal, origin between the fingers at "
                   "the height of joint 1): circle:X,Y,R or segment:X1,Y1,X2,Y2[,R]; repeatable");
  hand->add_option("--mode", a.mode, "Operating mode: basic, wide, pinch or scissor")
      ->capture_default_str();
  AddNumberOption(hand, "--spread", &a.spread,
                  "Spread motor position in [0, 255] (overrides --mode)");
  AddNumberOption(hand, "--g", &a.g, "One motor command for all fingers, in [0, 255]");
  AddNumberOption(hand, "--g-a", &a.g_a, "Motor command of finger A (one command per finger)");
  AddNumberOption(hand, "--g-b", &a.g_b, "Motor command of finger B");
  AddNumberOption(hand, "--g-c", &a.g_c, "Motor command of finger C");
  hand->add_flag("--json", a.json, "Machine-readable output");
  hand->add_flag("--joint-state", a.joint_state,
                 "Also give the joints of the ROS description (names, radians; "
                 "docs/robot_frames.md)");
  hand->add_option("--draw", a.draw, "Write an SVG drawing of the hand (see --at)");
  AddNumberListOption(hand, "--at", &a.draw_at,
                      "Motor positions drawn by --draw (default 0,30,70,110,150,180,210,255)");
  hand->add_flag("--simulate", a.simulate,
                 "Also simulate the composed finger automata and compare with the closed form");
  hand->add_option("--model", a.model, "Hand model for --simulate (default: the bundled hand.ha)");
}

// `hybrid diagnose` and `hybrid synthesize` (measured finger data).
void AddDiagnosis(CLI::App& app, Commands& c) {
  hybrid::cli::DiagnoseArgs& d = c.diagnose_args;
  CLI::App* diagnose = c.diagnose = app.add_subcommand(
      "diagnose",
      "Compare measured data with a model: residuals per variable and mode, the cause (a "
      "parameter, a sensor bias or gain, a flow gain, a moved guard or invariant threshold, an "
      "input offset, a delayed transition; for the finger backlash, motor_offset, joint_range, "
      "sensor_bias, "
      "compliance, theta3_law), or none, or unexplained; an extended model and its held-out "
      "gain");
  diagnose
      ->add_option("FILE", c.diagnose_first,
                   "A model file, then its trace DATA.csv (columns run,time, the model's inputs "
                   "and variables; docs/diagnosis.md); or, alone, the finger's measured runs "
                   "(run,g,theta1,theta2,theta3[,gob,contact_link])")
      ->required();
  diagnose->add_option("DATA", c.diagnose_data, "The trace of the model FILE");
  diagnose->add_option("--model", d.model,
                       "The model (default for the finger's data: the bundled finger.ha)");
  diagnose->add_option("--config", c.config, kConfigHelp);
  diagnose
      ->add_option("--noise", c.diagnose_noise,
                   "NAME=SD: noise standard deviation of a traced variable, in place of the "
                   "estimate (traces of any model); repeatable")
      ->take_all();
  diagnose->add_flag("--json", d.json, "Machine-readable output");
  diagnose->add_option("--out-model", d.out_model,
                       "Write the extended model (accepted by simulate, dot and check)");
  diagnose->add_option("--report", d.report,
                       "Write diagnosis.json and SVG plots (measured, baseline, extended) here");
  AddNumberOption(diagnose, "--significance", &d.significance,
                  "Held-out gain (chi-square units) needed to name a cause");
  AddNumberOption(diagnose, "--threads", &d.threads, "Worker threads");
  AddProgressOptions(diagnose, &d.progress);

  hybrid::cli::SynthesizeArgs& s = c.synthesize_args;
  CLI::App* synthesize = c.synthesize = app.add_subcommand(
      "synthesize",
      "Write SYNTHETIC finger data (the model plus hidden effects, the report's noise and "
      "outliers) in the CSV format of `hybrid diagnose`");
  synthesize
      ->add_option("--effect", s.effects,
                   "NAME=VALUE: a hidden effect, e.g. backlash=6, theta3_bias=2.5, "
                   "ripple_amplitude=3; repeatable")
      ->take_all();
  AddNumberOption(synthesize, "--seed", &s.seed, "Random seed");
  AddNumberOption(synthesize, "--free-runs", &s.free_runs, "Runs without an object");
  AddNumberOption(synthesize, "--samples", &s.samples, "Samples per run (even)");
  synthesize->add_option("--model", s.model, "Finger automaton (default: the bundled finger.ha)");
  synthesize->add_option("-o,--output,--out", s.out,
                         "Output CSV (default: standard output; --out: the old spelling)");
}

// The bundled model `name` where a command's --model was not given and the command reads it.
void DefaultModels(Commands& c) {
  using hybrid::cli::BundledFile;
  if (c.finger->parsed() && c.finger_args.model.empty() && c.finger_args.simulate) {
    c.finger_args.model = BundledFile("spec/finger.ha").string();
  }
  if (c.hand->parsed() && c.hand_args.model.empty() && c.hand_args.simulate) {
    c.hand_args.model = BundledFile("spec/hand.ha").string();
  }
  if (c.synthesize->parsed() && c.synthesize_args.model.empty()) {
    c.synthesize_args.model = BundledFile("spec/finger.ha").string();
  }
}

// `hybrid diagnose [MODEL] DATA [--model MODEL]`: a trace of any model (a CSV with a `time`
// column) goes to RunDiagnoseModel, the finger's measured runs to RunDiagnose.
ExitCode RunDiagnosis(Commands& c) {
  using hybrid::cli::Arg;
  using hybrid::cli::OptionError;
  hybrid::cli::DiagnoseArgs& d = c.diagnose_args;
  if (!c.diagnose_data.empty()) {
    if (!d.model.empty()) {
      throw OptionError("model",
                        "the model is given twice: write `hybrid diagnose MODEL DATA` or "
                        "`hybrid diagnose DATA --model MODEL`");
    }
    d.model = c.diagnose_first;
    d.data = c.diagnose_data;
  } else {
    d.data = c.diagnose_first;
  }
  if (hybrid::IsTraceFile(d.data)) {
    if (d.model.empty()) {
      throw OptionError("model", d.data +
                                     " is a trace (it has a 'time' column): give its model, "
                                     "`hybrid diagnose MODEL " +
                                     d.data + "`");
    }
    const hybrid::cli::DiagnoseModelArgs m{d.model,    d.data,         d.json,    d.out_model,
                                           d.report,   d.significance, d.threads, c.diagnose_noise,
                                           d.progress, c.config};
    return hybrid::cli::RunDiagnoseModel(m);
  }
  if (!c.config.empty()) {
    throw OptionError(
        "config", Arg("config") + " applies to a SpaceEx model (.xml), not to the finger's data");
  }
  if (!c.diagnose_noise.empty()) {
    throw OptionError("noise", Arg("noise") +
                                   " applies to a trace of any model (a CSV with a "
                                   "'time' column), not to the finger's data");
  }
  if (d.model.empty()) d.model = hybrid::cli::BundledFile("spec/finger.ha").string();
  return hybrid::cli::RunDiagnose(d);
}

// `hybrid import`: the translation, checked by parsing it, then written; notes on stderr.
ExitCode RunImport(const Commands& c) {
  std::optional<std::filesystem::path> config;
  if (!c.config.empty()) {
    config = c.config;
  } else {
    config = hybrid::spaceex::DefaultConfigFile(c.model);
  }
  hybrid::cli::CheckDistinctFiles({{"model", c.model}, {"config", config ? config->string() : ""}},
                                  {{"output", c.output}});
  hybrid::cli::CheckOutputPlaces({{"output", c.output}});
  const hybrid::spaceex::Translation translation =
      hybrid::spaceex::ImportSpaceExFile(c.model, config);
  (void)translation.Parse(c.model);
  for (const std::string& note : translation.notes) {
    std::cerr << c.model << ": note: " << note << "\n";
  }
  WriteOutput(c.output, translation.text);
  return ExitCode::kOk;
}

// `hybrid info` and `hybrid dot` on the parsed model.
ExitCode RunModelCommand(const Commands& c) {
  if (c.import->parsed()) return RunImport(c);
  if (c.dot->parsed()) {
    hybrid::cli::CheckDistinctFiles(
        hybrid::cli::ModelInputs("model", c.model,
                                 c.config.empty() ? std::nullopt : std::optional(c.config)),
        {{"output", c.output}});
    hybrid::cli::CheckOutputPlaces({{"output", c.output}});
  }
  const System system = hybrid::cli::ReadModelArgument(c.model, c.config);
  if (c.info->parsed()) {
    const json report = hybrid::cli::InfoJson(system, c.model);
    for (const auto& w : report["warnings"]) {
      if (!c.as_json) continue;
      std::cerr << c.model << ": warning: " << w.get<std::string>() << "\n";
    }
    // The file name may be any bytes: replace invalid UTF-8 rather than throw.
    WriteOutput("-", c.as_json ? report.dump(2, ' ', false, json::error_handler_t::replace) + "\n"
                               : hybrid::cli::InfoText(report, system));
    return ExitCode::kOk;
  }
  std::string text;
  try {
    hybrid::DotOptions options;
    options.product = c.product;
    options.compact = c.compact;
    if (!c.group_by.empty()) {
      options.group = hybrid::cli::ModeGroups(c.group_by, system, {hybrid::cli::PhaseGrouping()});
    }
    text = hybrid::WriteDot(system, options);
  } catch (const std::invalid_argument& e) {
    std::cerr << c.model << ": cannot draw the product: " << e.what()
              << " (omit --product to draw one cluster per component)\n";
    return ExitCode::kInput;
  }
  WriteOutput(c.output, text);
  return ExitCode::kOk;
}

// The exit code of the exception `error` of `command`, whose message it writes to standard
// error (cli/error_report.h).
ExitCode Report(std::exception_ptr error, std::string_view command, const std::string& prefix,
                ExitCode invalid_code) {
  const hybrid::cli::ErrorReport report =
      hybrid::cli::ReportError(error, command, prefix, invalid_code);
  std::cerr << report.message << "\n";
  return report.code;
}

// Runs the parsed command; every exception becomes a message and an exit code (Report).
ExitCode Run(Commands& c) {
  // In the gripper, diagnosis and check commands, std::invalid_argument is a bad option value
  // (the models are validated by the parser: ParseError, exit 1).
  const std::pair<CLI::App*, std::string> commands[] = {{c.finger, "finger"},
                                                        {c.hand, "hand"},
                                                        {c.diagnose, "diagnose"},
                                                        {c.synthesize, "synthesize"},
                                                        {c.check, "check"}};
  for (const auto& [command, name] : commands) {
    if (!command->parsed()) continue;
    try {
      DefaultModels(c);
      if (command == c.finger) return hybrid::cli::RunFinger(c.finger_args);
      if (command == c.hand) return hybrid::cli::RunHand(c.hand_args);
      if (command == c.diagnose) return RunDiagnosis(c);
      if (command == c.synthesize) return hybrid::cli::RunSynthesize(c.synthesize_args);
      return hybrid::cli::RunCheck(c.check_args);
    } catch (...) {
      return Report(std::current_exception(), name, "hybrid " + name, ExitCode::kUsage);
    }
  }
  const std::string& model = c.simulate->parsed() ? c.simulate_args.model : c.model;
  std::string name = "info";
  for (const CLI::App* command : {c.dot, c.import, c.simulate}) {
    if (command->parsed()) name = command->get_name();
  }
  try {
    if (c.simulate->parsed()) return hybrid::cli::RunSimulate(c.simulate_args);
    return RunModelCommand(c);
  } catch (...) {
    return Report(std::current_exception(), name, model, ExitCode::kInput);
  }
}

// A message for a first argument (after a leading --log LEVEL) that is no option and no command
// ("unknown command 'simulat'; did you mean 'simulate'?"), or nullopt.
std::optional<std::string> UnknownCommand(const CLI::App& app, int argc, char** argv) {
  int first = 1;
  if (first < argc && std::string_view(argv[first]) == "--log") first += 2;
  if (first < argc && std::string_view(argv[first]).starts_with("--log=")) first += 1;
  if (first >= argc || argv[first][0] == '-') return std::nullopt;
  const std::string word = argv[first];
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  if (std::find(names.begin(), names.end(), word) != names.end()) return std::nullopt;
  std::string message = "unknown command '" + word + "'";
  if (const auto closest = hybrid::cli::ClosestName(word, names)) {
    message += "; did you mean '" + *closest + "'?";
  }
  message += " (commands:";
  for (const std::string& name : names) message += " " + name;
  return message + ")";
}

// `--log LEVEL` on `command` (the program and every subcommand: before or after the command's
// name), into `*level`.
void AddLogOption(CLI::App* command, std::string* level) {
  command
      ->add_option("--log", *level,
                   "Log what the engines do (solver queries, replays, induction steps) to "
                   "standard error from LEVEL up: debug, info or warning (default: no log)")
      ->type_name("LEVEL")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            hybrid::LogLevel ignored;
            if (hybrid::ParseLogLevel(text, &ignored)) return "";
            return "'" + text + "' is not a log level (debug, info or warning)";
          },
          "debug|info|warning"));
}

// Installs the standard error log sink at the level of --log, if given.
void StartLog(const std::string& level) {
  hybrid::LogLevel minimum;
  if (!level.empty() && hybrid::ParseLogLevel(level, &minimum)) {
    hybrid::SetLogSink(hybrid::StderrLogSink(), minimum);
  }
}

// Where the help sends the reader: the documentation is docs/ in a source tree and
// PREFIX/share/doc/hybrid/ in an installed copy (`cmake --install`, `pip install`); no path of
// the build machine is compiled in.
constexpr const char* kCliDoc =
    "cli.md of hybrid's documentation (docs/ in the source tree, share/doc/hybrid/ under the "
    "installation prefix)";

// Each command's help lists the exit codes it can return.
void SetExitCodeFooters(Commands& c) {
  const std::string common =
      "0 success; 1 invalid model or data (FILE:LINE:COL: message on stderr); 2 usage error (a "
      "bad option value, named); 3 cannot write output; 4 out of memory or internal error";
  const std::string more = ". Numbers, output files and limits: " + std::string(kCliDoc) + ".";
  for (CLI::App* app : {c.info, c.dot, c.import, c.diagnose, c.synthesize}) {
    app->footer("Exit codes: " + common + more);
  }
  c.simulate->footer("Exit codes: " + common + "; 5 simulation stopped early" + more);
  c.check->footer("Exit codes: " + common +
                  "; 6 a property violated (or a reach target unreachable); 7 no violation, but "
                  "a verdict unknown" +
                  more);
  for (CLI::App* app : {c.finger, c.hand}) {
    app->footer("Exit codes: " + common +
                "; 5 --simulate disagrees with the closed form or stops early" + more);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A signal that stops the program (Ctrl-C, kill) removes the temporary files of an output
  // being written.
  hybrid::cli::RemoveTemporaryFilesOnSignals();
  CLI::App app{"hybrid: declare, inspect and draw hybrid automata; see " + std::string(kCliDoc),
               "hybrid"};
  app.footer(
      "Exit codes: 0 success; 1 invalid model or data (FILE:LINE:COL: message on stderr); 2 usage "
      "error (a bad option value, named); 3 cannot write output; 4 out of memory or internal "
      "error; 5 simulation stopped early; 6 check: a property violated; 7 check: a verdict "
      "unknown. Numbers, output files and limits: " +
      std::string(kCliDoc) + ".");
  app.require_subcommand(1);
  app.set_version_flag("--version", "hybrid " HYBRID_VERSION);
  Commands commands;
  AddModelCommands(app, commands);
  AddSimulate(app, commands);
  AddCheck(app, commands);
  AddFinger(app, commands);
  AddHand(app, commands);
  AddDiagnosis(app, commands);
  SetExitCodeFooters(commands);
  AddLogOption(&app, &commands.log);
  for (CLI::App* command : app.get_subcommands({})) AddLogOption(command, &commands.log);
  using hybrid::cli::ExitStatus;
  if (const auto unknown = UnknownCommand(app, argc, argv)) {
    std::cerr << "hybrid: " << *unknown << "\nRun with --help for more information.\n";
    return ExitStatus(ExitCode::kUsage);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? ExitStatus(ExitCode::kOk) : ExitStatus(ExitCode::kUsage);
  }
  StartLog(commands.log);
  return ExitStatus(Run(commands));
}
