#include "hybrid/gripper/measured_data.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string_view>
#include <system_error>
#include <utility>

#include "automaton/csv_cells.h"
#include "automaton/number_syntax.h"
#include "automaton/quoted_text.h"
#include "hybrid/diagnosis/noise_floor.h"

namespace hybrid {

namespace {

// The columns a file may have; the first five are required.
enum Field { kRun, kG, kTheta1, kTheta2, kTheta3, kGob, kContactLink, kPosition, kFieldCount };
constexpr std::array<std::string_view, kFieldCount> kFieldNames = {
    "run", "g", "theta1", "theta2", "theta3", "gob", "contact_link", "position"};
// How far (counts) a reported motor position may lie above its request: the gripper reports
// whole counts, so a motor at a fractional request rounds up by at most half a count.
constexpr double kPositionRounding = 0.5;
constexpr int kRequiredFields = 5;
constexpr double kMaxCounts = 255.0;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Whether `cell` is a sign and "nan", "inf" or "infinity" in any case (refused as not finite,
// a friendlier message than "not a number").
bool NamesNonFinite(std::string_view cell) {
  if (!cell.empty() && (cell.front() == '+' || cell.front() == '-')) cell.remove_prefix(1);
  std::string lower(cell);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == "nan" || lower == "inf" || lower == "infinity";
}

// `cell` in single quotes for messages, its control characters escaped.
std::string Quoted(std::string_view cell) { return QuotedForMessage(cell); }

// The shortest text that reads back as `x`.
std::string FormatNumber(double x) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

template <typename T>
std::string FormatOptional(const std::optional<T>& x) {
  return x ? FormatNumber(static_cast<double>(*x)) : std::string("empty");
}

// Reads the lines of one file and throws DataError for its problems.
class Reader {
 public:
  Reader(std::istream& in, std::string source) : in_(in) { data_.source = std::move(source); }

  MeasuredData Read() {
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
        ReadHeader(line);
        header_read = true;
      } else {
        ReadRow(line);
      }
    }
    if (in_.bad()) Fail(line_, 0, "read error");
    if (!header_read) {
      Fail(0, 0, line_ == 0 ? "empty file: no header" : "no header: only comments and blank lines");
    }
    if (data_.runs.empty()) Fail(header_line_, 0, "no data rows after the header");
    CloseRun();
    return std::move(data_);
  }

 private:
  // The parsed cells of one row.
  struct Row {
    std::string run;
    double g = 0.0;
    std::array<double, 3> theta = {kNaN, kNaN, kNaN};
    std::optional<double> gob;
    std::optional<int> contact_link;
    double position = kNaN;
  };

  [[noreturn]] void Fail(int line, int column, const std::string& message) const {
    throw DataError(data_.source, line, column, message);
  }

  [[noreturn]] void FailCell(int column, Field field, const std::string& message) const {
    Fail(line_, column, "column '" + std::string(kFieldNames[field]) + "': " + message);
  }

  // 1-based column of `field` (which the header has).
  int ColumnOf(Field field) const { return column_of_[field] + 1; }

  void ReadHeader(std::string_view line) {
    header_line_ = line_;
    column_of_.fill(-1);
    const std::vector<std::string_view> names = SplitCsvCells(line);
    for (int c = 0; c < static_cast<int>(names.size()); ++c) {
      const std::string_view name = names[c];
      if (name.find('"') != std::string_view::npos) {
        Fail(line_, c + 1, "quotes are not supported: " + Quoted(name));
      }
      if (name.empty()) Fail(line_, c + 1, "empty column name");
      const auto it = std::find(kFieldNames.begin(), kFieldNames.end(), name);
      if (it == kFieldNames.end()) {
        std::string expected;
        for (const std::string_view known : kFieldNames) {
          expected += (expected.empty() ? "" : ", ") + std::string(known);
        }
        Fail(line_, c + 1,
             "unknown column " + Quoted(name) + " (the columns are " + expected + ")");
      }
      const Field field = static_cast<Field>(it - kFieldNames.begin());
      if (column_of_[field] >= 0) {
        Fail(line_, c + 1,
             "duplicate column " + Quoted(name) + " (also column " +
                 std::to_string(ColumnOf(field)) + ")");
      }
      column_of_[field] = c;
      fields_.push_back(field);
    }
    for (int f = 0; f < kRequiredFields; ++f) {
      if (column_of_[f] < 0) {
        Fail(line_, 0, "missing column '" + std::string(kFieldNames[f]) + "'");
      }
    }
    if ((column_of_[kGob] >= 0) != (column_of_[kContactLink] >= 0)) {
      const Field present = column_of_[kGob] >= 0 ? kGob : kContactLink;
      const Field absent = present == kGob ? kContactLink : kGob;
      Fail(line_, ColumnOf(present),
           "column '" + std::string(kFieldNames[present]) + "' requires column '" +
               std::string(kFieldNames[absent]) + "'");
    }
  }

  // The number in non-empty `cell` (column `column`, 1-based), finite, in the decimal syntax of
  // automaton/number_syntax.h.
  double ParseNumber(std::string_view cell, int column, Field field) const {
    const NumberRead<double> r = ReadDecimal(cell);
    const std::string quoted = Quoted(cell);
    switch (r.error) {
      case NumberError::kNone:
        return r.value;
      case NumberError::kOverflow:
        FailCell(column, field, "not finite (out of the range of a double): " + quoted);
      case NumberError::kUnderflow:
        FailCell(column, field, "too small for a double: " + quoted);
      default:
        FailCell(column, field,
                 (NamesNonFinite(cell) ? "not finite: " : "not a number: ") + quoted);
    }
  }

  // A joint angle in degrees, at most one turn either way: anything larger is no measurement of
  // the finger, and values near the range of a double overflowed the noise estimate (1e308
  // squared).
  double ParseAngle(std::string_view cell, int column, Field field) const {
    const double value = ParseNumber(cell, column, field);
    if (value < -360.0 || value > 360.0) {
      FailCell(column, field, "outside [-360, 360] degrees: " + Quoted(cell));
    }
    return value;
  }

  double ParseCounts(std::string_view cell, int column, Field field) const {
    const double value = ParseNumber(cell, column, field);
    if (value < 0.0 || value > kMaxCounts) {
      FailCell(column, field, "outside [0, 255]: " + Quoted(cell));
    }
    return value;
  }

  Row ParseRow(const std::vector<std::string_view>& cells) const {
    Row row;
    for (int c = 0; c < static_cast<int>(cells.size()); ++c) {
      const std::string_view cell = cells[c];
      const Field field = fields_[c];
      const int column = c + 1;
      if (cell.find('"') != std::string_view::npos) {
        FailCell(column, field, "quotes are not supported: " + Quoted(cell));
      }
      switch (field) {
        case kRun:
          if (cell.empty()) FailCell(column, field, "empty run label");
          row.run = std::string(cell);
          break;
        case kG:
          if (cell.empty()) FailCell(column, field, "empty; g is required on every row");
          row.g = ParseCounts(cell, column, field);
          break;
        case kTheta1:
        case kTheta2:
        case kTheta3:
          if (!cell.empty()) row.theta[field - kTheta1] = ParseAngle(cell, column, field);
          break;
        case kGob:
          if (!cell.empty()) row.gob = ParseCounts(cell, column, field);
          break;
        case kContactLink:
          if (!cell.empty()) {
            const double link = ParseNumber(cell, column, field);
            if (link != 1.0 && link != 2.0) {
              FailCell(column, field, "not 1 or 2: " + Quoted(cell));
            }
            row.contact_link = static_cast<int>(link);
          }
          break;
        case kPosition:
          if (!cell.empty()) row.position = ParseCounts(cell, column, field);
          break;
        case kFieldCount:
          break;
      }
    }
    if (row.position > row.g + kPositionRounding) {
      FailCell(ColumnOf(kPosition), kPosition,
               "the motor (" + FormatNumber(row.position) +
                   ") is past the request g = " + FormatNumber(row.g) +
                   "; the controller never drives the motor beyond the request");
    }
    return row;
  }

  void ReadRow(std::string_view line) {
    const std::vector<std::string_view> cells = SplitCsvCells(line);
    if (cells.size() != fields_.size()) {
      Fail(line_, 0,
           std::string(cells.size() < fields_.size() ? "too few" : "too many") +
               " cells: " + std::to_string(cells.size()) + " where the header has " +
               std::to_string(fields_.size()));
    }
    Row row = ParseRow(cells);

    if (data_.runs.empty() || row.run != data_.runs.back().label) {
      if (!data_.runs.empty()) CloseRun();
      if (const auto it = first_line_of_run_.find(row.run); it != first_line_of_run_.end()) {
        FailCell(ColumnOf(kRun), kRun,
                 "run " + Quoted(row.run) + " (from line " + std::to_string(it->second) +
                     ") reappears after run " + Quoted(data_.runs.back().label) +
                     "; the rows of a run must be contiguous");
      }
      first_line_of_run_.emplace(row.run, line_);
      MeasuredRun run;
      run.label = row.run;
      run.gob = row.gob;
      run.contact_link = row.contact_link;
      data_.runs.push_back(std::move(run));
    }
    MeasuredRun& run = data_.runs.back();

    if (row.gob.has_value() != row.contact_link.has_value()) {
      const Field empty = row.gob ? kContactLink : kGob;
      const Field given = empty == kGob ? kContactLink : kGob;
      FailCell(ColumnOf(empty), empty,
               "empty while '" + std::string(kFieldNames[given]) +
                   "' is given; give both (a contact run) or neither (a free-space run)");
    }
    if (row.gob != run.gob) {
      FailCell(ColumnOf(kGob), kGob,
               FormatOptional(row.gob) + " differs from " + FormatOptional(run.gob) +
                   " on the run's first row (line " + std::to_string(run.lines.front()) +
                   "); gob is constant within a run");
    }
    if (row.contact_link != run.contact_link) {
      FailCell(ColumnOf(kContactLink), kContactLink,
               FormatOptional(row.contact_link) + " differs from " +
                   FormatOptional(run.contact_link) + " on the run's first row (line " +
                   std::to_string(run.lines.front()) + "); contact_link is constant within a run");
    }

    run.g.push_back(row.g);
    if (column_of_[kPosition] >= 0) run.position.push_back(row.position);
    for (int j = 0; j < 3; ++j) run.theta[j].push_back(row.theta[j]);
    run.lines.push_back(line_);
  }

  // Checks the last run.
  void CloseRun() const {
    const MeasuredRun& run = data_.runs.back();
    if (static_cast<int>(run.g.size()) < kMinRunSamples) {
      Fail(run.lines.front(), ColumnOf(kRun),
           "run " + Quoted(run.label) + " has " + std::to_string(run.g.size()) + " sample" +
               (run.g.size() == 1 ? "" : "s") + "; a run needs at least " +
               std::to_string(kMinRunSamples));
    }
  }

  std::istream& in_;
  MeasuredData data_;
  int line_ = 0;
  int header_line_ = 0;
  // The field of each column, and the 0-based column of each field (-1 when absent).
  std::vector<Field> fields_;
  std::array<int, kFieldCount> column_of_{};
  std::map<std::string, int> first_line_of_run_;
};

bool Repeats(const MeasuredRun& a, const MeasuredRun& b) {
  if (a.gob != b.gob || a.contact_link != b.contact_link || a.g.size() != b.g.size()) {
    return false;
  }
  for (size_t i = 0; i < a.g.size(); ++i) {
    if (std::abs(a.g[i] - b.g[i]) > 1e-9) return false;
  }
  return true;
}

}  // namespace

int MeasuredData::samples() const {
  int n = 0;
  for (const MeasuredRun& run : runs) n += static_cast<int>(run.g.size());
  return n;
}

MeasuredData ReadMeasuredData(std::istream& in, const std::string& source) {
  return Reader(in, source).Read();
}

MeasuredData ReadMeasuredDataFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw DataError(path, 0, 0, "is a directory");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    throw DataError(path, 0, 0,
                    std::string("cannot open the file") +
                        (error != 0 ? std::string(": ") + std::strerror(error) : std::string()));
  }
  return ReadMeasuredData(in, path);
}

OutlierReport CleanOutliers(MeasuredData& data, double threshold) {
  if (!std::isfinite(threshold) || threshold <= 0.0) {
    throw std::invalid_argument("the outlier threshold must be finite and positive");
  }
  const double t = threshold;
  OutlierReport report;
  for (MeasuredRun& run : data.runs) {
    for (int j = 0; j < 3; ++j) {
      std::vector<double>& x = run.theta[j];
      const int n = static_cast<int>(x.size());
      // The first non-missing sample at or after `from`, or n.
      const auto present = [&](int from) {
        while (from < n && std::isnan(x[from])) ++from;
        return from;
      };
      int k = present(0);
      if (k == n) continue;
      double previous = x[k];  // the previous inlier
      for (k = present(k + 1); k < n;) {
        const int next = present(k + 1);  // not yet cleaned: as measured
        const double value = x[k];
        const bool outlier =
            std::abs(value - previous) > t && (next == n || std::abs(value - x[next]) > t);
        if (!outlier) {
          previous = value;
        } else {
          double lo = previous - t;
          double hi = previous + t;
          if (next < n) {
            lo = std::max(previous, x[next]) - t;
            hi = std::min(previous, x[next]) + t;
          }
          const double cleaned =
              lo <= hi ? std::clamp(value, lo, hi) : previous + (value > previous ? t : -t);
          x[k] = cleaned;
          ++report.clamped[j];
          report.entries.push_back({run.label, run.lines[k], j + 1, value, cleaned});
        }
        k = next;
      }
    }
  }
  return report;
}

NoiseFloor EstimateNoiseFloor(const MeasuredData& data, double spike_sigmas) {
  // Each run's repeat_of: the first earlier run it repeats.
  std::vector<int> repeat_of(data.runs.size());
  std::vector<DiagnosisRun> runs;
  bool repeated = false;
  for (size_t r = 0; r < data.runs.size(); ++r) {
    const MeasuredRun& run = data.runs[r];
    repeat_of[r] = static_cast<int>(r);
    for (size_t s = 0; s < r; ++s) {
      if (repeat_of[s] == static_cast<int>(s) && Repeats(data.runs[s], run)) {
        repeat_of[r] = static_cast<int>(s);
        repeated = true;
        break;
      }
    }
    runs.push_back(DiagnosisRun{run.label, run.g, {run.theta[0], run.theta[1], run.theta[2]}});
  }
  const ChannelNoise noise = EstimateChannelNoise(runs, repeat_of, spike_sigmas);
  NoiseFloor floor;
  floor.method = repeated ? "repeated_runs" : "second_differences";
  for (size_t j = 0; j < 3 && j < noise.variance.size(); ++j) {
    floor.variance[j] = noise.variance[j];
    floor.dof[j] = noise.dof[j];
  }
  return floor;
}

}  // namespace hybrid
