// Tests of the `hybrid` command line (HYBRID_BINARY): exit codes (0 success, 1 invalid model,
// 2 usage error, 3 output error), FILE:LINE:COL: diagnostics for every malformed model, the
// JSON of `hybrid info`, and the files `hybrid dot -o` writes.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/dot_writer.h"
#include "hybrid/automaton/parser.h"
#include "tests/test_utilities/command_line.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using testing::Field;
using testing::Quote;
using testing::ReadAll;
using testing::Result;
using testing::RunHybrid;
using testing::TempDir;

const fs::path kSourceDir = HYBRID_SOURCE_DIR;
const fs::path kFinger = kSourceDir / "spec" / "finger.ha";
const fs::path kMalformedDir = kSourceDir / "tests" / "data" / "malformed";

// ---------------------------------------------------------------------------------------------
// Usage.

TEST(HybridCli, HelpExitsZero) {
  const Result r = RunHybrid("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("info"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dot"), std::string::npos);
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos);
  EXPECT_EQ(RunHybrid("info --help").exit_code, 0);
  EXPECT_EQ(RunHybrid("dot --help").exit_code, 0);
}

// An unknown command is named, with the closest command when it looks like a typo, and the list.
TEST(HybridCli, UnknownCommandsAreNamedWithTheClosestMatch) {
  const Result typo = RunHybrid("simulat spec/thermostat.ha");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.err.find("unknown command 'simulat'; did you mean 'simulate'?"), std::string::npos)
      << typo.err;
  const Result other = RunHybrid("frobnicate");
  EXPECT_EQ(other.exit_code, 2);
  EXPECT_NE(other.err.find("unknown command 'frobnicate' (commands: info dot import simulate"),
            std::string::npos)
      << other.err;
  EXPECT_EQ(other.err.find("did you mean"), std::string::npos) << other.err;
}

// -o/--output is the one spelling of a command's one output file; the old --out still works.
TEST(HybridCli, OutputOptionIsOneSpellingAndOldOnesStillWork) {
  TempDir dir;
  const std::string model = Quote((kSourceDir / "spec" / "thermostat.ha").string());
  std::string texts[3];
  const char* spellings[3] = {"-o", "--output", "--out"};
  for (int i = 0; i < 3; ++i) {
    const std::string path = (dir.path() / ("t" + std::to_string(i) + ".csv")).string();
    const Result r = RunHybrid("simulate " + model + " --until 1 " + spellings[i] + " " + path);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(path);
    texts[i].assign(std::istreambuf_iterator<char>(in), {});
  }
  EXPECT_NE(texts[0].find("time,kind,mode,x"), std::string::npos) << texts[0];
  EXPECT_EQ(texts[0], texts[1]);
  EXPECT_EQ(texts[0], texts[2]);
  const Result synthesize = RunHybrid("synthesize --free-runs 1 --samples 64 --output " +
                                      Quote((dir.path() / "s.csv").string()));
  EXPECT_EQ(synthesize.exit_code, 0) << synthesize.err;
}

// Each command's help lists its own exit codes only.
TEST(HybridCli, EachCommandsHelpListsItsExitCodes) {
  const Result check = RunHybrid("check --help");
  EXPECT_NE(check.out.find("6 a property violated"), std::string::npos) << check.out;
  EXPECT_EQ(check.out.find("simulation stopped early"), std::string::npos) << check.out;
  const Result simulate = RunHybrid("simulate --help");
  EXPECT_NE(simulate.out.find("5 simulation stopped early"), std::string::npos) << simulate.out;
  EXPECT_EQ(simulate.out.find("property violated"), std::string::npos) << simulate.out;
  const Result info = RunHybrid("info --help");
  EXPECT_NE(info.out.find("4 out of memory"), std::string::npos) << info.out;
  EXPECT_EQ(info.out.find("5 "), std::string::npos) << info.out;
}

TEST(HybridCli, VersionExitsZero) {
  const Result r = RunHybrid("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, "hybrid " HYBRID_PROJECT_VERSION "\n");  // CMake's project(VERSION)
}

// The help that sends the reader to cli.md says where it is both in a source tree and installed
// (`cmake --install` and `pip install` put docs/ in PREFIX/share/doc/hybrid/).
TEST(HybridCli, HelpSaysWhereTheDocumentationIs) {
  for (const char* command : {"", "info", "simulate", "check", "finger", "diagnose"}) {
    const Result r = RunHybrid(std::string(command) + " --help");
    EXPECT_EQ(r.exit_code, 0) << command;
    EXPECT_NE(r.out.find("cli.md of hybrid's documentation (docs/ in the source tree, "
                         "share/doc/hybrid/ under the installation prefix)"),
              std::string::npos)
        << command << ": " << r.out;
    EXPECT_EQ(r.out.find("docs/cli.md"), std::string::npos) << command;
  }
}

TEST(HybridCli, UsageErrorsExitTwo) {
  const std::string finger = Quote(kFinger);
  for (const std::string& args : std::vector<std::string>{
           "info --no-such-option " + finger,
           "--no-such-option",
           "",
           "frobnicate " + finger,
           "info",
           "dot",
           "dot " + finger + " -o",
           "info " + finger + " extra_argument",
       }) {
    const Result r = RunHybrid(args);
    EXPECT_EQ(r.exit_code, 2) << "hybrid " << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << "hybrid " << args;
    EXPECT_EQ(r.out, "") << "hybrid " << args;
  }
}

// Numbers are numbers in every command: an empty value is not 0, a negative seed is not
// 18446744073709551615, hexadecimal and doubled signs are refused; exit 2 naming the option,
// before any work (the model is never read).
TEST(HybridCli, NumericOptionsOfEveryCommandAreNumbers) {
  const std::string model = Quote(kSourceDir / "spec" / "thermostat.ha");
  const std::string data = Quote(kSourceDir / "data" / "finger_demo.csv");
  struct Case {
    std::string args;
    std::string message;
  };
  for (const Case& c : std::vector<Case>{
           {"check " + model + " --depth ''", "--depth: empty: a number is required"},
           {"check " + model + " --depth 0x10", "--depth: '0x10' is not a decimal number"},
           {"check " + model + " --depth 2.5", "--depth: '2.5' is not an integer"},
           {"check " + model + " --induction ''", "--induction: empty"},
           {"check " + model + " --budget ''", "--budget: empty"},
           {"check " + model + " --budget +-5", "--budget: '+-5' is not a decimal number"},
           {"check " + model + " --runs 1e2", "--runs: '1e2' is not an integer"},
           {"check " + model + " --method sample --seed -1",
            "--seed: '-1' is negative; a number >= 0 is required"},
           {"check " + model + " --seed 0x1", "--seed: '0x1' is not a decimal number"},
           {"simulate " + model + " --until ''", "--until: empty"},
           {"simulate " + model + " --sample ''", "--sample: empty"},
           {"diagnose " + data + " --threads ''", "--threads: empty"},
           {"diagnose " + data + " --significance 0x19", "--significance: '0x19' is not"},
           {"synthesize --samples ''", "--samples: empty"},
           {"hand --g ''", "--g: empty"},
           {"finger --g '' ", "--g: empty"},
       }) {
    const Result r = RunHybrid(c.args);
    EXPECT_EQ(r.exit_code, 2) << "hybrid " << c.args << "\n" << r.err;
    EXPECT_TRUE(r.err.starts_with(c.message)) << "hybrid " << c.args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << "hybrid " << c.args;
  }
}

// ---------------------------------------------------------------------------------------------
// info.

TEST(HybridCli, InfoJsonOfTheFinger) {
  const Result r = RunHybrid("info " + Quote(kFinger) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  nlohmann::json info;
  ASSERT_NO_THROW(info = nlohmann::json::parse(r.out)) << r.out;
  EXPECT_EQ(Field(info, "file"), kFinger.string());
  EXPECT_EQ(Field(info, "name"), "finger");
  ASSERT_EQ(Field(info, "components").size(), 1u);
  const auto& c = Field(info, "components", 0);
  EXPECT_EQ(Field(c, "automaton"), "finger");
  EXPECT_EQ(Field(c, "instance"), "");
  EXPECT_EQ(Field(c, "modes").size(), 31u);
  EXPECT_EQ(Field(c, "reachable_modes").size(), 31u);
  EXPECT_TRUE(Field(c, "unreachable_modes").empty());
  EXPECT_EQ(Field(c, "variables").size(), 6u);
  EXPECT_EQ(Field(c, "variables", 0, "name"), "theta1");
  EXPECT_EQ(Field(c, "variables", 0, "unit"), "deg");
  EXPECT_EQ(Field(c, "variables", 0, "domain"), nlohmann::json::array({0.0, 70.0}));
  EXPECT_EQ(Field(c, "discrete_variables").size(), 6u);
  EXPECT_EQ(Field(c, "inputs", 0, "bounds"), nlohmann::json::array({-1.0, 1.0}));
  EXPECT_EQ(Field(c, "initial_states", 0, "mode"), "c000_l000");
  EXPECT_EQ(Field(c, "properties").size(), 13u);
  EXPECT_TRUE(Field(info, "warnings").empty());
  EXPECT_EQ(Field(info, "scenario", "until"), 530.0);
  EXPECT_EQ(Field(info, "scenario", "inputs", 0, "shape"), "step");
  // Every transition names existing modes.
  std::set<std::string> modes;
  for (const auto& m : Field(c, "modes")) modes.insert(Field(m, "name").get<std::string>());
  for (const auto& t : Field(c, "transitions")) {
    EXPECT_TRUE(modes.count(Field(t, "source").get<std::string>())) << t;
    EXPECT_TRUE(modes.count(Field(t, "target").get<std::string>())) << t;
  }
}

TEST(HybridCli, InfoTextOfTheFinger) {
  const Result r = RunHybrid("info " + Quote(kFinger));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.starts_with("# model finger (" + kFinger.string() + ")\n")) << r.out;
  EXPECT_NE(r.out.find("\nautomaton finger {\n"), std::string::npos);
  EXPECT_NE(r.out.find("#   modes (31): c000_l000, "), std::string::npos);
  EXPECT_NE(r.out.find("#   reachable modes (31 of 31)"), std::string::npos);
  EXPECT_NE(r.out.find("\n# warnings: none\n"), std::string::npos);
}

TEST(HybridCli, InfoOfAComposedSystemWithWarnings) {
  TempDir dir;
  const fs::path model = dir.Write("sys.ha", R"(
automaton a {
  var x;
  mode m { x' = 1; }
  mode orphan { }
  transition m -> m { guard x >= 1; reset x := 0; }
  init m { x = 0; }
}
system s {
  instance A = a;
  instance B = a;
  property p: never in A.orphan;
}
)");
  const Result r = RunHybrid("info " + Quote(model) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json info = nlohmann::json::parse(r.out);
  EXPECT_EQ(Field(info, "name"), "s");
  ASSERT_EQ(Field(info, "components").size(), 2u);
  EXPECT_EQ(Field(info, "components", 1, "instance"), "B");
  EXPECT_EQ(Field(info, "components", 1, "unreachable_modes"), nlohmann::json::array({"B.orphan"}));
  EXPECT_EQ(Field(info, "warnings"),
            nlohmann::json::array({"A: mode 'orphan' is unreachable from the initial modes",
                                   "B: mode 'orphan' is unreachable from the initial modes"}));
  EXPECT_EQ(Field(info, "properties", 0, "predicate"), "in A.orphan");
  // With --json the warnings also go to stderr, prefixed by the file.
  EXPECT_EQ(r.err, model.string() +
                       ": warning: A: mode 'orphan' is unreachable from the initial "
                       "modes\n" +
                       model.string() +
                       ": warning: B: mode 'orphan' is unreachable from the initial modes\n");
}

TEST(HybridCli, InfoJsonOfAFileWhoseNameIsNotUtf8) {
  TempDir dir;
  const fs::path model = dir.Write("\xff\xfe.ha", ReadAll(kFinger));
  const Result r = RunHybrid("info " + Quote(model) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json info;
  ASSERT_NO_THROW(info = nlohmann::json::parse(r.out));
  // Invalid bytes become U+FFFD.
  EXPECT_EQ(Field(info, "file"), (dir.path() / "\xef\xbf\xbd\xef\xbf\xbd.ha").string());
}

// ---------------------------------------------------------------------------------------------
// Invalid models.

struct Expectation {
  std::string file;
  std::string diagnostic;  // FILE:LINE:COL: message, the first line of stderr
};

// Test names and failure messages show the file.
void PrintTo(const Expectation& x, std::ostream* os) { *os << x.file; }

std::vector<Expectation> LoadExpectations() {
  std::vector<Expectation> out;
  std::ifstream in(kMalformedDir / "expected.txt");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, '\t');) f.push_back(field);
    if (f.size() < 4) continue;
    const std::string reported = (kMalformedDir / (f.size() == 5 ? f[4] : f[0])).string();
    out.push_back({f[0], reported + ":" + f[1] + ":" + f[2] + ": " + f[3]});
  }
  return out;
}

class MalformedModelTest : public ::testing::TestWithParam<Expectation> {};

TEST_P(MalformedModelTest, ExitsOneWithLocatedDiagnostic) {
  const Expectation& x = GetParam();
  const std::string model = Quote(kMalformedDir / x.file);
  for (const std::string command : {"info", "info --json", "dot", "dot --product"}) {
    const Result r = RunHybrid(command + " " + model);
    EXPECT_EQ(r.exit_code, 1) << command;
    EXPECT_EQ(r.err, x.diagnostic + "\n") << command;
    EXPECT_EQ(r.out, "") << command;
  }
}

INSTANTIATE_TEST_SUITE_P(Malformed, MalformedModelTest, ::testing::ValuesIn(LoadExpectations()),
                         [](const auto& info) {
                           std::string name = fs::path(info.param.file).stem().string();
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(HybridCli, EveryMalformedFileIsCovered) { EXPECT_GE(LoadExpectations().size(), 20u); }

TEST(HybridCli, BinaryModelExitsOne) {
  TempDir dir;
  const char raw[] = "automaton a {\n  var x;\0\n}\n";
  const fs::path model = dir.Write("nul.ha", std::string(raw, sizeof(raw) - 1));
  const Result r = RunHybrid("info " + Quote(model));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, model.string() + ":2:9: NUL byte in model file (binary file?)\n");
  std::mt19937 rng(3);
  std::string garbage(1 << 20, '\0');
  for (char& c : garbage) c = static_cast<char>(rng());
  const fs::path random = dir.Write("random.ha", garbage);
  const Result g = RunHybrid("dot " + Quote(random));
  EXPECT_EQ(g.exit_code, 1);
  EXPECT_TRUE(g.err.starts_with(random.string() + ":1:")) << g.err;
}

TEST(HybridCli, MissingModelFileExitsOne) {
  const fs::path missing = kMalformedDir / "no_such_model.ha";
  const Result r = RunHybrid("info " + Quote(missing));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(r.err.starts_with(missing.string() + ":0:0: cannot read file: ")) << r.err;
}

TEST(HybridCli, ProductTooLargeToDrawExitsOne) {
  TempDir dir;
  std::string text =
      "automaton t { var x; mode a { x' = 1; } mode b { } "
      "transition a -> b { } transition b -> a { } init a { x = 0; } }\n"
      "system s {\n";
  for (int i = 0; i < 11; ++i) text += "  instance I" + std::to_string(i) + " = t;\n";  // 2^11
  const fs::path model = dir.Write("big.ha", text + "}\n");
  const Result r = RunHybrid("dot --product " + Quote(model));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("more than 2000 product modes"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(RunHybrid("dot " + Quote(model)).exit_code, 0);  // clusters are fine
}

// ---------------------------------------------------------------------------------------------
// dot and output files.

TEST(HybridCli, DotToStdoutIsTheLibraryOutput) {
  const Result r = RunHybrid("dot " + Quote(kFinger));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, WriteDot(ParseModelFile(kFinger)));
  const Result dash = RunHybrid("dot " + Quote(kFinger) + " -o -");
  EXPECT_EQ(dash.out, r.out);
}

TEST(HybridCli, DotOutputFileIsComplete) {
  TempDir dir;
  const fs::path out = dir.path() / "finger.dot";
  const Result r = RunHybrid("dot " + Quote(kFinger) + " -o " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
  const std::string written = ReadAll(out);
  EXPECT_EQ(written, WriteDot(ParseModelFile(kFinger)));
  EXPECT_TRUE(written.ends_with("}\n"));
  // Nothing else is left in the directory (no temporary file).
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"finger.dot"});
  // Graphviz accepts it.
  const fs::path svg = dir.path() / "finger.svg";
  EXPECT_EQ(std::system(("dot -Tsvg " + Quote(out) + " -o " + Quote(svg)).c_str()), 0);
  EXPECT_NE(ReadAll(svg).find("<svg"), std::string::npos);
}

TEST(HybridCli, DotProductOutputFile) {
  TempDir dir;
  const fs::path model = dir.Write("sys.ha", R"(
automaton a { var x; mode m { x' = 1; } mode n { } transition m -> n { } init m { x = 0; } }
system s { instance A = a; instance B = a; }
)");
  const fs::path out = dir.path() / "product.dot";
  const Result r = RunHybrid("dot --product " + Quote(model) + " --output " + Quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string written = ReadAll(out);
  EXPECT_EQ(written, WriteDot(ParseModelFile(model), {.product = true}));
  // Product modes named as simulate and check name them (instance.mode joined with "|").
  EXPECT_NE(written.find("label=\"A.n|B.n\\l"), std::string::npos) << written;
  const Result sim = RunHybrid("simulate " + Quote(model) + " --until 1 --json");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_NE(sim.out.find("\"mode\": \"A.n|B.n\""), std::string::npos) << sim.out;
  EXPECT_NE(written.find("label=\"A.m|B.m\\l"), std::string::npos);
}

TEST(HybridCli, UnwritableOutputExitsThreeAndLeavesNoFile) {
  const Result r = RunHybrid("dot " + Quote(kFinger) + " -o /nonexistent_dir/x.dot");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.err,
            "hybrid: cannot write -o '/nonexistent_dir/x.dot': the directory '/nonexistent_dir' "
            "does not exist\n");
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(fs::exists("/nonexistent_dir/x.dot"));
  EXPECT_FALSE(fs::exists("/nonexistent_dir"));
}

TEST(HybridCli, OutputOntoADirectoryExitsThreeAndCleansUp) {
  TempDir dir;
  fs::create_directory(dir.path() / "target");
  const Result r = RunHybrid("dot " + Quote(kFinger) + " -o " + Quote(dir.path() / "target"));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.err, "hybrid: cannot write -o '" + (dir.path() / "target").string() +
                       "': it is a directory\n");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"target"});  // no temporary file left
  EXPECT_TRUE(fs::is_empty(dir.path() / "target"));
}

// Out of memory is a resource error in plain words (it was "internal error: std::bad_alloc"):
// exit 4, no C++ type name. Under a 250 MB limit on virtual memory a small synthesis runs and a
// million-row one does not.
TEST(HybridCli, OutOfMemoryIsReportedInPlainWords) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  const std::string limit = "ulimit -v 250000; ";
  const Result small = RunHybrid("synthesize --free-runs 0 --samples 10 -o /dev/null", "", limit);
  ASSERT_EQ(small.exit_code, 0) << "the limit leaves too little memory to start:\n" << small.err;
  const Result r = RunHybrid("synthesize --free-runs 0 --samples 166666 -o /dev/null", "", limit);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_TRUE(r.err.starts_with("hybrid: out of memory: ")) << r.err;
  EXPECT_EQ(r.err.find("std::"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
}

// An output naming the input model is refused before any work (it was overwritten, exit 0),
// whatever the spelling of the path: exit 2 naming both, the model unchanged.
TEST(HybridCli, DotOutputNamingTheModelIsRefused) {
  TempDir dir;
  const std::string text = ReadAll(kFinger);
  const fs::path model = dir.Write("m.ha", text);
  for (const std::string& out :
       std::vector<std::string>{model.string(), (dir.path() / "." / "m.ha").string(),
                                (dir.path() / "x" / ".." / "m.ha").string()}) {
    if (out.find("/x/") != std::string::npos) fs::create_directory(dir.path() / "x");
    const Result r = RunHybrid("dot " + Quote(model) + " -o " + Quote(out));
    EXPECT_EQ(r.exit_code, 2) << out << "\n" << r.err;
    EXPECT_EQ(r.err, "hybrid: -o '" + out + "' names the input MODEL '" + model.string() +
                         "'; an output may not overwrite an input\n");
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(ReadAll(model), text);
  }
  // A hard link is the same file too.
  fs::create_hard_link(model, dir.path() / "hard.ha");
  EXPECT_EQ(RunHybrid("dot " + Quote(model) + " -o " + Quote(dir.File("hard.ha"))).exit_code, 2);
  EXPECT_EQ(ReadAll(model), text);
}

// Every file reading the model reads is an input no output may name, however spelled: a file it
// imports (directly or not) for dot, simulate, diagnose, synthesize and hand; the command refuses
// before any work, naming the option, the file and its importer, and leaves the file as it was.
TEST(HybridCli, OutputsNamingAFileTheModelImportsAreRefused) {
  TempDir dir;
  const std::string lib_text =
      "automaton lib {\n  var x;\n  mode m { x' = 1; }\n  init m { x = 0; }\n}\n";
  const fs::path lib = dir.Write("lib.ha", lib_text);
  const fs::path main =
      dir.Write("main.ha", "import \"lib.ha\";\nsystem main { instance A = lib; }\n");
  fs::create_symlink(lib, dir.path() / "link.ha");
  fs::create_directory(dir.path() / "x");
  const std::string importer = "(imported by MODEL '" + main.string() + "')";
  struct Case {
    std::string args;
    std::string option;
    std::string output;
  };
  const std::string m = Quote(main);
  for (const Case& c : std::vector<Case>{
           {"dot " + m + " -o", "-o", lib.string()},
           {"dot " + m + " -o", "-o", dir.File("./lib.ha")},
           {"dot " + m + " -o", "-o", dir.File("x/../lib.ha")},
           {"dot " + m + " -o", "-o", dir.File("link.ha")},
           {"simulate " + m + " --until 1 -o", "--out", lib.string()},
           {"simulate " + m + " --until 1 --plot", "--plot", dir.File("link.ha")},
           {"simulate " + m + " --until 1 --events", "--events", dir.File("./lib.ha")},
       }) {
    const Result r = RunHybrid(c.args + " " + Quote(c.output));
    EXPECT_EQ(r.exit_code, 2) << c.args << " " << c.output << "\n" << r.err;
    EXPECT_EQ(r.err, "hybrid: " + c.option + " '" + c.output + "' names the input '" +
                         lib.string() + "' " + importer +
                         "; an output may not overwrite an input\n");
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(ReadAll(lib), lib_text);
  }
  // --model of diagnose and synthesize: refused before the model is read (it is no finger).
  const std::string model = " --model " + m + " ";
  const std::string data = Quote((kSourceDir / "data" / "finger_demo.csv").string());
  for (const std::string& args : {"diagnose " + data + model + "--out-model " + Quote(lib),
                                  "synthesize" + model + "-o " + Quote(dir.File("link.ha"))}) {
    const Result r = RunHybrid(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("names the input '" + lib.string() + "' (imported by --model"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(ReadAll(lib), lib_text);
  }
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"lib.ha", "link.ha", "main.ha", "x"}));
}

// `hand --simulate` reads the hand model and the finger it imports: --draw may name neither.
TEST(HybridCli, HandDrawingOverTheImportedFingerIsRefused) {
  TempDir dir;
  const fs::path hand = dir.Write("hand.ha", ReadAll(kSourceDir / "spec" / "hand.ha"));
  const fs::path finger = dir.Write("finger.ha", ReadAll(kFinger));
  const Result r = RunHybrid("hand --simulate --model " + Quote(hand) + " --draw " + Quote(finger));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err, "hybrid: --draw '" + finger.string() + "' names the input '" + finger.string() +
                       "' (imported by --model '" + hand.string() +
                       "'); an output may not overwrite an input\n");
  EXPECT_EQ(ReadAll(finger), ReadAll(kFinger));
}

// Runs `hybrid ARGS...` (standard streams to /dev/null) and returns its process id.
pid_t SpawnHybrid(const std::vector<std::string>& args) {
  std::vector<std::string> words = {HYBRID_BINARY};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  for (int fd : {0, 1, 2}) {
    posix_spawn_file_actions_addopen(&actions, fd, "/dev/null", fd == 0 ? O_RDONLY : O_WRONLY, 0);
  }
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// Waits (at most `seconds`) for a file whose name starts with `prefix` to be created in the
// directory `inotify` watches; whether one was.
bool AwaitCreated(int inotify, const std::string& prefix, int seconds) {
  alignas(inotify_event) char buffer[4096];
  pollfd p{inotify, POLLIN, 0};
  while (::poll(&p, 1, seconds * 1000) > 0) {
    const ssize_t n = ::read(inotify, buffer, sizeof buffer);
    for (ssize_t at = 0; n > 0 && at < n;) {
      const auto* e = reinterpret_cast<const inotify_event*>(buffer + at);
      if (e->len > 0 && std::string(e->name).starts_with(prefix)) return true;
      at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  }
  return false;
}

// SIGTERM while the outputs are being written (a trajectory of tens of megabytes): the program
// ends by the signal, no temporary file is left, and the target is either not created or
// complete. Retried when the writing ends before the signal arrives.
TEST(HybridCli, SigtermWhileWritingLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string out = dir.File("t.csv");
  for (int attempt = 0; attempt < 5; ++attempt) {
    const int inotify = ::inotify_init1(IN_CLOEXEC);
    ASSERT_GE(inotify, 0);
    ASSERT_GE(::inotify_add_watch(inotify, dir.path().c_str(), IN_CREATE), 0);
    const pid_t pid =
        SpawnHybrid({"simulate", (kSourceDir / "spec" / "thermostat.ha").string(), "--until",
                     "40000", "--sample", "0.1", "-o", out, "--plot", dir.File("t.svg")});
    ASSERT_GT(pid, 0);
    const bool created = AwaitCreated(inotify, ".t.csv.tmp-", 120);
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ::close(inotify);
    ASSERT_TRUE(created) << "no temporary file was written";
    if (!WIFSIGNALED(status)) {  // done before the signal came: again
      fs::remove(out);
      fs::remove(dir.File("t.svg"));
      continue;
    }
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    for (const std::string& name : dir.Files()) {
      EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << name;
    }
    if (fs::exists(out)) {  // stopped while renaming: complete
      const std::string text = ReadAll(out);
      EXPECT_NE(text.find("\n40000,end,"), std::string::npos) << text.substr(text.size() - 200);
    }
    return;
  }
  GTEST_SKIP() << "every run finished writing before SIGTERM arrived";
}

TEST(HybridCli, FullStdoutExitsThree) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const Result dot = RunHybrid("dot " + Quote(kFinger), "/dev/full");
  EXPECT_EQ(dot.exit_code, 3);
  EXPECT_EQ(dot.err, "hybrid: cannot write to standard output\n");
  EXPECT_EQ(RunHybrid("info " + Quote(kFinger), "/dev/full").exit_code, 3);
}

TEST(HybridCli, FailedRunLeavesAnExistingOutputUntouched) {
  TempDir dir;
  const fs::path out = dir.Write("keep.dot", "previous contents\n");
  const Result r =
      RunHybrid("dot " + Quote(kMalformedDir / "bad_operator.ha") + " -o " + Quote(out));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(ReadAll(out), "previous contents\n");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"keep.dot"});
  // A successful run replaces it.
  EXPECT_EQ(RunHybrid("dot " + Quote(kFinger) + " -o " + Quote(out)).exit_code, 0);
  EXPECT_EQ(ReadAll(out), WriteDot(ParseModelFile(kFinger)));
}

// ---------------------------------------------------------------------------------------------
// `hybrid import` and SpaceEx models read by every model command.

namespace spaceex_cli {

const fs::path kFischerXml = kSourceDir / "spec" / "spaceex" / "fischer_2.xml";

TEST(HybridCli, ImportWritesAModelThatChecksLikeTheSpaceExFile) {
  TempDir dir;
  const fs::path out = dir.path() / "fischer.ha";
  const Result import =
      RunHybrid("import " + Quote(kFischerXml.string()) + " -o " + Quote(out.string()));
  ASSERT_EQ(import.exit_code, 0) << import.err;
  // The configuration next to the model was read; its time horizon bounds the property and the
  // default run.
  EXPECT_NE(import.err.find("note: time-horizon = 100 is the horizon of the default run"),
            std::string::npos)
      << import.err;
  EXPECT_NE(ReadAll(out).find("property forbidden: never in P1.cs and in P2.cs within 100;"),
            std::string::npos);
  EXPECT_NE(ReadAll(out).find("scenario { until 100; }"), std::string::npos);
  // Both the written model and the SpaceEx file itself are checked, with the same verdict:
  // Fischer's protocol with Delta = 2 > delta = 1 is safe.
  for (const fs::path& model : {out, kFischerXml}) {
    const Result check = RunHybrid("check " + Quote(model.string()) + " --json");
    ASSERT_EQ(check.exit_code, 0) << check.err;
    const nlohmann::json j = nlohmann::json::parse(check.out);
    EXPECT_EQ(Field(Field(Field(j, "properties"), 0), "verdict"), "proved") << model;
  }
}

// The configuration read beside a SpaceEx model is an input of every command reading the model.
TEST(HybridCli, OutputsNamingTheSpaceExConfigurationAreRefused) {
  TempDir dir;
  const fs::path xml = dir.Write("m.xml", ReadAll(kFischerXml));
  const std::string cfg_text = ReadAll(kSourceDir / "spec" / "spaceex" / "fischer_2.cfg");
  const fs::path cfg = dir.Write("m.cfg", cfg_text);
  for (const std::string& args :
       {"simulate " + Quote(xml) + " --until 1 -o ", "dot " + Quote(xml) + " -o "}) {
    const Result r = RunHybrid(args + Quote(cfg));
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err, "hybrid: " + std::string(args[0] == 's' ? "--out" : "-o") + " '" +
                         cfg.string() + "' names the input '" + cfg.string() +
                         "' (the SpaceEx configuration of MODEL '" + xml.string() +
                         "'); an output may not overwrite an input\n");
    EXPECT_EQ(ReadAll(cfg), cfg_text);
  }
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"m.cfg", "m.xml"}));
}

TEST(HybridCli, ImportRefusesToOverwriteItsInputsAndReportsBadFiles) {
  TempDir dir;
  const fs::path xml = dir.Write("m.xml", ReadAll(kFischerXml));
  const fs::path cfg = dir.Write("m.cfg", "initially = \"k == 0 & zz == 1\"\n");
  // The configuration found next to the model is an input too.
  Result r = RunHybrid("import " + Quote(xml.string()) + " -o " + Quote(cfg.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("an output may not overwrite an input"), std::string::npos) << r.err;
  EXPECT_EQ(ReadAll(cfg), "initially = \"k == 0 & zz == 1\"\n");
  r = RunHybrid("import " + Quote(xml.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, cfg.string() + ":1:23: undefined name 'zz' in 'initially'\n");
  const fs::path broken =
      dir.Write("broken.xml", "<sspaceex>\n  <component id=\"c\">\n</sspaceex>\n");
  r = RunHybrid("check " + Quote(broken.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, broken.string() + ":3:3: malformed XML: Start-end tags mismatch\n");
  r = RunHybrid("import " + Quote(xml.string()) + " --config " +
                Quote((dir.path() / "none.cfg").string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("none.cfg:0:0: cannot read file"), std::string::npos) << r.err;
}

}  // namespace spaceex_cli

}  // namespace
}  // namespace hybrid
