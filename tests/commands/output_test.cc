// Tests of commands/output.h: the inputs of a model (its imports, a SpaceEx configuration) that no
// output may name, and the temporary files removed when a signal stops the program.

#include "commands/output.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "tests/test_utilities/command_line.h"

namespace hybrid::cli {
namespace {

namespace fs = std::filesystem;
using ::hybrid::testing::ReadAll;
using ::hybrid::testing::TempDir;
using ::testing::ElementsAre;

// The paths of `files`, and the argument or role (in the API's words) of each.
std::vector<std::string> Paths(const std::vector<NamedFile>& files) {
  std::vector<std::string> out;
  for (const NamedFile& f : files) out.push_back(f.path);
  return out;
}
std::vector<std::string> Names(const std::vector<NamedFile>& files) {
  std::vector<std::string> out;
  for (const NamedFile& f : files) out.push_back(f.role.empty() ? f.argument : f.role.Text());
  return out;
}

// The message of the OptionError CheckDistinctFiles throws (in the API's words, and about the
// argument of the last output), or "" if it throws nothing.
std::string Refusal(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  try {
    CheckDistinctFiles(inputs, outputs);
  } catch (const OptionError& e) {
    EXPECT_EQ(e.argument(), outputs.back().argument);
    return e.what();
  }
  return "";
}

constexpr const char* kLibrary = "automaton lib { var x; mode m { x' = 1; } init m { x = 0; } }\n";

// ---------------------------------------------------------------------------------------------
// ModelInputs.

// Imports are found as the parser finds them: relative to the importing file, through nested
// imports, each file once (a cycle ends), not in comments; a missing import is left to the parser.
TEST(ModelInputs, ListsTheModelAndEveryFileItImports) {
  TempDir dir;
  fs::create_directory(dir.path() / "lib");
  dir.Write("lib/a.ha", "import \"b.ha\";  # relative to lib/\nimport \"../main.ha\";\n");
  dir.Write("lib/b.ha", std::string("import \"a.ha\";\n") + kLibrary);
  const std::string main = dir.Write("main.ha",
                                     "# import \"commented.ha\";\n"
                                     "import \"lib/a.ha\"; import\n  # a comment between\n"
                                     "  \"missing.ha\";\nsystem s { instance A = lib; }\n")
                               .string();
  const std::string top = "model '" + main + "'";
  const std::vector<NamedFile> inputs = ModelInputs("model", main);
  const std::string lib = (dir.path() / "lib").string();
  EXPECT_THAT(Paths(inputs), ElementsAre(main, lib + "/a.ha", lib + "/b.ha",
                                         (dir.path() / "missing.ha").string()));
  EXPECT_THAT(Names(inputs), ElementsAre("model", "imported by " + top,
                                         "imported by '" + lib + "/a.ha'", "imported by " + top));
}

// A SpaceEx model reads its configuration: the one given, else the .cfg beside it if any.
TEST(ModelInputs, ASpaceExModelReadsItsConfiguration) {
  TempDir dir;
  const std::string xml = dir.Write("m.xml", "<sspaceex/>\n").string();
  EXPECT_THAT(Paths(ModelInputs("model", xml)), ElementsAre(xml));
  const std::string cfg = dir.Write("m.cfg", "system = m\n").string();
  const std::vector<NamedFile> inputs = ModelInputs("model", xml);
  EXPECT_THAT(Paths(inputs), ElementsAre(xml, cfg));
  EXPECT_THAT(Names(inputs),
              ElementsAre("model", "the SpaceEx configuration of model '" + xml + "'"));
  // The role refers to the argument: each front end names it its own way.
  EXPECT_THAT(inputs[1].role.Arguments(), ElementsAre("model"));
  EXPECT_THAT(Paths(ModelInputs("model", xml, dir.File("other.cfg"))),
              ElementsAre(xml, dir.File("other.cfg")));
}

// A model that is not a regular file is not read (a FIFO would block, /dev/stdin be consumed).
TEST(ModelInputs, AStreamModelIsNotRead) {
  TempDir dir;
  const std::string fifo = dir.File("model.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT(Paths(ModelInputs("model", fifo)), ElementsAre(fifo));
  EXPECT_THAT(Paths(ModelInputs("model", dir.File("none.ha"))), ElementsAre(dir.File("none.ha")));
}

// ---------------------------------------------------------------------------------------------
// CheckDistinctFiles with a model's inputs.

// An output naming an imported file is refused, however it is spelled: its path and importer are
// named.
TEST(CheckDistinctFiles, RefusesAnOutputNamingAnImportedFile) {
  TempDir dir;
  const std::string lib = dir.Write("lib.ha", kLibrary).string();
  const std::string main =
      dir.Write("main.ha", "import \"lib.ha\";\nsystem s { instance A = lib; }\n").string();
  fs::create_symlink(lib, dir.path() / "link.ha");
  fs::create_directory(dir.path() / "x");
  const std::vector<NamedFile> inputs = ModelInputs("model", main);
  for (const std::string& out :
       {lib, dir.File("./lib.ha"), dir.File("x/../lib.ha"), dir.File("link.ha")}) {
    EXPECT_EQ(Refusal(inputs, {{"output", out}}), "output '" + out + "' names the input '" + lib +
                                                      "' (imported by model '" + main +
                                                      "'); an output may not overwrite an input")
        << out;
  }
  EXPECT_EQ(Refusal(inputs, {{"output", dir.File("new.ha")}}), "");
}

// Two outputs naming one file: both arguments are referred to, the error is about the later.
TEST(CheckDistinctFiles, RefusesTwoOutputsNamingOneFile) {
  TempDir dir;
  const std::string out = dir.File("t.csv");
  EXPECT_EQ(Refusal({}, {{"out", out}, {"events", out}}), "out and events name the same file ('" +
                                                              out + "', '" + out +
                                                              "'); give each output its own file");
  try {
    CheckDistinctFiles({}, {{"out", out}, {"events", out}});
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_THAT(e.message().Arguments(), ElementsAre("out", "events"));
  }
}

// A missing directory is an OutputError referring to the argument naming the file.
TEST(CheckOutputPlaces, RefersToTheArgumentOfAFileWhoseDirectoryIsMissing) {
  TempDir dir;
  const std::string out = dir.File("none/t.csv");
  try {
    CheckOutputPlaces({{"out_model", out}});
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write out_model '" + out + "': the directory '" +
                                         dir.File("none") + "' does not exist");
    EXPECT_THAT(e.message().Arguments(), ElementsAre("out_model"));
  }
}

// ---------------------------------------------------------------------------------------------
// RemovedOnSignal and RemoveTemporaryFilesOnSignals.

// SIGTERM removes the registered files and (empty) directories, keeps what is no longer
// registered, and still ends the program by SIGTERM.
TEST(RemovedOnSignalDeathTest, SigtermRemovesTheRegisteredPathsAndEndsTheProgram) {
  TempDir dir;
  const std::string temp = dir.File(".out.tmp-1-0"), kept = dir.File("kept.txt");
  const std::string outer = dir.File("report"), inner = dir.File("report/runs");
  EXPECT_EXIT(
      {
        RemoveTemporaryFilesOnSignals();
        const RemovedOnSignal outer_registered(outer, RemovedOnSignal::kDirectory);
        fs::create_directory(outer);
        const RemovedOnSignal inner_registered(inner, RemovedOnSignal::kDirectory);
        fs::create_directory(inner);
        const RemovedOnSignal registered(temp);
        dir.Write(".out.tmp-1-0", "half a file");
        { const RemovedOnSignal released(dir.Write("kept.txt", "kept").string()); }
        ::raise(SIGTERM);
      },
      ::testing::KilledBySignal(SIGTERM), "");
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(outer));
  EXPECT_EQ(ReadAll(kept), "kept");
}

// What WriteOutputs has written stays: its registrations end with it.
TEST(RemovedOnSignalDeathTest, WrittenOutputsStayWhenASignalFollows) {
  TempDir dir;
  EXPECT_EXIT(
      {
        RemoveTemporaryFilesOnSignals();
        WriteOutputs({{dir.File("report/a.txt"), "a"}, {dir.File("b.txt"), "b"}},
                     {dir.File("report")});
        ::raise(SIGINT);
      },
      ::testing::KilledBySignal(SIGINT), "");
  EXPECT_EQ(ReadAll(dir.File("report/a.txt")), "a");
  EXPECT_EQ(ReadAll(dir.File("b.txt")), "b");
}

// The table is bounded: past 64 paths nothing is registered; a slot released is used again.
TEST(RemovedOnSignal, RegistersAtMost64PathsAndNoLongPath) {
  std::vector<RemovedOnSignal> registered;
  for (int i = 0; i < 64; ++i) registered.emplace_back("/tmp/x" + std::to_string(i));
  for (const RemovedOnSignal& r : registered) EXPECT_TRUE(r.registered());
  EXPECT_FALSE(RemovedOnSignal("/tmp/one-too-many").registered());
  registered.pop_back();
  EXPECT_TRUE(RemovedOnSignal("/tmp/again").registered());
  registered.clear();
  EXPECT_FALSE(RemovedOnSignal(std::string(5000, 'x')).registered());
  EXPECT_FALSE(RemovedOnSignal("").registered());
}

}  // namespace
}  // namespace hybrid::cli
