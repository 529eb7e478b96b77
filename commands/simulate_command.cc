#include "commands/simulate_command.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "automaton/number_syntax.h"
#include "commands/command_error.h"
#include "commands/initial_values.h"
#include "commands/model_file.h"
#include "commands/output.h"
#include "commands/trajectory_plot.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::cli {
namespace {

using json = nlohmann::ordered_json;

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto first = cell.find_first_not_of(" \t\r");
    const auto last = cell.find_last_not_of(" \t\r");
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// The number in `cell` (decimal syntax, automaton/number_syntax.h); ParseError at its row and
// column otherwise.
double CsvNumber(const std::string& file, int row, int column, const std::string& cell) {
  const NumberRead<double> r = ReadDecimal(cell);
  if (!r.ok()) {
    throw ParseError(file, row, column,
                     NumberErrorMessage(cell, r.error) + " (CSV row " + std::to_string(row) +
                         ", column " + std::to_string(column) + ")");
  }
  return r.value;
}

// Reads `time,NAME,...` rows into one signal per input column.
std::vector<InputSignal> ReadInputCsv(const std::string& path, InputSignal::Shape shape,
                                      const SymbolTable& symbols) {
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, 0, "cannot open input CSV");
  std::string line;
  int row = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++row;
    if (line.empty() || line[0] == '#') continue;
    header = SplitCsvLine(line);
  }
  if (header.size() < 2 || header[0] != "time") {
    throw ParseError(path, row, 1, "the header must be 'time,INPUT[,INPUT...]'");
  }
  std::vector<InputSignal> signals;
  for (size_t c = 1; c < header.size(); ++c) {
    const auto slot = symbols.Find(header[c]);
    if (!slot || symbols[*slot].kind != SymbolKind::kInput) {
      throw ParseError(path, row, static_cast<int>(c + 1),
                       "'" + header[c] + "' is not an input of the model");
    }
    for (size_t d = 1; d < c; ++d) {
      if (header[d] == header[c]) {
        throw ParseError(path, row, static_cast<int>(c + 1),
                         "duplicate column '" + header[c] + "'");
      }
    }
    signals.push_back({*slot, shape, {}});
  }
  while (std::getline(in, line)) {
    ++row;
    if (line.empty() || line[0] == '#') continue;
    const auto cells = SplitCsvLine(line);
    if (cells.size() != header.size()) {
      throw ParseError(path, row, 1,
                       "expected " + std::to_string(header.size()) + " cells, found " +
                           std::to_string(cells.size()));
    }
    const double t = CsvNumber(path, row, 1, cells[0]);
    for (size_t c = 1; c < cells.size(); ++c) {
      auto& points = signals[c - 1].points;
      if (!points.empty() && !(points.back().first < t)) {
        throw ParseError(path, row, 1, "times must increase strictly");
      }
      points.emplace_back(t, CsvNumber(path, row, static_cast<int>(c + 1), cells[c]));
    }
  }
  if (signals.front().points.empty()) throw ParseError(path, row, 1, "no data rows");
  return signals;
}

std::string KindName(StateSample::Kind kind) {
  switch (kind) {
    case StateSample::Kind::kStart:
      return "start";
    case StateSample::Kind::kSample:
      return "sample";
    case StateSample::Kind::kBeforeEvent:
      return "before_event";
    case StateSample::Kind::kAfterEvent:
      return "after_event";
    case StateSample::Kind::kEnd:
      return "end";
  }
  return "?";
}

std::string Join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i > 0 ? sep : "") + items[i];
  return out;
}

std::string TraceCsv(const Simulator& sim, const SimulationResult& r) {
  std::ostringstream out;
  out.precision(17);
  out << "time,kind,mode";
  for (const auto& v : sim.variable_names()) out << "," << v;
  out << "\n";
  for (const StateSample& s : r.samples) {
    out << s.time << "," << KindName(s.kind) << "," << sim.ModeLabel(s.modes);
    for (int i = 0; i < s.x.size(); ++i) out << "," << s.x[i];
    out << "\n";
  }
  return out.str();
}

std::string EventsCsv(const Simulator& sim, const SimulationResult& r) {
  std::ostringstream out;
  out.precision(17);
  out << "time,cause,transitions,label,mode_before,mode_after";
  for (const auto& v : sim.variable_names()) out << "," << v << "_before";
  for (const auto& v : sim.variable_names()) out << "," << v << "_after";
  out << "\n";
  for (const EventRecord& e : r.events) {
    out << e.time << "," << EventCauseName(e.cause) << "," << Join(e.transitions, "+") << ","
        << e.label << "," << sim.ModeLabel(e.modes_before) << "," << sim.ModeLabel(e.modes_after);
    for (int i = 0; i < e.before.size(); ++i) out << "," << e.before[i];
    for (int i = 0; i < e.after.size(); ++i) out << "," << e.after[i];
    out << "\n";
  }
  return out.str();
}

json State(const Simulator& sim, const Eigen::VectorXd& x) {
  json j = json::object();
  for (size_t i = 0; i < sim.variable_names().size(); ++i) j[sim.variable_names()[i]] = x[i];
  return j;
}

std::string SummaryText(const Simulator& sim, const SimulationResult& r, double until) {
  std::ostringstream out;
  out.precision(10);
  const StateSample& last = r.samples.back();
  out << "status: " << StatusName(r.status) << (r.message.empty() ? "" : " (" + r.message + ")")
      << "\n";
  out << "simulated until t = " << last.time << " of " << until << ", " << r.events.size()
      << " events, " << r.steps << " solver steps\n";
  out << "final mode: " << sim.ModeLabel(last.modes) << "\nfinal state:";
  for (size_t i = 0; i < sim.variable_names().size(); ++i) {
    out << " " << sim.variable_names()[i] << " = " << last.x[i] << ";";
  }
  out << "\n";
  const size_t shown = std::min<size_t>(r.events.size(), 20);
  if (shown > 0) out << "events" << (shown < r.events.size() ? " (first 20)" : "") << ":\n";
  for (size_t i = 0; i < shown; ++i) {
    const EventRecord& e = r.events[i];
    out << "  t = " << e.time << "  " << Join(e.transitions, "+") << "  "
        << sim.ModeLabel(e.modes_before) << " -> " << sim.ModeLabel(e.modes_after) << "\n";
  }
  if (r.zeno) {
    out << "zeno: events accumulate at t = " << r.zeno->accumulation_time
        << "; cycle: " << Join(r.zeno->cycle, ", ") << "\n";
  }
  return out.str();
}

// Applies the `parameters` overrides (NAME=VALUE) to `system`. Throws OptionError about
// "parameters".
void SetParameters(const std::vector<std::string>& specs, System& system) {
  for (const std::string& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError("parameters", Arg("parameters") + " '" + spec + "': expected NAME=VALUE");
    }
    const std::string name = spec.substr(0, eq);
    const double value = OptionNumber("parameters", spec.substr(eq + 1), name);
    try {
      system.SetParameter(name, value);
    } catch (const std::invalid_argument& e) {
      throw OptionError("parameters", Arg("parameters") + " " + name + ": " + e.what());
    }
  }
}

// The signals of `inputs` (NAME=SIGNAL, each replacing any earlier signal of NAME in
// `signals`). Throws OptionError about "inputs".
void OverrideInputs(const std::vector<std::string>& specs, const SymbolTable& symbols,
                    std::vector<InputSignal>& signals) {
  for (const std::string& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError("inputs", Arg("inputs") + " '" + spec + "': expected NAME=SIGNAL");
    }
    const std::string name = spec.substr(0, eq);
    const auto slot = symbols.Find(name);
    if (!slot || symbols[*slot].kind != SymbolKind::kInput) {
      std::string known;
      for (int s : symbols.SlotsOfKind(SymbolKind::kInput)) known += " " + symbols[s].name;
      throw OptionError("inputs", Arg("inputs") + ": '" + name +
                                      "' is not an input of the model (inputs:" +
                                      (known.empty() ? " none" : known) + ")");
    }
    InputSignal s;
    try {
      s = ParseSignal(spec.substr(eq + 1), name);
    } catch (const ParseError& e) {
      // "inputs u:1:12: ...": the argument, the input and the column.
      throw OptionError("inputs", Arg("inputs") + " " + e.what());
    }
    s.slot = *slot;
    std::erase_if(signals, [&](const InputSignal& x) { return x.slot == s.slot; });
    signals.push_back(std::move(s));
  }
}

}  // namespace

std::string EventCauseName(EventRecord::Cause cause) {
  switch (cause) {
    case EventRecord::Cause::kCrossing:
      return "crossing";
    case EventRecord::Cause::kInvariant:
      return "invariant";
    case EventRecord::Cause::kEnabled:
      return "enabled";
    case EventRecord::Cause::kScheduled:
      return "scheduled";
  }
  return "?";
}

nlohmann::ordered_json SimulationReport(const Simulator& sim, const SimulationResult& r,
                                        double until) {
  json events = json::array();
  for (const EventRecord& e : r.events) {
    events.push_back({{"time", e.time},
                      {"cause", EventCauseName(e.cause)},
                      {"transitions", e.transitions},
                      {"label", e.label},
                      {"mode_before", sim.ModeLabel(e.modes_before)},
                      {"mode_after", sim.ModeLabel(e.modes_after)},
                      {"before", State(sim, e.before)},
                      {"after", State(sim, e.after)}});
  }
  const StateSample& last = r.samples.back();
  json out = {
      {"status", std::string(StatusName(r.status))},
      {"message", r.message},
      {"until", until},
      {"final",
       {{"time", last.time}, {"mode", sim.ModeLabel(last.modes)}, {"values", State(sim, last.x)}}},
      {"steps", r.steps},
      {"events", events}};
  if (r.zeno) {
    out["zeno"] = {{"accumulation_time", r.zeno->accumulation_time}, {"cycle", r.zeno->cycle}};
  }
  return out;
}

namespace {

// The checks of the options made before the model is read. Throws OptionError (and OutputError
// for an output's missing directory).
void CheckSimulateArgs(const SimulateArgs& args) {
  std::vector<NamedFile> inputs =
      ModelInputs("model", args.model,
                  args.config.empty() ? std::nullopt : std::optional<std::string>(args.config));
  inputs.push_back({"input_csv", args.input_csv});
  CheckDistinctFiles(inputs, {{"out", args.out}, {"events", args.events}, {"plot", args.plot}});
  if (args.input_csv.empty() ? false : args.csv_shape != "step" && args.csv_shape != "linear") {
    throw OptionError("csv_shape", Arg("csv_shape") + " must be 'step' or 'linear'");
  }
  if (!(args.sample >= 0.0)) throw OptionError("sample", Arg("sample") + " must be a number >= 0");
  if (args.until && !(*args.until > 0.0)) {
    throw OptionError("until", Arg("until") + ": the horizon must be positive and finite");
  }
  (void)ParseInitialValues(args.init);
  CheckOutputPlaces({{"out", args.out}, {"events", args.events}, {"plot", args.plot}});
}

// The horizon of the run (`until`, else the scenario's), once the options are known to fit the
// simulator's limits. Throws InputError when there is neither, OptionError naming `sample` and
// `until` when the run would record more states than SimulationOptions::max_samples (checked here
// rather than by the simulator so that the message refers to the arguments).
double CheckedHorizon(const SimulationOptions& options, const System& system) {
  if (!options.until && !system.scenario()) {
    throw InputError("no horizon: give one (" + Arg("until") +
                     ") or declare a scenario in the model");
  }
  const double until = options.until ? *options.until : system.scenario()->until;
  const double planned = options.sample_step > 0.0 ? std::floor(until / options.sample_step) : 0.0;
  if (planned > static_cast<double>(options.max_samples)) {
    throw OptionError("sample", "recording the state every " + FormatNumber(options.sample_step) +
                                    " (" + Arg("sample") + ") up to t = " + FormatNumber(until) +
                                    " (" + Arg("until") + ") would record " +
                                    FormatNumber(planned) + " samples, more than the limit of " +
                                    std::to_string(options.max_samples) +
                                    ": give a larger sample step or a shorter horizon");
  }
  try {  // the simulator's own checks of the options, told apart from the model's
    ValidateSimulationOptions(options, until);
  } catch (const std::invalid_argument& e) {
    throw OptionError("sample", ArgumentMessage(e.what()));
  }
  return until;
}

}  // namespace

ExitCode RunSimulate(const SimulateArgs& args) {
  CheckSimulateArgs(args);
  System system = ReadModelArgument(args.model, args.config);
  SetParameters(args.parameters, system);
  SetInitialValues(ParseInitialValues(args.init), system);
  const SymbolTable& symbols = system.symbols();
  std::vector<InputSignal> signals;
  if (!args.input_csv.empty()) {
    signals = ReadInputCsv(
        args.input_csv,
        args.csv_shape == "step" ? InputSignal::Shape::kStep : InputSignal::Shape::kLinear,
        symbols);
  }
  OverrideInputs(args.inputs, symbols, signals);
  SimulationOptions options;
  options.until = args.until;
  options.sample_step = args.sample;
  const double until = CheckedHorizon(options, system);
  const Simulator sim(system);
  const SimulationResult result = sim.Run(options, signals);
  std::vector<std::pair<std::string, std::string>> files;
  if (!args.out.empty()) files.emplace_back(args.out, TraceCsv(sim, result));
  if (!args.events.empty()) files.emplace_back(args.events, EventsCsv(sim, result));
  if (!args.plot.empty()) {
    // The inputs as the run saw them: the scenario's signals where no option replaced them.
    std::vector<InputSignal> drawn = signals;
    if (system.scenario()) {
      for (const InputSignal& s : system.scenario()->inputs) {
        if (std::none_of(drawn.begin(), drawn.end(),
                         [&](const InputSignal& d) { return d.slot == s.slot; })) {
          drawn.push_back(s);
        }
      }
    }
    // Without samples between events the plot draws a run of its own that records some, so that
    // its curves follow the model; the other outputs keep the run they describe.
    const SimulationOptions plotted = PlotOptions(options, until);
    const SimulationResult dense =
        plotted.sample_step == options.sample_step ? SimulationResult{} : sim.Run(plotted, signals);
    files.emplace_back(args.plot, TrajectoryPlotSvg(sim, dense.samples.empty() ? result : dense,
                                                    drawn, system.name()));
  }
  WriteOutputs(files);
  WriteOutput("-", args.json ? SimulationReport(sim, result, until).dump(2) + "\n"
                             : SummaryText(sim, result, until));
  return result.status == SimulationStatus::kCompleted ? ExitCode::kOk
                                                       : ExitCode::kSimulationFailed;
}

}  // namespace hybrid::cli
