// Tests of the model a command reads (commands/model_file.h): a SpaceEx model with the
// configuration beside it or the one given, whose time-horizon (read here from the file apart
// from the import) is the model's horizon, and a configuration refused with a model-language file.

#include "commands/model_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "commands/command_error.h"
#include "hybrid/automaton/parser.h"
#include "tests/test_utilities/command_line.h"

namespace hybrid::cli {
namespace {

namespace fs = std::filesystem;
using hybrid::testing::ReadAll;
using hybrid::testing::TempDir;

const fs::path kSpec = fs::path(HYBRID_SOURCE_DIR) / "spec";
const std::string kXml = (kSpec / "spaceex" / "fischer_2.xml").string();
const std::string kCfg = (kSpec / "spaceex" / "fischer_2.cfg").string();

// The number after `time-horizon =` in the configuration text `cfg`.
double TimeHorizon(const std::string& cfg) {
  std::istringstream in(cfg);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("time-horizon", 0) == 0) return std::stod(line.substr(line.find('=') + 1));
  }
  ADD_FAILURE() << "no time-horizon";
  return 0.0;
}

TEST(ModelFile, SpaceExHorizonIsTheTimeHorizonOfItsConfiguration) {
  const System beside = ReadModelArgument(kXml, "");
  ASSERT_TRUE(beside.scenario().has_value());
  EXPECT_EQ(beside.scenario()->until, TimeHorizon(ReadAll(kCfg)));
  EXPECT_EQ(beside.properties()[0].horizon, beside.scenario()->until);
  // Another configuration: the same one with a horizon of 0.75.
  TempDir dir;
  std::string text = ReadAll(kCfg);
  const std::size_t at = text.find("time-horizon");
  text.replace(at, text.find('\n', at) - at, "time-horizon = 0.75");
  const System other = ReadModelArgument(kXml, dir.Write("other.cfg", text).string());
  ASSERT_TRUE(other.scenario().has_value());
  EXPECT_EQ(other.scenario()->until, 0.75);
  EXPECT_EQ(other.properties()[0].horizon, 0.75);
}

TEST(ModelFile, ConfigurationErrors) {
  TempDir dir;
  const std::string bad = dir.Write("bad.cfg", "system = \"fischer\"\ntime-horizon = -\n").string();
  try {
    (void)ReadModelArgument(kXml, bad);
    ADD_FAILURE() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), bad);
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.column(), 16);
  }
  const std::string ha = (kSpec / "thermostat.ha").string();
  try {
    (void)ReadModelArgument(ha, kCfg);
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), "config");
    EXPECT_EQ(std::string(e.what()),
              "config names a SpaceEx configuration, read with a SpaceEx model (.xml) only, and "
              "model '" +
                  ha + "' is not one");
  }
  EXPECT_NO_THROW((void)ReadModelArgument(ha, ""));
}

}  // namespace
}  // namespace hybrid::cli
