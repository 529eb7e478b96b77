#pragma once

// The exit codes of the `hybrid` program, one list for every command (docs/cli.md, "Exit codes").

namespace hybrid::cli {

/// What a command's run came to, as the program's exit status.
enum class ExitCode : int {
  /// Success.
  kOk = 0,
  /// Invalid model or input: a syntax error, an invalid declaration, a malformed data file, an
  /// input the model refuses, an object the gripper cannot hold (FILE:LINE:COL: message).
  kInput = 1,
  /// Usage error: an unknown command or option, a malformed or out-of-range option value,
  /// outputs naming one file or an input (the message names the option).
  kUsage = 2,
  /// An output cannot be written.
  kOutput = 3,
  /// Out of memory, or an internal error (a bug).
  kInternal = 4,
  /// `simulate`: the run stopped before its horizon; `finger --simulate`, `hand --simulate`: the
  /// simulation did not complete or differs from the closed form.
  kSimulationFailed = 5,
  /// `check`: a property is violated, or a reach target is unreachable.
  kViolated = 6,
  /// `check`: no property violated, but some verdict is unknown.
  kUnknown = 7,
};

/// `code` as a process exit status.
constexpr int ExitStatus(ExitCode code) { return static_cast<int>(code); }

}  // namespace hybrid::cli
