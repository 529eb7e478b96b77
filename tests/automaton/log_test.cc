// Tests of the logging facility (include/hybrid/automaton/log.h): nothing reaches anyone without a
// sink, the level filters, an empty sink turns logging off, and the level names.

#include "hybrid/automaton/log.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hybrid {
namespace {

struct Line {
  LogLevel level;
  std::string topic, message;
};

TEST(Log, ReachesTheSinkAtOrAboveItsLevel) {
  std::vector<Line> lines;
  SetLogSink(
      [&](LogLevel level, std::string_view topic, std::string_view message) {
        lines.push_back({level, std::string(topic), std::string(message)});
      },
      LogLevel::kInfo);
  EXPECT_FALSE(LogEnabled(LogLevel::kDebug));
  EXPECT_TRUE(LogEnabled(LogLevel::kInfo));
  Log(LogLevel::kDebug, "prove", "not shown");
  Log(LogLevel::kInfo, "prove", "query: sat");
  Log(LogLevel::kWarning, "simulate", "slow");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].topic, "prove");
  EXPECT_EQ(lines[0].message, "query: sat");
  EXPECT_EQ(lines[1].level, LogLevel::kWarning);
  SetLogSink({});
  EXPECT_FALSE(LogEnabled(LogLevel::kWarning));
  Log(LogLevel::kWarning, "simulate", "after the sink was removed");
  EXPECT_EQ(lines.size(), 2u);
}

TEST(Log, LevelNames) {
  LogLevel level = LogLevel::kWarning;
  EXPECT_TRUE(ParseLogLevel("debug", &level));
  EXPECT_EQ(level, LogLevel::kDebug);
  EXPECT_TRUE(ParseLogLevel("info", &level));
  EXPECT_EQ(level, LogLevel::kInfo);
  EXPECT_TRUE(ParseLogLevel("warning", &level));
  EXPECT_EQ(level, LogLevel::kWarning);
  EXPECT_FALSE(ParseLogLevel("DEBUG", &level));
  EXPECT_FALSE(ParseLogLevel("", &level));
}

}  // namespace
}  // namespace hybrid
