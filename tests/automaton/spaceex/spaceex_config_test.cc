#include "automaton/spaceex/spaceex_config.h"

#include <gtest/gtest.h>

#include <string>

#include "hybrid/automaton/parser.h"

namespace hybrid::spaceex {
namespace {

std::string Error(const std::string& text) {
  try {
    SpaceExConfig(text, "m.cfg");
  } catch (const ParseError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SpaceExConfigTest, ReadsQuotedAndPlainValuesAndSkipsComments) {
  const std::string text =
      "# options\n"
      "system = \"sys\"\n"
      "// another comment\n"
      "initially = \"x == 0 &\n   loc(P1) == a\"\n"
      "time-horizon=40   \n";
  const SpaceExConfig cfg(text, "m.cfg");
  EXPECT_EQ(cfg.Find("system")->text, "sys");
  EXPECT_EQ(cfg.Find("initially")->text, "x == 0 &\n   loc(P1) == a");
  EXPECT_EQ(cfg.Find("time-horizon")->text, "40");
  EXPECT_FALSE(cfg.Find("forbidden"));
  // Offsets lead back to lines and columns: 'x' of initially is on line 4, column 14.
  EXPECT_EQ(cfg.LineColumn(cfg.Find("initially")->offset), std::make_pair(4, 14));
  EXPECT_EQ(cfg.LineColumn(cfg.Find("initially")->offset + 12), std::make_pair(5, 4));
}

TEST(SpaceExConfigTest, MalformedLinesAreReportedAtTheirPosition) {
  EXPECT_EQ(Error("system = \"s\"\nbad line\n"), "m.cfg:2:5: expected 'option = value'");
  EXPECT_EQ(Error("a = \"open\n"), "m.cfg:1:5: unterminated '\"'");
  EXPECT_EQ(Error("a = \"v\" junk\n"), "m.cfg:1:9: unexpected text after the closing '\"'");
  EXPECT_EQ(Error("a = 1\na = 2\n"), "m.cfg:2:1: option 'a' is given twice");
}

}  // namespace
}  // namespace hybrid::spaceex
