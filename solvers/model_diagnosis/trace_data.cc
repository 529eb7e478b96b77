#include "hybrid/model_diagnosis/trace_data.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include "automaton/csv_cells.h"
#include "automaton/number_syntax.h"
#include "automaton/quoted_text.h"

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a header column holds.
struct Column {
  enum class Kind { kRun, kTime, kInput, kObserved, kMode } kind;
  int index = 0;  // into input_names / observed_names
  int slot = 0;   // System slot of an input
};

// Reads the lines of one trace file and throws DataError for its problems.
class TraceReader {
 public:
  TraceReader(std::istream& in, std::string source, const System& model) : in_(in), model_(model) {
    data_.source = std::move(source);
  }

  TraceData Read() {
    std::string text;
    bool header_read = false;
    while (std::getline(in_, text)) {
      ++line_;
      std::string_view line = text;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (line_ == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
      const std::string_view trimmed = TrimBlanks(line);
      if (trimmed.empty() || trimmed.front() == '#') continue;
      if (!header_read) {
        ReadHeader(SplitCsvCells(line));
        header_read = true;
      } else {
        ReadRow(SplitCsvCells(line));
      }
    }
    if (in_.bad()) Fail(line_, 0, "read error");
    if (!header_read) Fail(0, 0, "no header: the file is empty or has only comments");
    if (data_.runs.empty()) Fail(header_line_, 0, "no data rows after the header");
    CloseRun();
    return std::move(data_);
  }

 private:
  [[noreturn]] void Fail(int line, int column, const std::string& message) const {
    throw DataError(data_.source, line, column, message);
  }

  // The names a column may take, for the message about an unknown one.
  std::string KnownNames() const {
    std::string names = "run, time, mode";
    const SymbolTable& symbols = model_.symbols();
    for (int slot = 0; slot < symbols.size(); ++slot) {
      const SymbolKind kind = symbols[slot].kind;
      if (kind == SymbolKind::kVariable || kind == SymbolKind::kInput) {
        names += ", " + symbols[slot].name;
      }
    }
    return names;
  }

  Column Classify(std::string_view name, int column) {
    if (name.empty()) Fail(line_, column, "empty column name");
    if (name == "run") return {Column::Kind::kRun};
    if (name == "time") return {Column::Kind::kTime};
    if (name == "mode") return {Column::Kind::kMode};
    const std::optional<int> slot = model_.symbols().Find(name);
    const std::optional<SymbolKind> kind =
        slot ? std::optional(model_.symbols()[*slot].kind) : std::nullopt;
    if (kind == SymbolKind::kInput) {
      data_.input_names.emplace_back(name);
      return {Column::Kind::kInput, static_cast<int>(data_.input_names.size()) - 1, *slot};
    }
    if (kind == SymbolKind::kVariable) {
      data_.observed_names.emplace_back(name);
      return {Column::Kind::kObserved, static_cast<int>(data_.observed_names.size()) - 1, *slot};
    }
    Fail(line_, column,
         "unknown column " + QuotedForMessage(name) +
             (kind ? " (a parameter or discrete variable, not a measured signal)" : "") +
             "; the columns are " + KnownNames());
  }

  void ReadHeader(const std::vector<std::string_view>& cells) {
    header_line_ = line_;
    std::set<std::string_view> seen;
    for (size_t i = 0; i < cells.size(); ++i) {
      const int column = static_cast<int>(i) + 1;
      if (cells[i].find('"') != std::string_view::npos) {
        Fail(line_, column, "quotes are not supported");
      }
      if (!seen.insert(cells[i]).second) {
        Fail(line_, column, "duplicate column " + QuotedForMessage(cells[i]));
      }
      columns_.push_back(Classify(cells[i], column));
    }
    if (!seen.contains("time")) Fail(line_, 0, "no 'time' column");
    if (data_.observed_names.empty()) {
      Fail(line_, 0, "no column of a continuous variable of the model to compare with");
    }
    has_run_ = seen.contains("run");
  }

  // The number in cell `column` of the current row, NaN for an empty cell where allowed.
  double Number(std::string_view cell, int column, bool allow_empty) const {
    if (cell.empty()) {
      if (allow_empty) return kNaN;
      Fail(line_, column, "empty cell");
    }
    const NumberRead<double> r = ReadDecimal(cell);
    if (!r.ok()) Fail(line_, column, NumberErrorMessage(cell, r.error));
    return r.value;
  }

  void StartRun(std::string_view label, int column) {
    CloseRun();
    const std::string name(label.empty() && !has_run_ ? "1" : label);
    if (name.empty()) Fail(line_, column, "empty run label");
    if (!labels_.insert(name).second) {
      Fail(line_, column, "run " + QuotedForMessage(name) + " comes back after another run");
    }
    TraceRun run;
    run.label = name;
    run.inputs.resize(data_.input_names.size());
    run.observed.resize(data_.observed_names.size());
    data_.runs.push_back(std::move(run));
    run_line_ = line_;
  }

  void CloseRun() {
    if (data_.runs.empty()) return;
    const TraceRun& run = data_.runs.back();
    if (static_cast<int>(run.time.size()) < kMinTraceSamples) {
      Fail(run_line_, 0,
           "run " + QuotedForMessage(run.label) + " has " + std::to_string(run.time.size()) +
               " rows; a run needs at least " + std::to_string(kMinTraceSamples));
    }
    for (size_t i = 0; i < run.inputs.size(); ++i) {
      bool any = false;
      for (double v : run.inputs[i]) any = any || !std::isnan(v);
      if (!any) {
        Fail(run_line_, 0,
             "input " + QuotedForMessage(data_.input_names[i]) + " is empty throughout run " +
                 QuotedForMessage(run.label));
      }
    }
  }

  void ReadRow(const std::vector<std::string_view>& cells) {
    if (++rows_ > kMaxTraceRows) {
      Fail(line_, 0, "more than " + std::to_string(kMaxTraceRows) + " data rows");
    }
    if (cells.size() != columns_.size()) {
      Fail(line_, 0,
           "the row has " + std::to_string(cells.size()) + " cells, the header " +
               std::to_string(columns_.size()));
    }
    std::string_view label;
    int label_column = 0;
    for (size_t i = 0; i < cells.size(); ++i) {
      if (cells[i].find('"') != std::string_view::npos) {
        Fail(line_, static_cast<int>(i) + 1, "quotes are not supported");
      }
      if (columns_[i].kind == Column::Kind::kRun) {
        label = cells[i];
        label_column = static_cast<int>(i) + 1;
        if (label.empty()) Fail(line_, label_column, "empty run label");
      }
    }
    if (data_.runs.empty() || (has_run_ && data_.runs.back().label != label)) {
      StartRun(label, label_column);
    }
    for (size_t i = 0; i < cells.size(); ++i) ReadCell(cells[i], static_cast<int>(i) + 1);
    data_.runs.back().lines.push_back(line_);
  }

  void ReadCell(std::string_view cell, int column) {
    TraceRun& run = data_.runs.back();
    const Column& c = columns_[column - 1];
    switch (c.kind) {
      case Column::Kind::kRun:
        return;
      case Column::Kind::kTime:
        return ReadTime(run, Number(cell, column, false), column);
      case Column::Kind::kObserved:
        run.observed[c.index].push_back(Number(cell, column, true));
        return;
      case Column::Kind::kInput:
        run.inputs[c.index].push_back(ReadInput(cell, column, c.slot));
        return;
      case Column::Kind::kMode:
        if (!cell.empty() && !model_.FindMode(cell)) {
          Fail(line_, column, "the model has no mode " + QuotedForMessage(cell));
        }
        run.mode.emplace_back(cell);
        return;
    }
  }

  void ReadTime(TraceRun& run, double t, int column) const {
    if (t < 0) Fail(line_, column, "time must be >= 0");
    if (!run.time.empty() && !(t > run.time.back())) {
      Fail(line_, column,
           "time must increase within a run (the previous row has a later or equal time)");
    }
    run.time.push_back(t);
  }

  double ReadInput(std::string_view cell, int column, int slot) const {
    const double v = Number(cell, column, true);
    if (std::isnan(v)) return v;
    const auto [lo, hi] = model_.InputBounds(slot);
    if (v < lo || v > hi) {
      Fail(line_, column,
           "input " + QuotedForMessage(model_.symbols()[slot].name) + " = " + std::string(cell) +
               " is outside its bounds [" + FormatBound(lo) + ", " + FormatBound(hi) + "]");
    }
    return v;
  }

  static std::string FormatBound(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.10g", x);
    return buffer;
  }

  std::istream& in_;
  const System& model_;
  TraceData data_;
  std::vector<Column> columns_;
  std::set<std::string> labels_;
  bool has_run_ = false;
  int line_ = 0, header_line_ = 0, run_line_ = 0, rows_ = 0;
};

}  // namespace

TraceData ReadTraceData(std::istream& in, const std::string& source, const System& model) {
  return TraceReader(in, source, model).Read();
}

TraceData ReadTraceFile(const std::string& path, const System& model) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw DataError(path, 0, 0, "is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DataError(path, 0, 0, "cannot open the file");
  return ReadTraceData(in, path, model);
}

bool IsTraceFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text;
  bool first = true;
  while (in && std::getline(in, text)) {
    std::string_view line = text;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (first && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
    first = false;
    const std::string_view trimmed = TrimBlanks(line);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    for (std::string_view cell : SplitCsvCells(line)) {
      if (cell == "time") return true;
    }
    return false;
  }
  return false;
}

}  // namespace hybrid
