// Tests of cli/error_report.h: what the program says, and the exit code, for each kind of error a
// command throws; messages name flags (never API names or C++ names).

#include "cli/error_report.h"

#include <gtest/gtest.h>

#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "automaton/internal_assert.h"

namespace hybrid::cli {
namespace {

template <typename E>
ErrorReport ReportOf(const E& error, const std::string& command = "check",
                     ExitCode invalid_code = ExitCode::kUsage) {
  return ReportError(std::make_exception_ptr(error), command, "hybrid " + command, invalid_code);
}

TEST(ReportError, OptionErrorsNameFlagsAndExitTwo) {
  const ErrorReport usage = ReportOf(
      OptionError("g_range", Arg("queries") + " and " + Arg("g_range") + " cannot be combined"),
      "finger");
  EXPECT_EQ(usage.message, "hybrid: --queries and --g-range cannot be combined");
  EXPECT_EQ(usage.code, ExitCode::kUsage);
  // A value the command refuses is said in the command's name.
  const ErrorReport range = ReportOf(
      OptionError("depth", Arg("depth") + " must be in [0, 1000]", OptionError::Scope::kCommand));
  EXPECT_EQ(range.message, "hybrid check: --depth must be in [0, 1000]");
  EXPECT_EQ(range.code, ExitCode::kUsage);
}

TEST(ReportError, InputAndOutputErrors) {
  const ErrorReport input = ReportOf(
      InputError("d.csv: no run has the finger's object (" + Arg("objects") + ")"), "finger");
  EXPECT_EQ(input.message, "hybrid finger: d.csv: no run has the finger's object (--object)");
  EXPECT_EQ(input.code, ExitCode::kInput);
  const ErrorReport output =
      ReportOf(OutputError("cannot write " + Arg("output") + " 'x': it is a directory"), "dot");
  EXPECT_EQ(output.message, "hybrid: cannot write -o 'x': it is a directory");
  EXPECT_EQ(output.code, ExitCode::kOutput);
  const ErrorReport parse = ReportOf(ParseError("m.ha", 3, 7, "expected ';'"), "info");
  EXPECT_EQ(parse.message, "m.ha:3:7: expected ';'");
  EXPECT_EQ(parse.code, ExitCode::kInput);
}

// A broken invariant is a bug: exit 4 with its message (which names the invariant and where).
TEST(ReportError, InternalErrorsExitFourWithTheirMessage) {
  try {
    HYBRID_ASSERT(1 + 1 == 3, "arithmetic holds");
    FAIL() << "no exception";
  } catch (...) {
    const ErrorReport r =
        ReportError(std::current_exception(), "check", "hybrid check", ExitCode::kUsage);
    EXPECT_EQ(r.code, ExitCode::kInternal);
    EXPECT_TRUE(
        r.message.starts_with("hybrid: internal error (a bug of hybrid, please report "
                              "it): arithmetic holds [1 + 1 == 3 failed at "))
        << r.message;
  }
}

TEST(ReportError, LibraryValuesMemoryAndUnexpectedErrors) {
  const ErrorReport value =
      ReportOf(std::invalid_argument("the data have no runs"), "diagnose", ExitCode::kUsage);
  EXPECT_EQ(value.message, "hybrid diagnose: the data have no runs");
  EXPECT_EQ(value.code, ExitCode::kUsage);
  const ErrorReport memory = ReportOf(std::bad_alloc());
  EXPECT_TRUE(memory.message.starts_with("hybrid: out of memory: hybrid check needs more memory"))
      << memory.message;
  EXPECT_EQ(memory.code, ExitCode::kInternal);
  const ErrorReport plain = ReportOf(std::runtime_error("the solver failed"));
  EXPECT_EQ(plain.message,
            "hybrid: internal error: the solver failed (a bug: please report it with the command "
            "that caused it)");
  const ErrorReport cpp = ReportOf(std::runtime_error("vector::_M_realloc_insert"));
  EXPECT_EQ(cpp.message,
            "hybrid: internal error (a bug: please report it with the command that caused it)");
  EXPECT_EQ(cpp.code, ExitCode::kInternal);
}

TEST(NamesCppInternals, SpotsTypeAndFunctionNames) {
  for (const std::string internal :
       {"std::bad_alloc", "vector::_M_realloc_insert", "basic_string::_M_create", "map::at",
        "bad_optional_access", "[json.exception.type_error.302] type must be number", ""}) {
    EXPECT_TRUE(NamesCppInternals(internal)) << internal;
  }
  for (const std::string plain : {"cannot write 'x.csv'", "the solver failed at t = 3"}) {
    EXPECT_FALSE(NamesCppInternals(plain)) << plain;
  }
}

}  // namespace
}  // namespace hybrid::cli
