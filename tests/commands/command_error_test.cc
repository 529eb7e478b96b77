// Tests of commands/command_error.h: the errors of the commands speak of arguments by their API
// names (what()) and keep the references for a front end (message()); OptionNumber reads a number
// of an argument's value, refusing anything else with an OptionError about that argument.

#include "commands/command_error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace hybrid::cli {
namespace {

using ::testing::ElementsAre;

TEST(OptionError, NamesItsArgumentAndKeepsTheReferences) {
  const OptionError e("method", Arg("method") + " must be 'auto' or 'reach', not 'x'",
                      OptionError::Scope::kCommand);
  EXPECT_EQ(e.argument(), "method");
  EXPECT_EQ(std::string(e.what()), "method must be 'auto' or 'reach', not 'x'");
  EXPECT_THAT(e.message().Arguments(), ElementsAre("method"));
  EXPECT_EQ(e.scope(), OptionError::Scope::kCommand);
  EXPECT_EQ(OptionError("until", "x").scope(), OptionError::Scope::kProgram);
  // No flag in the API's words.
  EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos);
}

TEST(InputError, IsACommandErrorWithReferences) {
  const InputError e("d.csv: no run has the finger's object (" + Arg("objects") + ")");
  const CommandError& base = e;
  EXPECT_EQ(std::string(base.what()), "d.csv: no run has the finger's object (objects)");
  EXPECT_THAT(base.message().Arguments(), ElementsAre("objects"));
}

TEST(OptionNumber, ReadsDecimalNumbersAndRefusesTheRestAboutTheArgument) {
  EXPECT_EQ(OptionNumber("parameters", "+1e1", "a"), 10.0);
  EXPECT_EQ(OptionNumber("until", ".5"), 0.5);
  try {
    OptionNumber("parameters", "0x10", "a");
    FAIL() << "no exception";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "parameters");
    EXPECT_EQ(std::string(e.what()), "parameters a: '0x10' is not a decimal number");
    EXPECT_EQ(e.message(), Arg("parameters") + " a: '0x10' is not a decimal number");
  }
  try {
    OptionNumber("effects", "");
    FAIL() << "no exception";
  } catch (const OptionError& e) {
    EXPECT_EQ(std::string(e.what()), "effects: empty: a number is required");
  }
  for (const char* bad : {"inf", "nan", "1e999", "+-1", "5s", " 1"}) {
    EXPECT_THROW(OptionNumber("until", bad), OptionError) << bad;
  }
}

}  // namespace
}  // namespace hybrid::cli
