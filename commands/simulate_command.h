#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/exit_code.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::cli {

/// Options of `hybrid simulate` (see docs/cli.md); the fields' names are the arguments' API names
/// that messages refer to (commands/argument_message.h).
struct SimulateArgs {
  std::string model;
  std::vector<std::string> inputs;      ///< NAME=SIGNAL, SIGNAL as in a scenario
  std::vector<std::string> parameters;  ///< NAME=VALUE: parameter overrides (System::SetParameter)
  /// NAME=VALUE: the initial value of continuous variable NAME for this run, after `parameters`
  /// (commands/initial_values.h).
  std::vector<std::string> init;
  /// A SpaceEx configuration read in place of the `.cfg` next to a SpaceEx `model` (empty: that
  /// one; commands/model_file.h).
  std::string config;
  std::string input_csv;           ///< time column plus one column per input
  std::string csv_shape = "step";  ///< how CSV rows are joined: step or linear
  /// nullopt: the scenario's horizon (for a SpaceEx model, its configuration's time-horizon).
  std::optional<double> until;
  double sample = 0.0;  ///< 0: start, end and events only
  std::string out;      ///< trajectory CSV
  std::string events;   ///< event log CSV
  std::string plot;     ///< SVG of the run (variables, inputs, jumps, modes)
  bool json = false;    ///< JSON summary (with every event) on standard output
};

/// Runs `hybrid simulate`; returns ExitCode::kOk when the run completed, kSimulationFailed when
/// it stopped early. Throws, before simulating: OptionError (commands/command_error.h) for bad
/// argument values (a malformed or unknown parameter in `parameters` or input in `inputs`, a
/// malformed, unknown, non-finite or out-of-domain initial value in `init`, a `config` with a
/// model that is not a SpaceEx model,
/// `csv_shape`, a negative `sample`, an `until` that is not positive, more recorded states than
/// the simulator allows, `out` and `events` naming one file or an output naming the model or the
/// input CSV); OutputError when an output's directory does not exist; hybrid::ParseError for a
/// bad model or input CSV (with position); InputError when there is no horizon (no `until`, no
/// scenario); std::invalid_argument from the simulator for inputs the model refuses (a value
/// outside its bounds, an initial state outside its invariant). Writes the outputs all or nothing
/// (OutputError when a file cannot be written).
ExitCode RunSimulate(const SimulateArgs& args);

/// The name of an event's cause in the reports: crossing, invariant, enabled or scheduled.
std::string EventCauseName(EventRecord::Cause cause);

/// The JSON document of `hybrid simulate --json` for run `r` of `sim` to horizon `until`:
/// status, message, until, final (a state: time, mode, values), steps, events (time, cause,
/// transitions, label, mode_before, mode_after, before and after as values), zeno if detected.
nlohmann::ordered_json SimulationReport(const Simulator& sim, const SimulationResult& r,
                                        double until);

}  // namespace hybrid::cli
