#pragma once

// What the program says when a command throws: one message for standard error, in the words of
// the command line (flags, by cli/flag_names.h), and the exit code (commands/exit_code.h). Messages
// never show C++ type or function names: the libraries' own messages carry none, and those of
// unexpected exceptions that name C++ internals ("std::bad_alloc", "vector::_M_realloc_insert",
// "[json.exception...]") are not shown.

#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>

#include "automaton/internal_assert.h"
#include "cli/flag_names.h"
#include "commands/command_error.h"
#include "commands/exit_code.h"
#include "commands/output.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/measured_data.h"

namespace hybrid::cli {

/// Whether `what` (the message of an unexpected exception) names C++ internals and must not be
/// shown: "std::...", "...::_M_...", "basic_string...", "bad_alloc", nlohmann's "[json.exception".
inline bool NamesCppInternals(std::string_view what) {
  for (const std::string_view marker :
       {"std::", "::", "_M_", "basic_string", "bad_alloc", "bad_array", "bad_function", "bad_cast",
        "bad_any", "bad_optional", "bad_variant", "[json.exception", "vector", "__"}) {
    if (what.find(marker) != std::string_view::npos) return true;
  }
  return what.empty();
}

/// A failed command as the program reports it: the message (one line, without its newline) and
/// the exit code.
struct ErrorReport {
  std::string message;
  ExitCode code;
};

/// The report of the exception `error` of the command `command` ("check", "simulate", ...;
/// its arguments are named by FlagName) whose messages begin with `prefix` ("hybrid check", or
/// the model file) (docs/cli.md, "Exit codes"):
/// - OptionError: "hybrid: MESSAGE" (or "PREFIX: MESSAGE" for Scope::kCommand), kUsage;
/// - InputError: "PREFIX: MESSAGE", kInput; ParseError and DataError: their located message,
///   kInput; OutputError: "hybrid: MESSAGE", kOutput;
/// - InternalError (a broken invariant, HYBRID_ASSERT): "hybrid: " and its message, kInternal;
/// - exhausted memory (std::bad_alloc, std::length_error): "hybrid: out of memory: ...",
///   kInternal;
/// - std::invalid_argument (a value a library refuses): "PREFIX: MESSAGE", `invalid_code`
///   (kInput where the model is what the libraries check, kUsage where the options are);
/// - anything else: "hybrid: internal error..." with its message unless it names C++ internals,
///   kInternal.
inline ErrorReport ReportError(std::exception_ptr error, std::string_view command,
                               const std::string& prefix, ExitCode invalid_code) {
  const auto text = [command](const CommandError& e) {
    return CommandLineText(command, e.message());
  };
  const std::string bug = " (a bug: please report it with the command that caused it)";
  try {
    std::rethrow_exception(error);
  } catch (const OptionError& e) {
    const bool by_command = e.scope() == OptionError::Scope::kCommand;
    return {(by_command ? prefix : "hybrid") + ": " + text(e), ExitCode::kUsage};
  } catch (const InputError& e) {
    return {prefix + ": " + text(e), ExitCode::kInput};
  } catch (const OutputError& e) {
    return {"hybrid: " + text(e), ExitCode::kOutput};
  } catch (const ParseError& e) {
    return {e.what(), ExitCode::kInput};
  } catch (const DataError& e) {
    return {e.what(), ExitCode::kInput};
  } catch (const InternalError& e) {
    return {std::string("hybrid: ") + e.what(), ExitCode::kInternal};
  } catch (const std::bad_alloc&) {
    return {"hybrid: out of memory: " + prefix +
                " needs more memory than the system could give; make the problem smaller (a "
                "shorter horizon, fewer samples, runs or modes)",
            ExitCode::kInternal};
  } catch (const std::length_error&) {
    return {"hybrid: out of memory: " + prefix +
                " asked for a block of memory larger than any the system can give; make the "
                "problem smaller",
            ExitCode::kInternal};
  } catch (const std::invalid_argument& e) {
    return {prefix + ": " + e.what(), invalid_code};
  } catch (const std::exception& e) {
    const std::string what = e.what();
    return {
        "hybrid: internal error" + (NamesCppInternals(what) ? std::string() : ": " + what) + bug,
        ExitCode::kInternal};
  } catch (...) {
    return {"hybrid: internal error" + bug, ExitCode::kInternal};
  }
}

}  // namespace hybrid::cli
