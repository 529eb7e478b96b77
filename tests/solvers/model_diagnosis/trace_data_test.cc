#include "hybrid/model_diagnosis/trace_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "hybrid/automaton/parser.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

System Thermostat() { return ParseModel(testing::SpecText("thermostat"), "thermostat.ha"); }

// `rows` rows of run `run` from time `t0`, 1 apart: "run,t,u,x".
std::string Rows(const std::string& run, int rows, double t0 = 0.0) {
  std::string text;
  for (int k = 0; k < rows; ++k) {
    text += run + "," + std::to_string(t0 + k) + ",10," + std::to_string(20.0 - 0.1 * k) + "\n";
  }
  return text;
}

TraceData Read(const std::string& text) {
  std::istringstream in(text);
  return ReadTraceData(in, "t.csv", Thermostat());
}

TEST(TraceData, ReadsRunsInputsAndObservedVariables) {
  const TraceData d = Read("# a comment\nrun,time,u,x\n" + Rows("a", 12) + Rows("b", 10));
  ASSERT_EQ(d.runs.size(), 2u);
  EXPECT_EQ(d.input_names, std::vector<std::string>{"u"});
  EXPECT_EQ(d.observed_names, std::vector<std::string>{"x"});
  EXPECT_EQ(d.runs[0].label, "a");
  EXPECT_EQ(d.runs[0].time.size(), 12u);
  EXPECT_DOUBLE_EQ(d.runs[0].observed[0][3], 19.7);
  EXPECT_DOUBLE_EQ(d.runs[1].inputs[0][0], 10.0);
  EXPECT_EQ(d.runs[0].lines.front(), 3);
}

TEST(TraceData, WithoutRunColumnTheFileIsOneRunAndEmptyCellsAreMissing) {
  std::string text = "time,x\n";
  for (int k = 0; k < 10; ++k) text += std::to_string(k) + "," + (k == 4 ? "" : "20") + "\n";
  const TraceData d = Read(text);
  ASSERT_EQ(d.runs.size(), 1u);
  EXPECT_EQ(d.runs[0].label, "1");
  EXPECT_TRUE(std::isnan(d.runs[0].observed[0][4]));
  EXPECT_TRUE(d.input_names.empty());
}

TEST(TraceData, ModeColumnNamesModes) {
  std::string text = "time,x,mode\n";
  for (int k = 0; k < 10; ++k) text += std::to_string(k) + ",20," + (k < 5 ? "off" : "") + "\n";
  EXPECT_EQ(Read(text).runs[0].mode[0], "off");
}

struct BadTrace {
  std::string name;
  std::string text;
  std::string message;  // what() must start with it
};

class DiagnoseTraceBadData : public ::testing::TestWithParam<BadTrace> {};

TEST_P(DiagnoseTraceBadData, NamesLineAndColumn) {
  try {
    Read(GetParam().text);
    FAIL() << "accepted";
  } catch (const DataError& e) {
    EXPECT_EQ(std::string(e.what()).substr(0, GetParam().message.size()), GetParam().message)
        << e.what();
  }
}

const std::string kHeader = "run,time,u,x\n";

INSTANTIATE_TEST_SUITE_P(
    Table, DiagnoseTraceBadData,
    ::testing::Values(
        BadTrace{"Empty", "", "t.csv:0:0: no header"},
        BadTrace{"UnknownColumn", "run,time,u,y\n" + Rows("a", 10),
                 "t.csv:1:4: unknown column 'y'; the columns are run, time, mode, x, u"},
        BadTrace{"ParameterColumn", "time,p\n", "t.csv:1:2: unknown column 'p' (a parameter"},
        BadTrace{"Duplicate", "time,x,x\n", "t.csv:1:3: duplicate column 'x'"},
        BadTrace{"NoTime", "run,x\n", "t.csv:1:0: no 'time' column"},
        BadTrace{"NoVariable", "run,time,u\n", "t.csv:1:0: no column of a continuous variable"},
        BadTrace{"NoRows", kHeader, "t.csv:1:0: no data rows"},
        BadTrace{"NotANumber", kHeader + "a,0,10,abc\n", "t.csv:2:4: 'abc'"},
        BadTrace{"TimeBackwards", kHeader + "a,1,10,20\na,0.5,10,20\n",
                 "t.csv:3:2: time must increase within a run"},
        BadTrace{"NegativeTime", kHeader + "a,-1,10,20\n", "t.csv:2:2: time must be >= 0"},
        BadTrace{"InputOutOfBounds", kHeader + "a,0,99,20\n",
                 "t.csv:2:3: input 'u' = 99 is outside its bounds [-20, 30]"},
        BadTrace{"ShortRun", kHeader + Rows("a", 9), "t.csv:2:0: run 'a' has 9 rows"},
        BadTrace{"RunComesBack", kHeader + Rows("a", 10) + Rows("b", 10) + Rows("a", 10, 20),
                 "t.csv:22:1: run 'a' comes back after another run"},
        BadTrace{"TooFewCells", kHeader + "a,0,10\n", "t.csv:2:0: the row has 3 cells"},
        BadTrace{"Quote", kHeader + "a,0,10,\"20\"\n", "t.csv:2:4: quotes are not supported"},
        BadTrace{"UnknownMode", "time,x,mode\n0,20,of\n", "t.csv:2:3: the model has no mode 'of'"},
        BadTrace{"EmptyInputThroughout",
                 kHeader + "a,0,,20\na,1,,20\na,2,,20\na,3,,20\na,4,,20\na,5,,20\na,6,,20\n"
                           "a,7,,20\na,8,,20\na,9,,20\n",
                 "t.csv:2:0: input 'u' is empty throughout run 'a'"}),
    [](const auto& info) { return info.param.name; });

TEST(TraceData, IsTraceFileLooksForTimeInTheHeader) {
  EXPECT_TRUE(IsTraceFile(std::string(HYBRID_SOURCE_DIR) + "/data/thermostat_clean.csv"));
  EXPECT_FALSE(IsTraceFile(std::string(HYBRID_SOURCE_DIR) + "/data/finger_demo.csv"));
  EXPECT_FALSE(IsTraceFile("/nonexistent/file.csv"));
}

TEST(TraceData, ReadTraceFileRefusesADirectory) {
  EXPECT_THROW(ReadTraceFile(HYBRID_SOURCE_DIR, Thermostat()), DataError);
}

}  // namespace
}  // namespace hybrid
