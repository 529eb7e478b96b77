// `hybrid diagnose MODEL DATA.csv` (commands/diagnose_model_command.h) through the program: the
// dispatch between a trace of any model and the finger's data, exit codes, outputs.
#include "commands/diagnose_model_command.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/test_utilities/command_line.h"

namespace hybrid::cli {
namespace {

using testing::Quote;
using testing::RunHybrid;
using testing::TempDir;

const std::string kRoot = HYBRID_SOURCE_DIR;
const std::string kUrgent = Quote(kRoot + "/spec/thermostat_urgent.ha");
const std::string kThreshold = Quote(kRoot + "/data/thermostat_threshold.csv");

TEST(DiagnoseModelCommand, WritesTheExtendedModelAndTheReport) {
  TempDir dir;
  const std::string model = (dir.path() / "extended.ha").string();
  const std::string report = (dir.path() / "report").string();
  const testing::Result r =
      RunHybrid("diagnose " + kUrgent + " " + kThreshold + " --json --out-model " + Quote(model) +
                " --report " + Quote(report));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cause"], nlohmann::json::array({"switch_on.threshold"}));
  EXPECT_NEAR(j["parameters"]["switch_on.threshold"].get<double>(), 18.5, 0.025);
  EXPECT_LT(j["extended_mse"]["x"].get<double>(), 0.1 * j["baseline_mse"]["x"].get<double>());
  const std::string text = testing::ReadAll(model);
  EXPECT_NE(text.find("param switch_on_threshold = 18.4"), std::string::npos) << text;
  EXPECT_TRUE(std::filesystem::exists(report + "/diagnosis.json"));
  EXPECT_NE(testing::ReadAll(report + "/x.svg").find("<svg"), std::string::npos);
  // The extended model's properties are checked like any model's: violated (6) for the
  // thermostat's `comfortable` under u = 30, as for the model given; never an error.
  const testing::Result check = RunHybrid("check " + Quote(model));
  EXPECT_TRUE(check.exit_code == 0 || check.exit_code == 6 || check.exit_code == 7)
      << check.exit_code << check.err;
}

struct Refused {
  std::string name;
  std::string args;
  int exit_code;
  std::string message;
};

class DiagnoseModelRefused : public ::testing::TestWithParam<Refused> {};

TEST_P(DiagnoseModelRefused, ExitsWithAMessage) {
  TempDir dir;
  const std::string bad = dir.Write("bad.csv", "run,time,u,x\na,0,10,20\na,zero,10,20\n").string();
  std::string args = GetParam().args;
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"BAD", Quote(bad)}}) {
    for (size_t at = args.find(key); at != std::string::npos; at = args.find(key)) {
      args.replace(at, key.size(), value);
    }
  }
  const testing::Result r = RunHybrid(args);
  EXPECT_EQ(r.exit_code, GetParam().exit_code) << r.err;
  EXPECT_NE(r.err.find(GetParam().message), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    Table, DiagnoseModelRefused,
    ::testing::Values(
        Refused{"TraceWithoutModel", "diagnose " + kThreshold, 2, "give its model"},
        Refused{"ModelTwice", "diagnose " + kUrgent + " " + kThreshold + " --model " + kUrgent, 2,
                "the model is given twice"},
        Refused{"NoiseOnFingerData",
                "diagnose " + Quote(kRoot + "/data/finger_demo.csv") + " --noise theta1=1", 2,
                "--noise applies to a trace"},
        Refused{"NoiseMalformed", "diagnose " + kUrgent + " " + kThreshold + " --noise x", 2,
                "expected NAME=SD"},
        Refused{"NoiseOfAnUnobservedVariable",
                "diagnose " + kUrgent + " " + kThreshold + " --noise y=0.1", 2,
                "which the data do not observe"},
        Refused{"Threads", "diagnose " + kUrgent + " " + kThreshold + " --threads 0", 2,
                "must lie in [1, 64]"},
        Refused{"BadCell", "diagnose " + kUrgent + " BAD", 1, "bad.csv:3:2: 'zero'"},
        Refused{"ModelWithoutTheTracedVariables",
                "diagnose " + Quote(kRoot + "/spec/hand.ha") + " " + kThreshold, 1,
                "thermostat_threshold.csv:3:4: unknown column 'x'"},
        Refused{"OutputIsTheData",
                "diagnose " + kUrgent + " " + kThreshold + " --out-model " + kThreshold, 2,
                "an output may not overwrite an input"}),
    [](const auto& info) { return info.param.name; });

TEST(DiagnoseModelCommand, AFailedRunLeavesTheOutputsAlone) {
  TempDir dir;
  const std::string out = dir.Write("out.ha", "keep me").string();
  const std::string bad = dir.Write("bad.csv", "run,time,u,x\na,0,10,20\n").string();
  const testing::Result r =
      RunHybrid("diagnose " + kUrgent + " " + Quote(bad) + " --out-model " + Quote(out));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(testing::ReadAll(out), "keep me");
}

}  // namespace
}  // namespace hybrid::cli
