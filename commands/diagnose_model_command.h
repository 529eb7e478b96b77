#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/exit_code.h"
#include "commands/progress.h"

namespace hybrid::cli {

/// Options of `hybrid diagnose MODEL DATA.csv`, a measured trace of any model (docs/cli.md,
/// docs/diagnosis.md "Any model"); the fields' names are the arguments' API names that messages
/// refer to (commands/argument_message.h).
struct DiagnoseModelArgs {
  std::string model;      ///< the model file (language or SpaceEx), one automaton
  std::string data;       ///< the trace CSV (include/hybrid/model_diagnosis/trace_data.h)
  bool json = false;      ///< machine-readable output on standard output
  std::string out_model;  ///< write the extended model here
  std::string report;     ///< write diagnosis.json and one SVG plot per observed variable here
  double significance = 25.0;
  int threads = 2;
  /// NAME=SD: the noise standard deviation of observed variable NAME, in place of the estimate.
  std::vector<std::string> noise;
  ProgressMode progress = ProgressMode::kOff;
  /// A SpaceEx configuration read in place of the `.cfg` next to a SpaceEx `model` (empty: that
  /// one; commands/model_file.h).
  std::string config;
};

/// Checks the options both `hybrid diagnose` forms share (the finger's too): OptionError (exit 2)
/// unless `threads` lies in [1, 64] and `significance` is finite and positive.
void CheckDiagnosisOptions(int threads, double significance);

/// The report `--json` prints for `args` (model, data, significance, threads, noise; nothing is
/// written). With `curves`, also "curves": per run its label, "time", and per observed variable
/// the "measured", "baseline" and "extended" values at those times (null where missing), for
/// plots (the Python module's arrays). Throws as RunDiagnoseModel.
nlohmann::ordered_json DiagnoseModelReport(const DiagnoseModelArgs& args, bool curves = false);

/// Runs `hybrid diagnose MODEL DATA.csv`; returns kOk. Before any work: OptionError (exit 2) for
/// bad option values and for outputs naming an input or each other (a `config` with a model that
/// is not a SpaceEx model: when the model is read); OutputError when an output's
/// directory does not exist. Then ParseError for a bad model, hybrid::DataError (FILE:LINE:COL)
/// for a bad trace, InputError for a model the diagnosis does not take (several components) or
/// cannot simulate as it is (exit 1), OutputError when an output cannot be written. Outputs are
/// written all or nothing.
ExitCode RunDiagnoseModel(const DiagnoseModelArgs& args);

}  // namespace hybrid::cli
