// Tests of cli/flag_names.h: the program names the commands' arguments by their flags (the only
// place that does), each command its own way where they differ.

#include "cli/flag_names.h"

#include <gtest/gtest.h>

#include <string>

namespace hybrid::cli {
namespace {

TEST(FlagName, DashesAndUnderscoresByDefault) {
  EXPECT_EQ(FlagName("simulate", "until"), "--until");
  EXPECT_EQ(FlagName("dot", "group_by"), "--group-by");
  EXPECT_EQ(FlagName("diagnose", "out_model"), "--out-model");
  EXPECT_EQ(FlagName("hand", "g_a"), "--g-a");
  EXPECT_EQ(FlagName("synthesize", "free_runs"), "--free-runs");
  EXPECT_EQ(FlagName("finger", "gob2"), "--gob2");
}

TEST(FlagName, FlagsSpelledApartFromTheirApiNames) {
  EXPECT_EQ(FlagName("simulate", "parameters"), "--set");
  EXPECT_EQ(FlagName("simulate", "inputs"), "--input");
  EXPECT_EQ(FlagName("check", "properties"), "--property");
  EXPECT_EQ(FlagName("hand", "objects"), "--object");
  EXPECT_EQ(FlagName("synthesize", "effects"), "--effect");
  EXPECT_EQ(FlagName("finger", "draw_at"), "--at");
}

// The model is positional for the model commands and an option for the gripper's.
TEST(FlagName, DependsOnTheCommandWhereCommandsDiffer) {
  for (const char* command : {"info", "dot", "import", "simulate", "check"}) {
    EXPECT_EQ(FlagName(command, "model"), "MODEL") << command;
  }
  for (const char* command : {"finger", "hand", "diagnose", "synthesize"}) {
    EXPECT_EQ(FlagName(command, "model"), "--model") << command;
  }
  EXPECT_EQ(FlagName("diagnose", "data"), "DATA");
  EXPECT_EQ(FlagName("finger", "data"), "--data");
  EXPECT_EQ(FlagName("dot", "output"), "-o");
  EXPECT_EQ(FlagName("import", "output"), "-o");
  EXPECT_EQ(FlagName("finger", "output"), "-o/--output");
  EXPECT_EQ(FlagName("simulate", "out"), "--out");
}

TEST(CommandLineText, RendersEveryReference) {
  EXPECT_EQ(CommandLineText("finger",
                            Arg("output") + " needs " + Arg("queries") + " or " + Arg("g_range")),
            "-o/--output needs --queries or --g-range");
  EXPECT_EQ(CommandLineText("simulate", "recording the state every 1e-09 (" + Arg("sample") +
                                            ") up to t = 120 (" + Arg("until") + ")"),
            "recording the state every 1e-09 (--sample) up to t = 120 (--until)");
}

}  // namespace
}  // namespace hybrid::cli
