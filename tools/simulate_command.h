#pragma once

#include <optional>
#include <string>
#include <vector>

namespace hybrid::cli {

/// Options of `hybrid simulate` (see docs/cli.md).
struct SimulateArgs {
  std::string model;
  std::vector<std::string> inputs;      ///< NAME=SIGNAL, SIGNAL as in a scenario
  std::vector<std::string> parameters;  ///< NAME=VALUE: parameter overrides (System::SetParameter)
  std::string input_csv;                ///< time column plus one column per input
  std::string csv_shape = "step";       ///< how CSV rows are joined: step or linear
  std::optional<double> until;          ///< nullopt: the scenario's horizon
  double sample = 0.0;                  ///< 0: start, end and events only
  std::string out;                      ///< trajectory CSV
  std::string events;                   ///< event log CSV
  bool json = false;                    ///< JSON summary (with every event) on standard output
};

/// Runs `hybrid simulate`; returns the process exit code (0 completed, 5 stopped early). Throws
/// hybrid::ParseError for a bad model, signal or CSV (with position), std::invalid_argument for
/// bad options, and OutputError (tools/output.h) when a file cannot be written.
int RunSimulate(const SimulateArgs& args);

}  // namespace hybrid::cli
