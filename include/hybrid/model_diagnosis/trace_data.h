#pragma once

// Measured traces of any model, for `hybrid diagnose MODEL DATA.csv` (docs/diagnosis.md, "Any
// model").
//
// File format. A CSV file (comma-separated, no quoting) whose header row names its columns in any
// order:
//   run    optional; the run's label (any non-empty text). Without it the file is one run,
//          labelled "1". The rows of a run are contiguous (a label does not come back).
//   time   required; the sample's time in the model's time unit, finite, >= 0 and strictly
//          increasing within a run. Every run starts from the model's initial state at time 0.
//   NAME   an input or a continuous variable of the model, by its name in the model (for a
//          system of several components the qualified name, e.g. `A.x`); a number, or an empty
//          cell for a missing sample. Inputs are read as piecewise linear between their samples
//          (missing ones skipped) and must lie within the input's declared bounds; variables are
//          the observed channels. At least one variable column is required.
//   mode   optional; the mode the system was seen in (a mode name of the model, or empty).
// Any other column is an error that names the closest model name, so that typos are caught.
// A line whose first non-blank character is `#` is a comment; blank lines are ignored; cells are
// trimmed of spaces and tabs; "\r\n" line ends and a UTF-8 byte-order mark are accepted. Numbers
// are in the decimal syntax of the model language (no hexadecimal, inf or nan). A run has at
// least kMinTraceSamples rows; a file at most kMaxTraceRows.

#include <istream>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/diagnosis/data_error.h"

namespace hybrid {

/// The fewest rows a run may have.
inline constexpr int kMinTraceSamples = 10;
/// The most data rows a file may have (a bound on memory: about 100 bytes per cell).
inline constexpr int kMaxTraceRows = 1000000;

/// One measured run: parallel vectors with one entry per sample, in time order.
struct TraceRun {
  std::string label;
  std::vector<double> time;
  /// inputs[i][k]: input TraceData::input_names[i] at sample k, NaN where missing.
  std::vector<std::vector<double>> inputs;
  /// observed[c][k]: variable TraceData::observed_names[c] at sample k, NaN where missing.
  std::vector<std::vector<double>> observed;
  /// The `mode` column's cells (empty strings where missing; empty vector without the column).
  std::vector<std::string> mode;
  /// The file line (1-based) of each sample.
  std::vector<int> lines;
};

/// The runs of one trace file, in file order.
struct TraceData {
  std::string source;
  /// The input columns, in file order (System names).
  std::vector<std::string> input_names;
  /// The observed variable columns, in file order (System names).
  std::vector<std::string> observed_names;
  std::vector<TraceRun> runs;
};

/// Reads a trace of `model` in the format described at the top of this file from `in`; `source`
/// names it in messages. Throws DataError ("SOURCE:LINE:COL: message", COL the 1-based column,
/// 0 for a whole line) at the first problem: no header; an unknown, duplicate or empty column
/// name; no `time` column or no variable column; no data rows; a row with too few or too many
/// cells; a quote; an empty `run` or `time`; a cell that is not a number or not finite; a time
/// below 0 or not after the previous one of its run; an input outside its bounds; a mode the
/// model does not have; a run label that comes back; a run with fewer than kMinTraceSamples
/// rows or an input column empty throughout a run; more than kMaxTraceRows rows.
TraceData ReadTraceData(std::istream& in, const std::string& source, const System& model);

/// ReadTraceData on the file at `path` (also the source in messages). Throws DataError with line
/// and column 0 if the file cannot be opened or is a directory.
TraceData ReadTraceFile(const std::string& path, const System& model);

/// Whether the first header row of the CSV file at `path` has a `time` column (a trace of any
/// model, rather than the finger's measured data). False when the file cannot be read.
bool IsTraceFile(const std::string& path);

}  // namespace hybrid
