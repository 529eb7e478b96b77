// Tests of `hybrid info`'s text form (commands/info_command.h): the model in its own language,
// which the parser (written apart from the printer) reads back to an equal System for every bundled
// model, with units, `within` horizons and the scenario kept; the analysis as comments; and the
// scenario's command-line form, which `hybrid simulate` runs to the same result as the scenario.

#include "commands/info_command.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "commands/simulate_command.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/spaceex/spaceex_import.h"
#include "tests/test_utilities/command_line.h"
#include "tests/test_utilities/in_process.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using testing::Quote;
using testing::Result;
using testing::RunHybrid;
using testing::TempDir;

const fs::path kSourceDir = HYBRID_SOURCE_DIR;

using testing::ArgsOf;
using testing::InProcess;
using testing::RunInProcess;

std::vector<fs::path> BundledModels() {
  std::vector<fs::path> out;
  for (const char* folder : {"spec", "spec/benchmarks", "spec/spaceex"}) {
    for (const auto& entry : fs::directory_iterator(kSourceDir / folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".ha" || ext == ".xml") out.push_back(entry.path());
    }
  }
  return out;
}

std::string InfoTextOf(const System& system, const std::string& file) {
  return cli::InfoText(cli::InfoJson(system, file), system);
}

TEST(InfoText, ParsesBackToTheSameModelForEveryBundledModel) {
  const std::vector<fs::path> models = BundledModels();
  ASSERT_GE(models.size(), 20u);
  for (const fs::path& path : models) {
    const System original = spaceex::ReadModelFile(path.string());
    const std::string text = InfoTextOf(original, path.string());
    const System again = ParseModel(text, "info of " + path.string());
    EXPECT_TRUE(again == original) << path << "\n" << text;
    EXPECT_NE(text.find("\n# analysis\n"), std::string::npos) << path;
  }
}

constexpr const char* kDeclarations = R"(automaton tank {
  param k [1/s] = 0.75 in [0.5, 1];
  var h [m] in [0, 10];
  input d [m/s] in [-0.2, 0];
  mode fill { h' = k * 0.5 + d; inv h <= 8; }
  mode full { h' = 0; }
  mode spare { h' = 0; }
  transition fill -> full { guard h >= 8; }
  init fill { h = 5; }
  scenario { until 4; d = linear(0: -0.2, 2: 0); }
  property soon: reach h >= 6 within 3.5;
  property bounded: always h <= 9;
}
)";

// What the old summary dropped: units of parameters and inputs, parameter ranges, `within`, and
// the scenario in the form `--input` reads; unreachable modes and warnings as comments.
TEST(InfoText, ShowsEveryDeclarationInTheLanguage) {
  const System s = ParseModel(kDeclarations, "tank.ha");
  const std::string text = InfoTextOf(s, "tank.ha");
  for (const char* expected :
       {"param k [1/s] = 0.75 in [0.5, 1];", "input d [m/s] in [-0.2, 0];",
        "property soon: reach h >= 6 within 3.5;", "d = linear(0: -0.2, 2: 0);",
        "#   unreachable modes: spare\n",
        "# the scenario on the command line: hybrid simulate MODEL --until 4 --input "
        "'d=linear(0: -0.2, 2: 0)'\n",
        "# warnings: 1\n"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
  }
  // Every line is either the model or a comment: the text is a model file.
  EXPECT_TRUE(ParseModel(text, "again.ha") == s);
}

// The scenario's command-line form runs as the scenario itself does. The program runs only the
// options (their command-line form is the point); the rest runs in this process.
TEST(InfoText, TheScenarioOptionsSimulateAsTheScenario) {
  TempDir dir;
  const fs::path model = dir.Write("tank.ha", kDeclarations);
  // What `hybrid info MODEL` writes.
  const std::string info = InfoTextOf(spaceex::ReadModelFile(model.string()), model.string());
  const std::string marker = "hybrid simulate MODEL ";
  const size_t at = info.find(marker);
  ASSERT_NE(at, std::string::npos) << info;
  const std::string options =
      info.substr(at + marker.size(), info.find('\n', at) - at - marker.size());
  const cli::SimulateArgs scenario_args =
      ArgsOf<cli::SimulateArgs>(model.string(), [&](cli::SimulateArgs& a) { a.json = true; });
  const InProcess by_scenario = RunInProcess([&] { return cli::RunSimulate(scenario_args); });
  const Result by_options = RunHybrid("simulate " + Quote(model) + " " + options + " --json");
  ASSERT_EQ(by_scenario.exit_code, 0);
  ASSERT_EQ(by_options.exit_code, 0) << by_options.err << options;
  EXPECT_EQ(by_options.out, by_scenario.out);
  // A different input gives a different run (the options are not ignored).
  const cli::SimulateArgs other_args =
      ArgsOf<cli::SimulateArgs>(model.string(), [&](cli::SimulateArgs& a) {
        a.inputs = {"d=0"};
        a.until = 4.0;
        a.json = true;
      });
  const InProcess other = RunInProcess([&] { return cli::RunSimulate(other_args); });
  EXPECT_NE(other.out, by_scenario.out);
}

}  // namespace
}  // namespace hybrid
