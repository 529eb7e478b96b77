// Tests of commands/argument_message.h: messages that refer to the commands' arguments by their
// API names, rendered by each front end in its own words.

#include "commands/argument_message.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace hybrid::cli {
namespace {

using ::testing::ElementsAre;

// The API's words name each argument as it is; a front end gives its own names.
TEST(ArgumentMessage, RendersReferencesAsEachFrontEndNamesThem) {
  const ArgumentMessage m = Arg("free_runs") + " 3 and " + Arg("samples") + " 10 make 9 runs";
  EXPECT_EQ(m.Text(), "free_runs 3 and samples 10 make 9 runs");
  EXPECT_EQ(m.Render([](const std::string& a) { return "--" + a; }),
            "--free_runs 3 and --samples 10 make 9 runs");
  EXPECT_THAT(m.Arguments(), ElementsAre("free_runs", "samples"));
}

// Text taken from the user is literal: braces, percent signs and backslashes mean nothing.
TEST(ArgumentMessage, LiteralTextIsKeptAsItIs) {
  const std::string spec = "{until}=%s\\1";
  const ArgumentMessage m = Arg("parameters") + " '" + spec + "': expected NAME=VALUE";
  EXPECT_EQ(m.Render([](const std::string&) { return "X"; }),
            "X '{until}=%s\\1': expected NAME=VALUE");
  EXPECT_THAT(m.Arguments(), ElementsAre("parameters"));
  EXPECT_TRUE(ArgumentMessage("").empty());
  EXPECT_TRUE(ArgumentMessage().Arguments().empty());
}

// Text before a reference, references side by side, and equal messages however they were built.
TEST(ArgumentMessage, ConcatenatesInEveryOrder) {
  const ArgumentMessage m = "pass " + Arg("model") + Arg("data") + std::string(" FILE");
  EXPECT_EQ(m.Render([](const std::string& a) { return "<" + a + ">"; }),
            "pass <model><data> FILE");
  ArgumentMessage built = "pass ";
  built += Arg("model");
  built += Arg("data");
  built += " ";
  built += "FILE";
  EXPECT_EQ(built, m);
  EXPECT_FALSE(built == ArgumentMessage("pass model data FILE"));  // references are not text
}

}  // namespace
}  // namespace hybrid::cli
