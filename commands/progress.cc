#include "commands/progress.h"

#include <unistd.h>

#include <utility>

namespace hybrid::cli {

ProgressLine::ProgressLine(std::string command, ProgressMode mode, std::FILE* stream)
    : command_(std::move(command)), stream_(stream), start_(std::chrono::steady_clock::now()) {
  terminal_ = isatty(fileno(stream_)) == 1;
  enabled_ = mode == ProgressMode::kOn || (mode == ProgressMode::kAuto && terminal_);
  last_ = start_;
}

ProgressLine::~ProgressLine() {
  if (shown_) {
    std::fputs("\r\033[K", stream_);
    std::fflush(stream_);
  }
}

void ProgressLine::Report(const std::string& text, bool force) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const auto gap = terminal_ ? std::chrono::milliseconds(100) : std::chrono::milliseconds(1000);
  if (reported_ && !force && now - last_ < gap) return;
  reported_ = true;
  last_ = now;
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, ", %.1f s",
                std::chrono::duration<double>(now - start_).count());
  const std::string line = "hybrid " + command_ + ": " + text + seconds;
  if (terminal_) {
    std::fprintf(stream_, "\r\033[K%s", line.c_str());
    shown_ = true;
  } else {
    std::fprintf(stream_, "%s\n", line.c_str());
  }
  std::fflush(stream_);
}

}  // namespace hybrid::cli
