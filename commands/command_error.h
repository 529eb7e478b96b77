#pragma once

// The errors the commands raise for what their caller gave them, in the words of the model and
// of the API (commands/argument_message.h): each front end renders the arguments a message refers
// to in its own words and maps the error to its own outcome (the program: an exit code,
// commands/exit_code.h; the Python module: ValueError).

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "automaton/number_syntax.h"
#include "commands/argument_message.h"

namespace hybrid::cli {

/// An error of a command whose message may refer to the command's arguments. what() is the
/// message in the API's words (ArgumentMessage::Text); message() keeps the references for a front
/// end to render.
class CommandError : public std::runtime_error {
 public:
  explicit CommandError(ArgumentMessage message)
      : std::runtime_error(message.Text()), message_(std::move(message)) {}

  /// The message, with its references to arguments.
  const ArgumentMessage& message() const { return message_; }

 private:
  ArgumentMessage message_;
};

/// A bad value of an argument of a command, or arguments that do not go together (an unknown
/// name in `parameters`, a malformed effect, two outputs naming one file, a depth out of range):
/// exit code 2 on the command line, ValueError in Python. The message speaks of arguments only
/// through references (never a flag).
class OptionError : public CommandError {
 public:
  /// Who the program says refuses the value: the program itself ("hybrid: ...", how arguments
  /// are written and combined) or the command by its name ("hybrid check: --depth must be in
  /// [0, 1000]", a value outside what the command accepts), as it always has. Only the program
  /// reads it.
  enum class Scope { kProgram, kCommand };

  /// An error about `argument` (its API name: "until", "method"), with `message`.
  OptionError(std::string argument, ArgumentMessage message, Scope scope = Scope::kProgram)
      : CommandError(std::move(message)), argument_(std::move(argument)), scope_(scope) {}

  /// The API name of the argument the error is about.
  const std::string& argument() const { return argument_; }
  Scope scope() const { return scope_; }

 private:
  std::string argument_;
  Scope scope_;
};

/// Input a command cannot use although it is well formed: objects the gripper cannot hold, a
/// model that is not the finger the command needs, measured runs that match nothing: exit code 1
/// on the command line (after the command's name), ValueError in Python.
class InputError : public CommandError {
 public:
  using CommandError::CommandError;
};

/// `text` (the value of `argument`, or a part of it) read as a double in the decimal syntax of
/// automaton/number_syntax.h. Otherwise throws OptionError about `argument`, "ARGUMENT[ DETAIL]:
/// WHY" with a reference to the argument ("parameters gob1: '0x10' is not a decimal number", on
/// the command line "--set gob1: ...").
inline double OptionNumber(const std::string& argument, std::string_view text,
                           const std::string& detail = "") {
  const NumberRead<double> r = ReadDecimal(text);
  if (!r.ok()) {
    throw OptionError(argument, Arg(argument) + (detail.empty() ? "" : " " + detail) + ": " +
                                    NumberErrorMessage(text, r.error));
  }
  return r.value;
}

}  // namespace hybrid::cli
