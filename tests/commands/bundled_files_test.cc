// The bundled models (commands/bundled_files.h) are found without any path compiled into `hybrid`:
// from the build tree, from an installed copy (cmake --install) and from a lone copy of the
// executable (its built-in copies); no --help shows an absolute path.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "tests/test_utilities/command_line.h"

namespace hybrid::testing {
namespace {

namespace fs = std::filesystem;

// Runs `program ARGS` with the environment assignments `env` (shell syntax, e.g. "A=1 B=2") and
// HYBRID_DATA_DIR unset; returns the exit code and standard output.
Result RunProgram(const fs::path& program, const std::string& args, const std::string& env) {
  TempDir dir;
  const fs::path out = dir.path() / "stdout", err = dir.path() / "stderr";
  const std::string command = "env -u HYBRID_DATA_DIR " + env + " " + Quote(program.string()) +
                              " " + args + " >" + Quote(out.string()) + " 2>" +
                              Quote(err.string()) + " </dev/null";
  const int status = std::system(command.c_str());
  Result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadAll(out);
  r.err = ReadAll(err);
  return r;
}

// The gripper commands that read a bundled model by default, with their expected exit code.
const char* const kFingerSimulation =
    "finger --g 255 --object circle:0.06,0.08,0.01 --simulate --json";
const char* const kHandSimulation = "hand --object circle:0,0.06,0.02 --simulate --json";

TEST(BundledFiles, NoHelpShowsAnAbsolutePath) {
  for (const char* command :
       {"", "info", "dot", "simulate", "check", "finger", "hand", "diagnose", "synthesize"}) {
    const Result r = RunHybrid(std::string(command) + " --help");
    EXPECT_EQ(r.exit_code, 0) << command;
    std::istringstream words(r.out);
    for (std::string word; words >> word;) {
      const std::size_t slash = word.find('/');
      EXPECT_FALSE(slash != std::string::npos &&
                   (slash == 0 || word[slash - 1] == '=' || word[slash - 1] == '('))
          << "hybrid " << command << " --help shows a path: " << word;
    }
    EXPECT_EQ(r.out.find(HYBRID_SOURCE_DIR), std::string::npos) << command;
  }
}

TEST(BundledFiles, TheBuildTreeReadsTheSourceModels) {
  TempDir cache;
  const std::string env = "XDG_CACHE_HOME=" + Quote(cache.path().string());
  EXPECT_EQ(RunProgram(HYBRID_BINARY, kFingerSimulation, env).exit_code, 0);
  EXPECT_EQ(RunProgram(HYBRID_BINARY, kHandSimulation, env).exit_code, 0);
  EXPECT_TRUE(cache.Files().empty()) << "the built-in copies were used";
}

TEST(BundledFiles, ALoneCopyOfTheProgramUsesItsBuiltInCopies) {
  TempDir dir, cache;
  fs::create_directories(dir.path() / "bin");
  const fs::path copy = dir.path() / "bin" / "hybrid";
  fs::copy_file(HYBRID_BINARY, copy);
  const std::string env = "XDG_CACHE_HOME=" + Quote(cache.path().string());
  const Result finger = RunProgram(copy, kFingerSimulation, env);
  EXPECT_EQ(finger.exit_code, 0) << finger.err;
  EXPECT_EQ(finger.out, RunHybrid(kFingerSimulation).out);
  const Result hand = RunProgram(copy, kHandSimulation, env);  // hand.ha imports finger.ha
  EXPECT_EQ(hand.exit_code, 0) << hand.err;
  EXPECT_EQ(hand.out, RunHybrid(kHandSimulation).out);
  // The built-in copies are the source's files.
  ASSERT_EQ(cache.Files().size(), 1u);
  const fs::path folder = cache.path() / "hybrid";
  ASSERT_TRUE(fs::is_directory(folder));
  for (const auto& entry : fs::directory_iterator(folder)) {
    for (const char* model : {"finger.ha", "hand.ha", "thermostat.ha", "bouncing_ball.ha"}) {
      EXPECT_EQ(ReadAll(entry.path() / "spec" / model),
                ReadAll(fs::path(HYBRID_SOURCE_DIR) / "spec" / model))
          << model;
    }
  }
  // $HYBRID_DATA_DIR comes first: an empty folder there does not hide the copies, a model
  // there replaces them.
  TempDir data;
  fs::create_directories(data.path() / "spec");
  data.Write("spec/finger.ha", "automaton finger { }");
  const Result replaced = RunProgram(copy, kFingerSimulation,
                                     "HYBRID_DATA_DIR=" + Quote(data.path().string()) + " " + env);
  EXPECT_EQ(replaced.exit_code, 1) << replaced.err;
  EXPECT_NE(replaced.err.find(data.path().string()), std::string::npos) << replaced.err;
}

TEST(BundledFiles, AnInstalledProgramReadsItsShareFolder) {
  TempDir prefix, cache;
  const fs::path build = fs::path(HYBRID_BINARY).parent_path().parent_path();
  const std::string install = "cmake --install " + Quote(build.string()) + " --prefix " +
                              Quote(prefix.path().string()) + " --component runtime >/dev/null";
  ASSERT_EQ(std::system(install.c_str()), 0) << install;
  const fs::path installed = prefix.path() / "bin" / "hybrid";
  ASSERT_TRUE(fs::exists(installed));
  EXPECT_TRUE(fs::exists(prefix.path() / "share" / "hybrid" / "spec" / "finger.ha"));
  const std::string env = "XDG_CACHE_HOME=" + Quote(cache.path().string());
  EXPECT_EQ(RunProgram(installed, kFingerSimulation, env).exit_code, 0);
  EXPECT_EQ(RunProgram(installed, kHandSimulation, env).exit_code, 0);
  EXPECT_TRUE(cache.Files().empty()) << "the installed share/hybrid/ was not used";
}

}  // namespace
}  // namespace hybrid::testing
