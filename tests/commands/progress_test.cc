// Tests of commands/progress.h: when a report is shown (terminal or not, --quiet, --progress), its
// form, its throttling; and of `hybrid check` and `hybrid diagnose` with --progress and --quiet:
// reports on standard error only, the standard output unchanged.

#include "commands/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <string>

#include "tests/test_utilities/command_line.h"

namespace hybrid::cli {
namespace {

using testing::Quote;
using testing::Result;
using testing::RunHybrid;

// What `write` printed to a temporary file (not a terminal).
template <typename Write>
std::string Printed(Write write) {
  std::FILE* f = std::tmpfile();
  write(f);
  std::string out(static_cast<size_t>(std::ftell(f)), '\0');
  std::rewind(f);
  const size_t n = std::fread(out.data(), 1, out.size(), f);
  out.resize(n);
  std::fclose(f);
  return out;
}

TEST(ProgressLine, OnAFileOnlyWhenForced) {
  for (const ProgressMode mode : {ProgressMode::kAuto, ProgressMode::kOff}) {
    EXPECT_EQ(Printed([&](std::FILE* f) {
                ProgressLine line("check", mode, f);
                EXPECT_FALSE(line.enabled());
                line.Report("one", true);
              }),
              "");
  }
  const std::string one = Printed([](std::FILE* f) {
    ProgressLine line("check", ProgressMode::kOn, f);
    EXPECT_TRUE(line.enabled());
    line.Report("one");
  });
  EXPECT_TRUE(std::regex_match(one, std::regex(R"(hybrid check: one, \d+\.\d s\n)"))) << one;
}

// Off a terminal: the first report, then at most one a second unless forced; nothing erased.
TEST(ProgressLine, ThrottlesUnlessForced) {
  const std::string printed = Printed([](std::FILE* f) {
    ProgressLine line("diagnose", ProgressMode::kOn, f);
    line.Report("a");
    line.Report("b");  // within a second of "a": dropped
    line.Report("c", true);
  });
  EXPECT_TRUE(std::regex_match(
      printed, std::regex(R"(hybrid diagnose: a, \d+\.\d s\nhybrid diagnose: c, \d+\.\d s\n)")))
      << printed;
}

TEST(ProgressCli, CheckReportsOnStandardErrorOnly) {
  const std::string model = Quote(std::string(HYBRID_SOURCE_DIR) + "/spec/benchmarks/fiscs04.ha");
  const Result quiet = RunHybrid("check " + model + " --json --quiet");
  const Result shown = RunHybrid("check " + model + " --json --progress");
  const Result plain = RunHybrid("check " + model + " --json");  // not a terminal: no report
  ASSERT_EQ(shown.exit_code, quiet.exit_code) << shown.err;
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(plain.err, "");
  EXPECT_TRUE(shown.err.starts_with("hybrid check: reachability: ")) << shown.err;
  EXPECT_NE(shown.err.find(" symbolic states, "), std::string::npos) << shown.err;
  // The verdicts do not change (the report's seconds may).
  const auto verdicts = [](const std::string& out) {
    std::string v;
    for (size_t at = out.find("\"verdict\""); at != std::string::npos;
         at = out.find("\"verdict\"", at + 1)) {
      v += out.substr(at, out.find(',', at) - at) + ";";
    }
    return v;
  };
  EXPECT_FALSE(verdicts(shown.out).empty());
  EXPECT_EQ(verdicts(shown.out), verdicts(quiet.out));
  const Result both = RunHybrid("check " + model + " --quiet --progress");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("--quiet excludes --progress"), std::string::npos) << both.err;
}

TEST(ProgressCli, CheckProveAndSampleReport) {
  const std::string model = Quote(std::string(HYBRID_SOURCE_DIR) + "/spec/thermostat.ha");
  const Result prove = RunHybrid("check " + model + " --method prove --progress");
  EXPECT_NE(prove.err.find("hybrid check: prove: "), std::string::npos) << prove.err;
  EXPECT_NE(prove.err.find("% of the solver budget used"), std::string::npos) << prove.err;
  const Result sample = RunHybrid("check " + model + " --method sample --runs 5 --progress");
  EXPECT_NE(sample.err.find("hybrid check: sample: property 1 of 3 (comfortable)"),
            std::string::npos)
      << sample.err;
  EXPECT_NE(sample.err.find("property 2 of 3 (heats)"), std::string::npos) << sample.err;
}

TEST(ProgressCli, DiagnoseReportsEachCandidate) {
  const std::string data = Quote(std::string(HYBRID_SOURCE_DIR) + "/data/finger_demo.csv");
  const Result r = RunHybrid("diagnose " + data + " --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hybrid diagnose: single causes: candidate 1 of "), std::string::npos)
      << r.err;
  EXPECT_EQ(RunHybrid("diagnose " + data + " --json --quiet").err, "");
}

}  // namespace
}  // namespace hybrid::cli
