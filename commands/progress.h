#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace hybrid::cli {

/// Whether a long command reports its progress on standard error.
enum class ProgressMode {
  kAuto,  ///< when standard error is a terminal (the default)
  kOn,    ///< always (--progress): on a terminal one rewritten line, elsewhere lines
  kOff,   ///< never (--quiet; the Python module)
};

/// A progress report of a long run on standard error, "hybrid COMMAND: TEXT, 12.3 s" (the time
/// since the report began). On a terminal it
/// rewrites one line (carriage return, erase to the end) at most every 0.1 s and erases it when
/// the run ends; elsewhere (forced with kOn) it writes whole lines, the first report and then at
/// most one per second. Only what is printed depends on the clock: the run itself does not.
class ProgressLine {
 public:
  /// `command` names the command ("check"); `stream` is where reports go (standard error).
  ProgressLine(std::string command, ProgressMode mode, std::FILE* stream = stderr);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  bool enabled() const { return enabled_; }
  /// Reports `text` and the seconds elapsed (dropped if the last report was too recent; `force`
  /// prints it anyway).
  void Report(const std::string& text, bool force = false);

 private:
  std::string command_;
  std::FILE* stream_;
  bool enabled_ = false;
  bool terminal_ = false;
  bool shown_ = false;  // a rewritten line is on the terminal
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_;
  bool reported_ = false;
};

}  // namespace hybrid::cli
