#pragma once

// Shared helpers for tests that run a command of the command library in this process (instead
// of starting the program): its arguments, and its exit code and standard output. For what a
// command computes and writes; the tests of the command line itself (options, messages on
// standard error, exit codes of errors, the process's memory) run the program
// (tests/test_utilities/command_line.h).

#include <iostream>
#include <sstream>
#include <string>

#include "commands/exit_code.h"

namespace hybrid::testing {

/// A command's arguments: `model`, the other fields their defaults.
template <typename T>
T ArgsOf(const std::string& model) {
  T a;
  a.model = model;
  return a;
}

/// A command's arguments: `model`, and the fields `set` sets (the others their defaults).
template <typename T, typename Set>
T ArgsOf(const std::string& model, Set set) {
  T a = ArgsOf<T>(model);
  set(a);
  return a;
}

/// The exit code of a command run in this process and what it wrote on standard output.
struct InProcess {
  int exit_code = -1;
  std::string out;
};

/// Runs `run` (returning a cli::ExitCode, e.g. `[&] { return cli::RunCheck(args); }`) with
/// std::cout captured; std::cout is restored also when `run` throws.
template <typename Run>
InProcess RunInProcess(Run run) {
  std::ostringstream out;
  struct Restore {
    std::streambuf* buffer;
    ~Restore() { std::cout.rdbuf(buffer); }
  } restore{std::cout.rdbuf(out.rdbuf())};
  const int exit_code = cli::ExitStatus(run());
  return {exit_code, out.str()};
}

}  // namespace hybrid::testing
