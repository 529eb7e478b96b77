// Tests of commands/exit_code.h: the one list of the program's exit codes, and its documentation
// (docs/cli.md, "Exit codes": one row per code, in order).

#include "commands/exit_code.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

namespace hybrid::cli {
namespace {

constexpr ExitCode kEveryCode[] = {ExitCode::kOk,       ExitCode::kInput,
                                   ExitCode::kUsage,    ExitCode::kOutput,
                                   ExitCode::kInternal, ExitCode::kSimulationFailed,
                                   ExitCode::kViolated, ExitCode::kUnknown};

TEST(ExitCode, CodesAreTheDocumentedNumbers) {
  for (int i = 0; i < static_cast<int>(std::size(kEveryCode)); ++i) {
    EXPECT_EQ(ExitStatus(kEveryCode[i]), i);
  }
}

// The table of docs/cli.md has one row per code, 0 to 7 in order, and no other.
TEST(ExitCode, DocsListEveryCodeOnceInOrder) {
  std::ifstream in(std::string(HYBRID_SOURCE_DIR) + "/docs/cli.md");
  ASSERT_TRUE(in) << "docs/cli.md";
  std::vector<int> rows;
  bool in_section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("## ")) in_section = line == "## Exit codes";
    if (!in_section || !line.starts_with("| ") || line.size() < 4) continue;
    const char c = line[2];
    if (c >= '0' && c <= '9' && line[3] == ' ') rows.push_back(c - '0');
  }
  EXPECT_EQ(rows, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
}

}  // namespace
}  // namespace hybrid::cli
