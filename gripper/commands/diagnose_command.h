#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/exit_code.h"
#include "commands/progress.h"

namespace hybrid::cli {

/// Options of `hybrid diagnose` (see docs/cli.md and docs/diagnosis.md); the fields' names are the
/// arguments' API names that messages refer to (commands/argument_message.h).
struct DiagnoseArgs {
  std::string data;       ///< the measured CSV
  std::string model;      ///< the finger automaton (spec/finger.ha by default)
  bool json = false;      ///< machine-readable output on standard output
  std::string out_model;  ///< write the extended model here
  std::string report;     ///< write diagnosis.json and SVG plots into this directory
  double significance = 25.0;
  int threads = 2;
  /// Progress on standard error (the command line: kAuto, --quiet, --progress).
  ProgressMode progress = ProgressMode::kOff;
};

/// Runs `hybrid diagnose`; returns kOk. Before any work: OptionError (commands/command_error.h,
/// exit 2) for bad argument values and for outputs (`out_model`, the report's files) naming one
/// file or an input (`data`, `model`); OutputError when `out_model`'s directory does not exist or
/// `report` lies below a file. Then hybrid::DataError for bad data (exit 1, with FILE:LINE:COL),
/// hybrid::ParseError for a bad model, InputError for a model that is not the finger, and
/// OutputError when an output cannot be written. The outputs are written all or nothing: the
/// report directory (created with its parents) and every file appear only when all are
/// written; on a failure nothing new is left.
ExitCode RunDiagnose(const DiagnoseArgs& args);

/// The report `hybrid diagnose --json` writes for `args` (data, model, significance, threads;
/// the output options are ignored: nothing is written). Throws as RunDiagnose.
nlohmann::ordered_json DiagnoseReport(const DiagnoseArgs& args);

/// Options of `hybrid synthesize`: data with hidden effects, for demos and tests (the fields'
/// names are the arguments' API names, as for DiagnoseArgs).
struct SynthesizeArgs {
  std::string model;
  std::string out = "-";
  /// NAME=VALUE: an effect parameter (backlash, motor_offset, theta1_max, theta2_bias,
  /// compliance_link2, theta3_fraction, ...) or one outside the diagnosable list
  /// (ripple_amplitude, ripple_period, theta3_hysteresis).
  std::vector<std::string> effects;
  std::uint64_t seed = 1;
  int free_runs = 4;
  int samples = 512;
};

/// Runs `hybrid synthesize`; returns kOk. Throws OptionError for a bad argument (exit 2):
/// `free_runs` outside [0, kMaxSyntheticFreeRuns], `samples` odd or outside [kMinRunSamples,
/// kMaxSyntheticSamples], more than kMaxSyntheticSamples rows in all
/// (include/hybrid/gripper/synthetic_data.h; checked before anything is allocated), a malformed
/// or unknown effect in `effects`, `out` naming the `model`; InputError for a model that is not
/// the finger.
ExitCode RunSynthesize(const SynthesizeArgs& args);

}  // namespace hybrid::cli
