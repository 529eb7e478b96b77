// tools/benchmarks.py (docs/benchmarks_lha.md): its quick subset of spec/benchmarks/ is decided
// and as expected, and its exit status follows the verdicts (skipped without python3).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "tests/test_utilities/command_line.h"

namespace hybrid::testing {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;

struct ScriptRun {
  int status = -1;  // as pclose returns it
  std::string output;
};

/// Runs the shell command `command` (standard error merged).
ScriptRun RunShell(const std::string& command) {
  ScriptRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  run.status = pclose(pipe);
  return run;
}

/// Runs `python3 tools/benchmarks.py --hybrid HYBRID_BINARY ARGS`.
ScriptRun RunScript(const std::string& args) {
  return RunShell("python3 " + Quote(kSource + "/tools/benchmarks.py") + " --hybrid " +
                  Quote(HYBRID_BINARY) + " " + args + " 2>&1 </dev/null");
}

/// Runs `python3 tools/benchmarks.py ARGS` as README.md's "Using it" does: from a directory laid
/// out as the repository (its tools/ and spec/; build/bin/hybrid the binary under test), with
/// the script's default binary.
ScriptRun RunScriptAsTheReadme(const std::string& args) {
  const TempDir repository;
  for (const char* name : {"tools", "spec"}) {
    std::filesystem::create_directory_symlink(kSource + "/" + name, repository.path() / name);
  }
  std::filesystem::create_directories(repository.path() / "build" / "bin");
  std::filesystem::create_symlink(HYBRID_BINARY, repository.path() / "build" / "bin" / "hybrid");
  return RunShell("cd " + Quote(repository.path().string()) + " && python3 tools/benchmarks.py " +
                  args + " 2>&1 </dev/null");
}

int ExitCode(const ScriptRun& run) { return WIFEXITED(run.status) ? WEXITSTATUS(run.status) : -1; }

#define SKIP_WITHOUT_PYTHON(run) \
  if (ExitCode(run) == 127) GTEST_SKIP() << "no python3: " << (run).output

// Every model of the quick subset is decided today and every verdict is the expected one. Run
// as README.md runs `python3 tools/benchmarks.py --quick` (the layout, the default binary), so
// that tests/python/test_readme.py need not run that command again: this is its check and more.
TEST(BenchmarksTest, QuickSubsetIsDecidedAsExpected) {
  const ScriptRun run = RunScriptAsTheReadme("--quick --require-all");
  SKIP_WITHOUT_PYTHON(run);
  EXPECT_EQ(ExitCode(run), 0) << run.output;
  EXPECT_EQ(run.output.find("MISMATCH "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" 0 MISMATCH, 0 UNKNOWN"), std::string::npos) << run.output;
}

// A decided verdict other than the expected one is a failure, with or without --require-all.
TEST(BenchmarksTest, ContradictionFails) {
  TempDir dir;
  const auto table = dir.Write("expected.tsv",
                               "file\tproperty\texpected\n"
                               "water_tank.ha\tlevel_in_range\tviolated\n");
  const ScriptRun run = RunScript("--expected " + Quote(table.string()) + " water_tank");
  SKIP_WITHOUT_PYTHON(run);
  EXPECT_EQ(ExitCode(run), 1) << run.output;
  EXPECT_NE(run.output.find("violated     proved       reach"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("MISMATCH"), std::string::npos) << run.output;
}

// A benchmark that does not exist and a missing binary are usage errors (exit status 2).
TEST(BenchmarksTest, UsageErrors) {
  const ScriptRun run = RunScript("no_such_benchmark");
  SKIP_WITHOUT_PYTHON(run);
  EXPECT_EQ(ExitCode(run), 2) << run.output;
  const ScriptRun no_binary = RunScript("--hybrid /nonexistent/hybrid water_tank");
  EXPECT_EQ(ExitCode(no_binary), 2) << no_binary.output;
}

// An unknown verdict (sampling never proves) is reported; it fails only with --require-all.
TEST(BenchmarksTest, UnknownFailsOnlyWithRequireAll) {
  TempDir dir;
  const auto table = dir.Write("expected.tsv",
                               "file\tproperty\texpected\n"
                               "water_tank.ha\tlevel_in_range\tproved\n");
  const std::string args = "--method sample --expected " + Quote(table.string()) + " water_tank";
  const ScriptRun run = RunScript(args);
  SKIP_WITHOUT_PYTHON(run);
  EXPECT_EQ(ExitCode(run), 0) << run.output;
  EXPECT_NE(run.output.find("UNKNOWN"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("sampling never proves"), std::string::npos) << run.output;
  EXPECT_EQ(ExitCode(RunScript(args + " --require-all")), 1);
}

// --json is one JSON document; --peer-command times a peer for each model.
TEST(BenchmarksTest, JsonAndPeerCommand) {
  const ScriptRun run = RunScript("--json --peer-command 'test -f {model}' water_tank nav2");
  SKIP_WITHOUT_PYTHON(run);
  ASSERT_EQ(ExitCode(run), 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  EXPECT_EQ(Field(report, "counts", "OK"), 7);
  EXPECT_EQ(Field(report, "models").size(), 2u);
  EXPECT_EQ(Field(report, "models", 0, "peer_exit_code"), 0);  // the model's path was substituted
  EXPECT_TRUE(Field(report, "models", 1, "ratio").is_number());
}

// --repeat N runs each model N times, in turns with the peer's, and reports the medians of the
// wall and CPU times; the CPU time counts the peer's process (here one that spins 0.2 s of
// CPU time by its own clock).
TEST(BenchmarksTest, RepeatReportsMediansOfWallAndCpuTimes) {
  const std::string spin =
      "python3 -c 'import time; t = time.process_time(); "
      "[0 for _ in iter(lambda: time.process_time() - t < 0.2, False)]'";
  const ScriptRun run =
      RunScript("--json --repeat 3 --peer-command " + Quote(spin) + " water_tank");
  SKIP_WITHOUT_PYTHON(run);
  ASSERT_EQ(ExitCode(run), 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  const nlohmann::json& model = Field(report, "models", 0);
  EXPECT_EQ(Field(model, "runs"), 3);
  EXPECT_GE(Field(model, "peer_cpu_seconds").get<double>(), 0.2);
  EXPECT_LT(Field(model, "peer_cpu_seconds").get<double>(), 5.0);
  EXPECT_GT(Field(model, "cpu_seconds").get<double>(), 0.0);
  EXPECT_TRUE(Field(model, "cpu_ratio").is_number());
  EXPECT_EQ(Field(report, "counts", "OK"), 4);  // water_tank's 4 verdicts, of the first run
}

// With --per-property, each property's runs are repeated (and the peer's verdict read).
TEST(BenchmarksTest, RepeatPerPropertyAndItsBounds) {
  const ScriptRun run = RunScript(
      "--json --repeat 2 --per-property --peer-command 'echo {name} {property} SAFE' water_tank");
  SKIP_WITHOUT_PYTHON(run);
  ASSERT_EQ(ExitCode(run), 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  ASSERT_EQ(Field(report, "models").size(), 4u);
  EXPECT_EQ(Field(report, "models", 0, "property"), "level_in_range");
  EXPECT_EQ(Field(report, "models", 0, "runs"), 2);
  EXPECT_EQ(Field(report, "models", 0, "peer_verdict"), "SAFE");
  const ScriptRun zero = RunScript("--repeat 0 water_tank");
  EXPECT_EQ(ExitCode(zero), 2) << zero.output;
  EXPECT_NE(zero.output.find("--repeat must be at least 1"), std::string::npos) << zero.output;
}

// A proof of the runs up to a time only (the flowpipe's "unreachable within 0.5" on nav2, which
// it leaves at its bound of mode entries) is not the unbounded property's verdict: UNKNOWN.
TEST(BenchmarksTest, BoundedProofIsNotTheExpectedVerdict) {
  const ScriptRun run = RunScript("--json --method flowpipe nav2");
  SKIP_WITHOUT_PYTHON(run);
  ASSERT_EQ(ExitCode(run), 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  const nlohmann::json& target = Field(report, "properties", 0);
  ASSERT_EQ(Field(target, "property"), "target");
  EXPECT_TRUE(Field(target, "got").get<std::string>().starts_with("unreachable within "))
      << target.dump();
  EXPECT_EQ(Field(target, "status"), "UNKNOWN");
  EXPECT_EQ(Field(report, "counts", "OK"), 0);
}

/// The rows (file, property, expected verdict) of a table of expected verdicts; comments and the
/// header left out.
std::set<std::array<std::string, 3>> ExpectedRows(const std::string& path) {
  std::set<std::array<std::string, 3>> rows;
  std::istringstream text(ReadAll(path));
  std::string line;
  while (std::getline(text, line)) {
    if (line.empty() || line[0] == '#' || line.starts_with("file\t")) continue;
    std::array<std::string, 3> row;
    std::istringstream fields(line);
    for (std::string& field : row) std::getline(fields, field, '\t');
    rows.insert(row);
  }
  return rows;
}

// The ARCH-COMP instances' properties (the peer comparison's table) are rows of expected.tsv,
// with the same verdicts.
TEST(BenchmarksTest, ArchCompTableIsPartOfTheExpectedTable) {
  const auto all = ExpectedRows(kSource + "/spec/benchmarks/expected.tsv");
  const auto arch = ExpectedRows(kSource + "/spec/benchmarks/expected_arch_comp.tsv");
  EXPECT_EQ(arch.size(), 10u);
  for (const auto& row : arch) {
    EXPECT_EQ(all.count(row), 1u) << row[0] << " " << row[1] << " " << row[2];
  }
}

}  // namespace
}  // namespace hybrid::testing
