#include "hybrid/automaton/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <string>
#include <utility>

namespace hybrid {
namespace {

struct Logger {
  std::mutex mutex;
  LogSink sink;
  // The lowest level that reaches the sink; above kWarning when there is none.
  std::atomic<int> minimum{static_cast<int>(LogLevel::kWarning) + 1};
};

Logger& TheLogger() {
  static Logger logger;
  return logger;
}

const char* LevelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarning:
      return "warning";
  }
  return "?";
}

}  // namespace

void SetLogSink(LogSink sink, LogLevel minimum) {
  Logger& logger = TheLogger();
  const std::lock_guard lock(logger.mutex);
  logger.minimum = sink ? static_cast<int>(minimum) : static_cast<int>(LogLevel::kWarning) + 1;
  logger.sink = std::move(sink);
}

bool LogEnabled(LogLevel level) {
  return static_cast<int>(level) >= TheLogger().minimum.load(std::memory_order_relaxed);
}

void Log(LogLevel level, std::string_view topic, std::string_view message) {
  if (!LogEnabled(level)) return;
  Logger& logger = TheLogger();
  const std::lock_guard lock(logger.mutex);
  if (logger.sink && static_cast<int>(level) >= logger.minimum) logger.sink(level, topic, message);
}

LogSink StderrLogSink() {
  return [](LogLevel level, std::string_view topic, std::string_view message) {
    std::string line = "hybrid [";
    line += LevelName(level);
    line += "] ";
    line += topic;
    line += ": ";
    line += message;
    line += '\n';
    std::fwrite(line.data(), 1, line.size(), stderr);
  };
}

bool ParseLogLevel(std::string_view text, LogLevel* level) {
  for (const LogLevel l : {LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarning}) {
    if (text == LevelName(l)) {
      *level = l;
      return true;
    }
  }
  return false;
}

}  // namespace hybrid
