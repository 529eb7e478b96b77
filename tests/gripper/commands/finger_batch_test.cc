// Tests of the batch queries of `hybrid finger` (gripper/commands/finger_batch.h): the queries file
// and the range are read exactly (positions, errors with row and column), and the answers are the
// report's free-space table (section 4.1: theta1 = g / 2 up to 140, theta3 = -g / 2 down to -55 at
// 110, theta2 = 0.9 (g - 140) after 140, stopped at 240 against the palm) in CSV and JSON.

#include "gripper/commands/finger_batch.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::cli {
namespace {

// A file holding `text` in the test's temporary directory.
std::string FileWith(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(FingerBatch, ReadsTheQueriesFile) {
  const std::string path = FileWith("q.csv", "# comment\ng\n0\n\n 102 \n153.5\r\n255\n");
  EXPECT_EQ(ReadMotorPositions(path, 10), (std::vector<double>{0, 102, 153.5, 255}));
}

TEST(FingerBatch, QueriesFileErrorsNameTheRowAndColumn) {
  const struct {
    std::string text;
    std::string where;
    std::string what;
  } cases[] = {
      {"x\n1\n", ":1:1:", "the header must be 'g'"},
      {"g\n1\n2,3\n", ":3:2:", "one column expected"},
      {"g\n1\n 0x10\n", ":3:2:", "(CSV row 3, column 1)"},
      {"g\n256\n", ":2:1:", "outside [0, 255]"},
      {"g\n", ":1:1:", "no queries"},
      {"g\n1\n2\n3\n", ":4:1:", "more than 2 queries"},
  };
  for (const auto& c : cases) {
    const std::string path = FileWith("bad.csv", c.text);
    try {
      ReadMotorPositions(path, 2);
      ADD_FAILURE() << c.text;
    } catch (const ParseError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + c.where), std::string::npos) << message;
      EXPECT_NE(message.find(c.what), std::string::npos) << message;
    }
  }
  EXPECT_THROW(ReadMotorPositions(FileWith("none", "") + "/missing", 2), ParseError);
}

TEST(FingerBatch, RangeIsEvenlySpacedWithExactEnds) {
  EXPECT_EQ(MotorRange("0:255:4", 10), (std::vector<double>{0, 85, 170, 255}));
  EXPECT_EQ(MotorRange("7:7:1", 10), (std::vector<double>{7}));
  EXPECT_EQ(MotorRange("0.1:0.3:3", 10).back(), 0.3);  // STOP itself, not 0.1 + 2 * 0.1
  for (const char* bad :
       {"0:255", "0:255:0", "0:255:11", "0:256:2", "a:1:2", "0:1:2:3", "0:1:-2"}) {
    EXPECT_THROW(MotorRange(bad, 10), OptionError) << bad;
  }
  try {
    MotorRange("0:255", 10);
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "g_range");
    EXPECT_EQ(std::string(e.what()), "g_range '0:255': expected START:STOP:COUNT");
  }
}

TEST(FingerBatch, AnswersAreTheFreeSpaceTable) {
  const gripper::FingerClosedForm closed;
  const std::vector<double> g = {0, 102, 153.5, 255};
  EXPECT_EQ(BatchCsv(closed, g),
            "g,motor,theta1,theta2,theta3,phase,mode\n"
            "0,0,0,0,0,1,c000_l000\n"
            "102,102,51,0,-51,1,c000_l000\n"
            "153.5,153.5,70,12.15,-55,2',c000_l10n\n"
            "255,240,70,90,-55,4,c000_l11n\n");
  const auto json = nlohmann::json::parse(BatchJson(closed, g));
  ASSERT_EQ(json.size(), 4u);
  EXPECT_EQ(json[2].at("theta2").get<double>(), 12.15);
  EXPECT_EQ(json[3].at("motor").get<double>(), 240.0);
  EXPECT_EQ(json[3].at("phase").get<std::string>(), "4");
}

}  // namespace
}  // namespace hybrid::cli
