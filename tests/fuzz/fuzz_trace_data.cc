// libFuzzer harness: the trace CSV reader of `hybrid diagnose MODEL DATA.csv` (ReadTraceData in
// include/hybrid/model_diagnosis/trace_data.h), reading traces of the thermostat of
// spec/thermostat.ha (parsed once; HYBRID_FUZZ_SPEC is set by tests/fuzz/CMakeLists.txt).
// Every input either throws DataError (source "trace.csv", a line of the input or 0, a column
// (cell number) of that line or 0, 0 when the line is; an escaped message that names no C++
// function or type) or gives a TraceData that keeps the documented contract:
// - the header's columns other than run, time and mode are, in file order, the input and
//   observed names, each a model symbol of that kind, none twice, at least one observed;
// - one run labelled "1" without a `run` column; labels non-empty and never twice;
// - every data row of the file (neither blank nor a comment, after the header) is a sample of
//   exactly one run, in file order (the runs' `lines` are the data rows' line numbers);
// - each run has at least kMinTraceSamples samples, every per-sample vector one entry per sample
//   (`mode` one per sample with a `mode` column, none without);
// - times finite, >= 0 and strictly increasing within a run; observed values finite or NaN;
//   inputs NaN or within the input's bounds, with at least one sample per run; modes empty or
//   a mode of the model.
// Any other exception escapes the harness and aborts: libFuzzer keeps the input as a crash.

#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/model_diagnosis/trace_data.h"
#include "tests/fuzz/fuzz_utilities.h"

namespace {

using hybrid::fuzz::FuzzFail;

constexpr const char* kSource = "trace.csv";

const hybrid::System& Model() {
  static const hybrid::System model =
      hybrid::ParseModelFile(std::string(HYBRID_FUZZ_SPEC) + "/thermostat.ha");
  return model;
}

std::string_view TrimCell(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// The input read by the documented format, independently of the reader: its lines (as
// std::getline gives them, a final "\r" and the first line's byte-order mark removed), the
// (1-based) line of the header (0 if none) and those of the data rows.
struct Layout {
  std::vector<std::string_view> lines;
  int header = 0;
  std::vector<int> data_lines;
  std::vector<std::string_view> header_cells;
};

Layout ReadLayout(std::string_view text) {
  Layout layout;
  size_t start = 0;
  while (start < text.size()) {
    size_t eol = text.find('\n', start);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(start, eol - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (layout.lines.empty() && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
    layout.lines.push_back(line);
    start = eol + 1;
  }
  for (size_t i = 0; i < layout.lines.size(); ++i) {
    const std::string_view trimmed = TrimCell(layout.lines[i]);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    const int number = static_cast<int>(i) + 1;
    if (layout.header == 0) {
      layout.header = number;
      std::string_view rest = layout.lines[i];
      for (size_t comma; (comma = rest.find(',')) != std::string_view::npos;) {
        layout.header_cells.push_back(TrimCell(rest.substr(0, comma)));
        rest.remove_prefix(comma + 1);
      }
      layout.header_cells.push_back(TrimCell(rest));
    } else {
      layout.data_lines.push_back(number);
    }
  }
  return layout;
}

size_t CellCount(std::string_view line) {
  size_t n = 1;
  for (char c : line) n += c == ',';
  return n;
}

void CheckError(const hybrid::DataError& e, std::string_view text, const Layout& layout) {
  const std::string what = e.what();
  if (e.source() != kSource) FuzzFail("a DataError naming another source: " + what);
  if (e.line() < 0 || e.column() < 0 || e.line() > static_cast<int>(layout.lines.size())) {
    FuzzFail("a DataError at a line outside the input: " + what);
  }
  if (e.line() == 0 && e.column() != 0) FuzzFail("a column without a line: " + what);
  if (e.column() > 0 && static_cast<size_t>(e.column()) > CellCount(layout.lines[e.line() - 1])) {
    FuzzFail("a DataError at a column past its line's cells: " + what);
  }
  const std::string prefix = std::string(kSource) + ":" + std::to_string(e.line()) + ":" +
                             std::to_string(e.column()) + ": ";
  if (!what.starts_with(prefix) || what.substr(prefix.size()) != e.message()) {
    FuzzFail("what() is not SOURCE:LINE:COL: MESSAGE: " + what);
  }
  if (e.message().empty() || hybrid::fuzz::LeaksCppNames(e.message(), text)) {
    FuzzFail("bad message: " + what);
  }
  for (const char c : e.message()) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) FuzzFail("a control byte in the message: " + what);
  }
}

void CheckNames(const hybrid::TraceData& data, const Layout& layout) {
  const hybrid::SymbolTable& symbols = Model().symbols();
  std::vector<std::string> inputs, observed;
  for (const std::string_view cell : layout.header_cells) {
    if (cell == "run" || cell == "time" || cell == "mode") continue;
    const std::optional<int> slot = symbols.Find(cell);
    if (!slot) FuzzFail("a column that is no name of the model was accepted");
    const hybrid::SymbolKind kind = symbols[*slot].kind;
    if (kind == hybrid::SymbolKind::kInput) {
      inputs.emplace_back(cell);
    } else if (kind == hybrid::SymbolKind::kVariable) {
      observed.emplace_back(cell);
    } else {
      FuzzFail("a parameter or discrete variable column was accepted");
    }
  }
  if (inputs != data.input_names) FuzzFail("input names differ from the header's columns");
  if (observed != data.observed_names) FuzzFail("observed names differ from the header's");
  if (observed.empty()) FuzzFail("a trace without an observed variable");
  const std::set<std::string_view> unique(layout.header_cells.begin(), layout.header_cells.end());
  if (unique.size() != layout.header_cells.size()) FuzzFail("a duplicate column was accepted");
  if (!unique.contains("time")) FuzzFail("a trace without a time column");
}

void CheckRun(const hybrid::TraceRun& run, const hybrid::TraceData& data, bool has_mode) {
  const hybrid::System& model = Model();
  const size_t n = run.time.size();
  if (run.label.empty()) FuzzFail("a run without a label");
  if (n < static_cast<size_t>(hybrid::kMinTraceSamples)) FuzzFail("a run with too few samples");
  if (run.lines.size() != n) FuzzFail("lines and samples differ in number");
  if (run.inputs.size() != data.input_names.size() ||
      run.observed.size() != data.observed_names.size()) {
    FuzzFail("a run's channels differ from the file's columns");
  }
  if (run.mode.size() != (has_mode ? n : 0)) FuzzFail("modes and samples differ in number");
  for (size_t k = 0; k < n; ++k) {
    const double t = run.time[k];
    if (!std::isfinite(t) || t < 0) FuzzFail("a time that is not finite or is negative");
    if (k > 0 && !(t > run.time[k - 1])) FuzzFail("times do not increase");
  }
  for (const std::vector<double>& channel : run.observed) {
    if (channel.size() != n) FuzzFail("observed values and samples differ in number");
    for (const double v : channel) {
      if (std::isinf(v)) FuzzFail("an infinite observed value");
    }
  }
  for (size_t i = 0; i < run.inputs.size(); ++i) {
    const std::vector<double>& channel = run.inputs[i];
    if (channel.size() != n) FuzzFail("input values and samples differ in number");
    const auto [lo, hi] = model.InputBounds(*model.symbols().Find(data.input_names[i]));
    bool any = false;
    for (const double v : channel) {
      if (std::isnan(v)) continue;
      any = true;
      if (!(v >= lo && v <= hi)) FuzzFail("an input outside its bounds");
    }
    if (!any) FuzzFail("an input empty throughout a run");
  }
  for (const std::string& mode : run.mode) {
    if (!mode.empty() && !model.FindMode(mode)) FuzzFail("a mode the model does not have");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text = hybrid::fuzz::AsText(data, size);
  const hybrid::System& model = Model();
  const Layout layout = ReadLayout(text);
  std::istringstream in{std::string(text)};
  hybrid::TraceData trace;
  try {
    trace = hybrid::ReadTraceData(in, kSource, model);
  } catch (const hybrid::DataError& e) {
    CheckError(e, text, layout);
    return 0;
  }
  if (trace.source != kSource) FuzzFail("a trace naming another source");
  if (layout.header == 0) FuzzFail("a trace read from a file without a header");
  CheckNames(trace, layout);
  if (trace.runs.empty()) FuzzFail("a trace without runs");
  const std::set<std::string_view> columns(layout.header_cells.begin(), layout.header_cells.end());
  if (!columns.contains("run") && (trace.runs.size() != 1 || trace.runs[0].label != "1")) {
    FuzzFail("a file without a run column is not the one run \"1\"");
  }
  std::set<std::string> labels;
  std::vector<int> lines;
  for (const hybrid::TraceRun& run : trace.runs) {
    CheckRun(run, trace, columns.contains("mode"));
    if (!labels.insert(run.label).second) FuzzFail("a run label twice");
    lines.insert(lines.end(), run.lines.begin(), run.lines.end());
  }
  if (lines != layout.data_lines) FuzzFail("the samples are not the file's data rows in order");
  return 0;
}
