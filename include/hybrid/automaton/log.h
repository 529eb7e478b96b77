#pragma once

// The one logging facility of the libraries: engines report what they do (a solver query and its
// time, a failed replay, an induction step) through Log(); nothing is printed unless the program
// (`hybrid --log LEVEL`), the Python module (`hybrid.set_log_level`) or a user of the libraries
// installs a sink. Engines never print to std::cerr and read no environment variables.

#include <functional>
#include <string>
#include <string_view>

namespace hybrid {

/// How much a message matters: kDebug (every step, for developers), kInfo (one line per unit of
/// work: a query, a property), kWarning (something the user may want to know).
enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2 };

/// Receives the messages at or above the level it was installed with: `topic` names the engine
/// ("prove", "simulate", ...), `message` is one line without a newline. Called from the thread
/// that logs (engines may log from worker threads: a sink must be thread-safe; the default
/// stderr sink of StderrLogSink is).
using LogSink =
    std::function<void(LogLevel level, std::string_view topic, std::string_view message)>;

/// Installs `sink` for messages at `minimum` or above (replacing the previous one); an empty
/// sink turns logging off. Not to be called while engines run.
void SetLogSink(LogSink sink, LogLevel minimum = LogLevel::kInfo);

/// Whether a message at `level` would reach a sink: engines test it before composing a costly
/// message.
bool LogEnabled(LogLevel level);

/// Sends `message` to the sink if one is installed for `level`.
void Log(LogLevel level, std::string_view topic, std::string_view message);

/// A sink writing "hybrid [LEVEL] topic: message" lines to standard error, one write per line.
LogSink StderrLogSink();

/// "debug", "info" or "warning" as a level; false for anything else.
bool ParseLogLevel(std::string_view text, LogLevel* level);

}  // namespace hybrid
