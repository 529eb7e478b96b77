// The bundled demo data (data/finger_demo.csv) is what the command in its header and in
// docs/diagnosis.md makes, byte for byte: the demo is reproducible and says it is synthetic.

#include <gtest/gtest.h>

#include <string>

#include "tests/test_utilities/command_line.h"

namespace hybrid {
namespace {

using testing::Quote;
using testing::ReadAll;
using testing::RunHybrid;
using testing::TempDir;

const std::string kDemo = std::string(HYBRID_SOURCE_DIR) + "/data/finger_demo.csv";

TEST(FingerDemoDataTest, IsReproducedByTheDocumentedCommand) {
  const TempDir dir;
  const std::string out = (dir.path() / "demo.csv").string();
  const auto r = RunHybrid("synthesize --effect backlash=6 --effect theta3_bias=2.5 --seed 7 -o " +
                           Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadAll(out), ReadAll(kDemo));
}

TEST(FingerDemoDataTest, SaysItIsSynthetic) {
  const std::string text = ReadAll(kDemo);
  EXPECT_EQ(text.rfind("# SYNTHETIC data (not measured)", 0), 0u);
  EXPECT_NE(text.find("seed 7"), std::string::npos);
  EXPECT_NE(text.find("backlash=6"), std::string::npos);
  EXPECT_NE(text.find("theta3_bias=2.5"), std::string::npos);
}

}  // namespace
}  // namespace hybrid
