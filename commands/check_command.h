#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/exit_code.h"
#include "commands/progress.h"
#include "hybrid/automaton/system.h"

namespace hybrid::cli {

/// Options of `hybrid check` (see docs/cli.md); the fields' names are the arguments' API names
/// that messages refer to (commands/argument_message.h).
struct CheckArgs {
  std::string model;
  std::vector<std::string> properties;  ///< names to check; empty: every declared property
  /// NAME=VALUE: the initial value of continuous variable NAME, for every property checked: the
  /// model's initial set with that variable at that point (commands/initial_values.h).
  std::vector<std::string> init;
  /// A SpaceEx configuration read in place of the `.cfg` next to a SpaceEx `model` (empty: that
  /// one; commands/model_file.h).
  std::string config;
  std::string method = "auto";  ///< auto, reach, prove or sample
  bool json = false;
  bool modes = false;      ///< also report which modes (discrete states) are reachable
  int depth = 10;          ///< prove: longest counterexample searched, in steps
  double budget = 60.0;    ///< prove and reach: each one's budget, in budget seconds
  int induction = 1;       ///< prove: largest k of k-induction
  int runs = 200;          ///< sample: random runs per property
  std::uint64_t seed = 1;  ///< sample: seed
  int order = 6;           ///< flowpipe: Taylor order (1 to 12)
  double step = 0.0;       ///< flowpipe: step (0: automatic)
  /// An SVG of the flowpipe projected on `axes` ("X,Y", two variables) is written here (none
  /// when empty); the flowpipe is computed for it if the method did not run it.
  std::string plot_reach;
  std::string axes;
  /// Progress on standard error (the command line: kAuto, --quiet, --progress).
  ProgressMode progress = ProgressMode::kOff;
};

/// Runs `hybrid check`; returns the exit code: kOk when no property is violated or unknown,
/// kViolated when some property is violated (or a reach target is unreachable), kUnknown when
/// none is violated but some verdict is unknown. Throws hybrid::ParseError for a bad model,
/// OptionError (commands/command_error.h) for bad arguments (an unknown property name, an
/// unknown method, a depth outside [0, 1000], an induction bound outside [1, 100], runs < 1, a
/// budget outside (0, 1e6], an order outside [1, 12], a negative step, a plot without two axes
/// that are variables, a bad `init` as SetInitialValues says, a `config` with a model that is not
/// a SpaceEx model), and OutputError when standard output or the plot cannot be written.
ExitCode RunCheck(const CheckArgs& args);

/// The report `hybrid check --json` writes (docs/cli.md) for `system` checked with `args`
/// (`args.model` is only the name the report gives; `args.json`, `args.init` and `args.config`
/// are ignored: `system` is the model as the caller read and set it up), and in `exit_code`
/// (if not null) the exit code RunCheck would return. Throws as RunCheck for bad arguments.
nlohmann::ordered_json CheckReport(const CheckArgs& args, const System& system,
                                   ExitCode* exit_code);

}  // namespace hybrid::cli
