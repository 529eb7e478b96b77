// Tests of the model-language parser: every malformed model of tests/data/malformed gives the
// ParseError recorded in tests/data/malformed/expected.txt (file, line, column and message
// exactly); binary and 10 MB inputs give a ParseError or parse, quickly, and never crash; and
// valid models give the expected IR.

#include "hybrid/automaton/parser.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/compiled_expression.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/automaton/system.h"
#include "tests/automaton/stack_budget.h"
#include "tests/test_utilities/command_line.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

const fs::path kSourceDir = HYBRID_SOURCE_DIR;
const fs::path kMalformedDir = kSourceDir / "tests" / "data" / "malformed";

// ---------------------------------------------------------------------------------------------
// Helpers.

// One line of tests/data/malformed/expected.txt.
struct Expectation {
  std::string file;  // the file parsed, relative to kMalformedDir
  int line = 0;
  int column = 0;
  std::string message;      // ParseError::message(), exactly
  std::string reported_in;  // the file the error is reported in (relative), usually `file`
};

// Test names and failure messages show the file.
void PrintTo(const Expectation& x, std::ostream* os) { *os << x.file; }

std::vector<std::string> SplitTabs(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, '\t')) fields.push_back(field);
  return fields;
}

std::vector<Expectation> LoadExpectations() {
  std::vector<Expectation> out;
  std::ifstream in(kMalformedDir / "expected.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> f = SplitTabs(line);
    if (f.size() != 4 && f.size() != 5) {
      ADD_FAILURE() << "malformed line in expected.txt: " << line;
      continue;
    }
    out.push_back({f[0], std::stoi(f[1]), std::stoi(f[2]), f[3], f.size() == 5 ? f[4] : f[0]});
  }
  return out;
}

std::string TestName(const ::testing::TestParamInfo<Expectation>& info) {
  std::string name = fs::path(info.param.file).stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

// The ParseError that parsing `text` throws; fails the test if none (or another exception) is
// thrown.
ParseError ParseFailure(std::string_view text, const std::string& file = "test.ha") {
  try {
    ParseModel(text, file);
  } catch (const ParseError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected a ParseError, got another exception: " << e.what();
    return ParseError(file, -1, -1, "wrong exception");
  }
  ADD_FAILURE() << "expected a ParseError, but the model parsed";
  return ParseError(file, -1, -1, "no exception");
}

// Parses `text` and returns its only automaton (as declared).
Automaton OnlyAutomaton(std::string_view text) {
  const System s = ParseModel(text, "test.ha");
  EXPECT_EQ(s.components().size(), 1u);
  return s.components()[0].source;
}

Expression Sym(const Automaton& a, const std::string& name) {
  const auto slot = a.symbols().Find(name);
  EXPECT_TRUE(slot.has_value()) << name;
  return Expression::Symbol(name, slot.value_or(0));
}

Expression C(double v) { return Expression::Constant(v); }

// Runs `f` and returns its wall time in seconds.
double Seconds(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// ParseModel on `text`: must either parse or throw a ParseError with a location inside the text,
// within `limit` seconds. Returns whether it parsed.
bool ParsesOrFailsCleanly(const std::string& text, double limit) {
  bool parsed = false;
  const double t = Seconds([&] {
    try {
      ParseModel(text, "big.ha");
      parsed = true;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "big.ha");
      EXPECT_GE(e.line(), 1);
      EXPECT_GE(e.column(), 1);
      EXPECT_FALSE(e.message().empty());
      EXPECT_EQ(std::string(e.what()).rfind("big.ha:", 0), 0u) << e.what();
    }
  });
  EXPECT_LT(t, limit) << "parsing " << text.size() << " bytes took " << t << " s";
  return parsed;
}

// Sanitizers slow every instruction down by a roughly constant factor; these limits are about
// how parsing grows with the input, not about the speed of one build.
constexpr double SanitizerSlowdown() {
#if defined(__SANITIZE_ADDRESS__)
  return 10.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return 10.0;
#endif
#endif
  return 1.0;
}

// Seconds, for every 10 MB input below.
constexpr double kTimeLimit = 5.0 * SanitizerSlowdown();
constexpr size_t kTenMegabytes = 10u << 20;

const char* const kSmallModel = R"(automaton a {
  var x;
  mode m { x' = 1; }
  init m { x = 0; }
}
)";

// ---------------------------------------------------------------------------------------------
// Malformed files.

class MalformedFileTest : public ::testing::TestWithParam<Expectation> {};

TEST_P(MalformedFileTest, ThrowsParseErrorAtTheOffendingToken) {
  const Expectation& x = GetParam();
  const fs::path path = kMalformedDir / x.file;
  ASSERT_TRUE(fs::exists(path)) << path;
  try {
    ParseModelFile(path);
    FAIL() << x.file << " parsed";
  } catch (const ParseError& e) {
    const std::string file = (kMalformedDir / x.reported_in).string();
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.line(), x.line);
    EXPECT_EQ(e.column(), x.column);
    EXPECT_EQ(e.message(), x.message);
    EXPECT_EQ(std::string(e.what()), file + ":" + std::to_string(x.line) + ":" +
                                         std::to_string(x.column) + ": " + x.message);
  } catch (const std::exception& e) {
    FAIL() << x.file << ": not a ParseError: " << e.what();
  }
}

// Parsing the text directly (ParseModel) reports the same error; imports are resolved relative
// to the name given.
TEST_P(MalformedFileTest, ParseModelOnTheTextGivesTheSameError) {
  const Expectation& x = GetParam();
  std::ifstream in(kMalformedDir / x.file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const std::string name = (kMalformedDir / x.file).string();
  const ParseError e = ParseFailure(text.str(), name);
  EXPECT_EQ(e.file(), (kMalformedDir / x.reported_in).string());
  EXPECT_EQ(e.line(), x.line);
  EXPECT_EQ(e.column(), x.column);
  EXPECT_EQ(e.message(), x.message);
}

INSTANTIATE_TEST_SUITE_P(Malformed, MalformedFileTest, ::testing::ValuesIn(LoadExpectations()),
                         TestName);

TEST(MalformedFiles, TableCoversEveryFileAndNoMore) {
  std::set<std::string> on_disk;
  for (const auto& entry : fs::directory_iterator(kMalformedDir)) {
    if (entry.path().extension() == ".ha") on_disk.insert(entry.path().filename().string());
  }
  std::set<std::string> in_table;
  for (const Expectation& x : LoadExpectations()) {
    EXPECT_TRUE(in_table.insert(x.file).second) << "listed twice: " << x.file;
  }
  EXPECT_EQ(on_disk, in_table);
  EXPECT_GE(in_table.size(), 20u);
}

// ---------------------------------------------------------------------------------------------
// Generated malformed inputs: binary, NUL bytes, limits.

TEST(ParseErrors, NulByteIsReportedWhereItIs) {
  const char raw[] = "automaton a {\n  var x;\0\n}\n";
  const std::string text(raw, sizeof(raw) - 1);
  const ParseError e = ParseFailure(text);
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.column(), 9);
  EXPECT_EQ(e.message(), "NUL byte in model file (binary file?)");
}

TEST(ParseErrors, BinaryGarbageIsReportedAtTheFirstControlByte) {
  // The start of an ELF header: DEL, 'E', 'L', 'F', then byte 2.
  const std::string text(
      "\x7f"
      "ELF\x02\x01\x01\x00\x00\x00",
      10);
  const ParseError e = ParseFailure(text, "prog.ha");
  EXPECT_EQ(e.file(), "prog.ha");
  EXPECT_EQ(e.line(), 1);
  EXPECT_EQ(e.column(), 5);
  EXPECT_EQ(e.message(), "control character 2 in model file (binary file?)");
}

// Messages quote the input; what they quote reaches a terminal escaped (automaton/quoted_text.h):
// a vertical tab and a C1 CSI (U+009B, ESC [ to some terminals) in an import's file name.
TEST(ParseErrors, ControlCharactersQuotedFromTheInputAreEscaped) {
  const ParseError e = ParseFailure("import \"a\vb\xc2\x9b[2J.ha\";\n" + std::string(kSmallModel));
  EXPECT_EQ(e.message(), "cannot import 'a\\x0bb\\u009b[2J.ha': no such file");
  EXPECT_EQ(std::string(e.what()), "test.ha:1:1: " + e.message());
  // The file name too, in what(); file() keeps it as given.
  const ParseError named("m\x1b]0;t\a.ha", 2, 3, "line\nbreak");
  EXPECT_EQ(std::string(named.what()), "m\\x1b]0;t\\x07.ha:2:3: line\\nbreak");
  EXPECT_EQ(named.file(), "m\x1b]0;t\a.ha");
  EXPECT_EQ(named.message(), "line\\nbreak");
}

TEST(ParseErrors, NonAsciiBytesOutsideCommentsAreSyntaxErrors) {
  const ParseError e = ParseFailure("automaton \xc3\xa9t\xc3\xa9 { }\n");
  EXPECT_EQ(e.line(), 1);
  EXPECT_EQ(e.column(), 11);
  EXPECT_EQ(e.message(), "expected a name");
}

TEST(ParseErrors, NonAsciiBytesInCommentsAreFine) {
  EXPECT_NO_THROW(ParseModel("# \xc3\xa9t\xc3\xa9 \xff\xfe\n" + std::string(kSmallModel), "t.ha"));
}

TEST(ParseErrors, MissingFileIsReportedAtLineZero) {
  const fs::path path = kMalformedDir / "this_file_does_not_exist.ha";
  try {
    ParseModelFile(path);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message().rfind("cannot read file: ", 0), 0u) << e.message();
  }
}

TEST(ParseErrors, DirectoryIsNotAModelFile) {
  try {
    ParseModelFile(kMalformedDir);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), kMalformedDir.string());
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message(), "cannot read file: it is a directory");
  }
}

TEST(ParseErrors, FileLargerThanTheLimitIsRejectedBeforeReading) {
  TempDir dir;
  const fs::path path = dir.Write("huge.ha", "");
  fs::resize_file(path, kMaxModelFileBytes + 1);  // sparse: nothing is written
  try {
    ParseModelFile(path);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message(), "file is " + std::to_string(kMaxModelFileBytes + 1) +
                               " bytes, larger than the " + std::to_string(kMaxModelFileBytes) +
                               "-byte limit for model files");
  }
}

TEST(ParseErrors, ErrorsInAnImportedFilePointIntoThatFile) {
  TempDir dir;
  dir.Write("lib.ha", "automaton lib {\n  var x;\n  mode m { x' = y; }\n  init m { x = 0; }\n}\n");
  const fs::path main =
      dir.Write("main.ha", "import \"lib.ha\";\nsystem s { instance L = lib; }\n");
  try {
    ParseModelFile(main);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), (dir.path() / "lib.ha").string());
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.column(), 17);
    EXPECT_EQ(e.message(), "undefined name 'y'");
  }
}

TEST(ParseErrors, ImportingItselfIsACycleDetectedAtOnce) {
  TempDir dir;
  const fs::path self = dir.Write("self.ha", std::string("import \"self.ha\";\n") + kSmallModel);
  try {
    ParseModelFile(self);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), self.string());
    EXPECT_EQ(e.line(), 1);
    EXPECT_EQ(e.column(), 1);
    EXPECT_EQ(e.message(), "import cycle through 'self.ha'");
  }
}

TEST(ParseErrors, ParseAutomatonWantsExactlyOneAutomaton) {
  EXPECT_NO_THROW(ParseAutomaton(kSmallModel, "t.ha"));
  EXPECT_THROW(ParseAutomaton(std::string(kSmallModel) + "system s { instance a; }\n", "t.ha"),
               ParseError);
  EXPECT_THROW(ParseAutomaton(std::string(kSmallModel) +
                                  "automaton b { var y; mode n { y' = 1; } init n { y = 0; } }",
                              "t.ha"),
               ParseError);
  EXPECT_THROW(ParseAutomaton("", "t.ha"), ParseError);
}

TEST(ParseErrors, SignalValueOutsideTheInputBoundsIsReportedAtTheValue) {
  const ParseError e = ParseFailure(R"(automaton a {
  var x;
  input u in [0, 2];
  mode m { x' = u; }
  init m { x = 0; }
  scenario { until 1; u = -0.5; }
})");
  EXPECT_EQ(e.line(), 6);
  EXPECT_EQ(e.column(), 27);
  EXPECT_EQ(e.message(), "signal for 'u' takes value -0.5 outside its bounds [0, 2]");
}

// An expression as deep as allowed parses and survives the IR's recursive tree walks; one level
// more is a ParseError at the operator that crosses the limit.
TEST(ParseErrors, ExpressionDepthLimitIsExact) {
  auto model = [](int terms) {
    std::string text = "automaton a {\n  var x;\n  mode m { x' = x";
    for (int i = 1; i < terms; ++i) text += " + x";
    return text + "; }\n  init m { x = 0; }\n}\n";
  };
  const Automaton a = OnlyAutomaton(model(kMaxExpressionDepth));
  const Expression& flow = a.modes()[0].flows.at(0).second;
  EXPECT_EQ(flow.Evaluate(std::vector<double>{2.0}), 2.0 * kMaxExpressionDepth);
  EXPECT_EQ(flow.Slots(), std::vector<int>{0});
  EXPECT_EQ(flow.ToString().size(), 4u * kMaxExpressionDepth - 3);
  EXPECT_EQ(flow.Derivative(0).Evaluate(std::vector<double>{0.0}), kMaxExpressionDepth);

  const ParseError e = ParseFailure(model(kMaxExpressionDepth + 1));
  EXPECT_EQ(e.line(), 3);
  // "  mode m { x' = x" is 17 bytes; operator j (from 1) is at column 19 + 4 (j - 1).
  EXPECT_EQ(e.column(), 19 + 4 * (kMaxExpressionDepth - 1));
  EXPECT_EQ(e.message(), "expression too long or nested too deeply (more than " +
                             std::to_string(kMaxExpressionDepth) + " levels)");
}

TEST(ParseErrors, LongDisjunctionInAPropertyIsRejectedNotACrash) {
  std::string text =
      std::string(kSmallModel, std::string(kSmallModel).size() - 2) + "  property p: always x > 0";
  for (int i = 0; i < 100000; ++i) text += " or x > 0";
  text += ";\n}\n";
  const ParseError e = ParseFailure(text);
  EXPECT_EQ(e.line(), 5);
  EXPECT_EQ(e.message().rfind("expression too long or nested too deeply", 0), 0u) << e.message();
}

// Dense expressions parse at roughly 1 MB/s (the PEGTL parse tree allocates several nodes per
// token), so these inputs are smaller than 10 MB.
TEST(ParseErrors, LongSumIsRejectedQuickly) {
  std::string text = "automaton a {\n  var x;\n  mode m { x' = x";
  while (text.size() < (256u << 10)) text += "+x";
  text += "; }\n  init m { x = 0; }\n}\n";
  EXPECT_FALSE(ParsesOrFailsCleanly(text, kTimeLimit));
}

TEST(ParseErrors, LongInvariantParsesQuickly) {
  std::string text = "automaton a {\n  var x;\n  mode m { x' = 1; inv x >= 0";
  while (text.size() < (256u << 10)) text += " and x <= 1";
  text += "; }\n  init m { x = 0; }\n}\n";
  EXPECT_TRUE(ParsesOrFailsCleanly(text, kTimeLimit));
}

// A flow `x' = <expression>` in an otherwise valid model; the expression starts at line 3,
// column 17.
std::string ModelWithFlow(const std::string& expression) {
  return "automaton a {\n  var x;\n  mode m { x' = " + expression + "; }\n  init m { x = 0; }\n}\n";
}

// `open` repeated n times, then `middle`, then `close` n times.
std::string Nested(const std::string& open, int n, const std::string& middle,
                   const std::string& close = "") {
  std::string out;
  for (int i = 0; i < n; ++i) out += open;
  out += middle;
  for (int i = 0; i < n; ++i) out += close;
  return out;
}

// The sum x + x + ... of `terms` terms (as many levels).
std::string SumOf(int terms) {
  std::string text = "x";
  for (int i = 1; i < terms; ++i) text += " + x";
  return text;
}

// A 10000-term sum used to overflow the stack of the IR's tree walks (printing, evaluation, ...)
// under AddressSanitizer or a 1 MiB stack: it is now refused at the operator that crosses the
// limit, before any tree that deep exists.
TEST(ParseErrors, TenThousandTermSumIsAClearError) {
  const ParseError e = ParseFailure(ModelWithFlow(SumOf(10000)), "sum.ha");
  EXPECT_EQ(e.file(), "sum.ha");
  EXPECT_EQ(e.line(), 3);
  // Operator j (from 1) is at column 19 + 4 (j - 1); operator kMaxExpressionDepth makes the
  // tree one level too deep.
  EXPECT_EQ(e.column(), 19 + 4 * (kMaxExpressionDepth - 1));
  EXPECT_EQ(e.message(), "expression too long or nested too deeply (more than " +
                             std::to_string(kMaxExpressionDepth) + " levels)");
}

// Nesting recurses in the parser itself (PEGTL's rules and parse tree): 10000 levels of each
// kind of nesting are refused with a located message, and refusing them fits a 1 MiB stack.
TEST(ParseErrors, TenThousandNestingLevelsAreAClearErrorOnASmallStack) {
  struct Case {
    const char* what;
    std::string text;
  };
  const std::vector<Case> cases = {
      {"parentheses", ModelWithFlow(Nested("(", 10000, "x", ")"))},
      {"unary minus", ModelWithFlow(Nested("-", 10000, "x"))},
      {"spaced unary minus", ModelWithFlow(Nested("- ", 10000, "x"))},
      {"powers", ModelWithFlow(Nested("x^", 10000, "x"))},
      {"calls", ModelWithFlow(Nested("sin(", 10000, "x", ")"))},
      {"parenthesised predicate", std::string(kSmallModel, std::string(kSmallModel).size() - 2) +
                                      "  property p: always " + Nested("(", 10000, "x > 0", ")") +
                                      ";\n}\n"},
      {"negated predicate", std::string(kSmallModel, std::string(kSmallModel).size() - 2) +
                                "  property p: always " + Nested("not ", 10000, "x > 0") +
                                ";\n}\n"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    testing::RunOnStack(testing::kOneMebibyte, [&] {
      const ParseError e = ParseFailure(c.text, "nest.ha");
      EXPECT_EQ(e.file(), "nest.ha");
      EXPECT_GE(e.line(), 3);
      EXPECT_GT(e.column(), 1);
      EXPECT_TRUE(e.message() == "expression nested too deeply" ||
                  e.message().starts_with("expression too long or nested too deeply"))
          << e.message();
    });
  }
}

// The deepest expressions the parser accepts, of every shape, go through every walk of the IR on
// a 1 MiB stack: building, printing the model, parsing the print back, evaluation, compilation,
// composition and destruction. The values are checked against closed forms.
TEST(Parser, DeepestAcceptedExpressionsFitASmallStack) {
  // The deepest nesting of `open` the parser accepts (found by bisection; 10000 is refused).
  auto deepest = [](const std::string& open, const std::string& middle, const std::string& close) {
    int lo = 1, hi = 10000;
    while (lo + 1 < hi) {
      const int mid = (lo + hi) / 2;
      try {
        ParseModel(ModelWithFlow(Nested(open, mid, middle, close)), "t.ha");
        lo = mid;
      } catch (const ParseError&) {
        hi = mid;
      }
    }
    return lo;
  };
  testing::RunOnStack(testing::kOneMebibyte, [&] {
    const int parens = deepest("(x - ", "x", ")");
    const int minus = deepest("-", "x", "");
    EXPECT_GE(parens, 20);  // enough for any hand-written model
    EXPECT_GE(minus, 20);
    // Sum at the limit (x at 1: kMaxExpressionDepth), nested differences x - (x - (...)) (x at
    // 1: 1 when the count of x is odd, 0 when even), alternating signs -(-(...x)) (x at 1:
    // (-1)^minus), and a comparison whose residual is at the limit.
    const std::string text =
        "automaton a {\n  var x;\n  var y;\n  var z;\n  mode m {\n    x' = " +
        SumOf(kMaxExpressionDepth) + ";\n    y' = " + Nested("(x - ", parens, "x", ")") +
        ";\n    z' = " + Nested("-", minus, "x") + ";\n    inv " + SumOf(kMaxExpressionDepth - 1) +
        " >= 0;\n  }\n  init m { x = 1; y = 0; z = 0; }\n}\n";
    const System s = ParseModel(text, "deep.ha");
    const Automaton& a = s.components()[0].automaton;
    const auto& flows = a.modes()[0].flows;
    ASSERT_EQ(flows.size(), 3u);
    EXPECT_EQ(flows[0].second.depth(), kMaxExpressionDepth);
    EXPECT_EQ(a.modes()[0].invariant.comparisons[0].Residual().depth(), kMaxExpressionDepth);
    const std::vector<double> env = {1.0, 0.0, 0.0};
    EXPECT_EQ(flows[0].second.Evaluate(env), kMaxExpressionDepth);
    EXPECT_EQ(flows[1].second.Evaluate(env), (parens + 1) % 2 == 1 ? 1.0 : 0.0);
    EXPECT_EQ(flows[2].second.Evaluate(env), minus % 2 == 0 ? 1.0 : -1.0);
    for (const auto& [slot, rhs] : flows) {
      EXPECT_EQ(CompiledExpression(rhs).Evaluate(env.data()), rhs.Evaluate(env));
    }
    // Print and parse back: the same model.
    const std::string printed = PrintSystem(s);
    EXPECT_EQ(ParseModel(printed, "printed.ha"), s);
    EXPECT_EQ(s.Product().num_modes(), 1);
  });
}

// ---------------------------------------------------------------------------------------------
// Reading model files.

// Positions in the parse tree refer to its input (its text and its source name). One taken after
// the input was destroyed read freed memory on every parse of a file (valgrind and
// AddressSanitizer saw it with a file name longer than the small-string buffer); under the
// sanitized test run these fail if it comes back.
TEST(Parser, ModelFromALongAbsolutePath) {
  TempDir dir;
  const fs::path deep = dir.path() / std::string(100, 'd') / "a_directory_with_a_long_name";
  fs::create_directories(deep);
  const fs::path model = deep / "thermostat_copied_under_a_rather_long_file_name.ha";
  fs::copy_file(kSourceDir / "spec" / "thermostat.ha", model);
  ASSERT_GT(model.string().size(), 150u);
  const System s = ParseModelFile(model);
  EXPECT_EQ(s.name(), "thermostat");
  EXPECT_EQ(s.components()[0].automaton.num_modes(), 2);
}

// The error is located after the whole file is built, from a position kept since the second
// automaton's name was parsed.
TEST(ParseErrors, SecondAutomatonWithoutSystemFromALongAbsolutePath) {
  TempDir dir;
  const fs::path deep = dir.path() / std::string(100, 'd');
  fs::create_directories(deep);
  const fs::path path = deep / "two_automata_and_no_system_in_one_file.ha";
  std::ofstream(path) << kSmallModel
                      << "automaton b {\n  var y;\n  mode n { y' = 1; }\n  init n { y = 0; }\n}\n";
  try {
    ParseModelFile(path);
    FAIL() << "parsed";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), 6);
    EXPECT_EQ(e.column(), 11);
    EXPECT_EQ(e.message(),
              "the file declares 2 automata and no system: add 'system NAME { instance A = a; ... "
              "}'");
  }
}

// Each import nests a parse: a chain of kMaxImportDepth imports is fine, one more is an error in
// the file whose import goes too deep.
TEST(ParseErrors, ImportsNestAtMostTheLimitDeep) {
  TempDir dir;
  auto chain = [&](int imports) {
    // f0 imports f1, ..., f(imports - 1) imports f(imports), which declares the automaton.
    for (int i = 0; i < imports; ++i) {
      dir.Write("f" + std::to_string(i) + ".ha",
                "import \"f" + std::to_string(i + 1) + ".ha\";\n" +
                    (i == 0 ? "system s { instance A = a; }\n" : ""));
    }
    dir.Write("f" + std::to_string(imports) + ".ha", kSmallModel);
    return dir.path() / "f0.ha";
  };
  EXPECT_EQ(ParseModelFile(chain(kMaxImportDepth)).components().size(), 1u);
  try {
    ParseModelFile(chain(kMaxImportDepth + 1));
    FAIL() << "parsed";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), (dir.path() / ("f" + std::to_string(kMaxImportDepth) + ".ha")).string());
    EXPECT_EQ(e.line(), 1);
    EXPECT_EQ(e.column(), 1);
    EXPECT_EQ(e.message(),
              "imports nested more than " + std::to_string(kMaxImportDepth) + " files deep");
  }
}

// Each file imports the next one twice, 40 files deep: every file used to be read and parsed
// once per path that reaches it (2^40 times for the last), a hang. Each is now read once.
TEST(ParseErrors, ImportsReachingAFileTwiceReadItOnce) {
  TempDir dir;
  constexpr int kDepth = 40;
  for (int i = 0; i < kDepth; ++i) {
    const std::string next = "\"f" + std::to_string(i + 1) + ".ha\";\n";
    dir.Write(
        "f" + std::to_string(i) + ".ha",
        "import " + next + "import " + next + (i == 0 ? "system s { instance A = a; }\n" : ""));
  }
  dir.Write("f" + std::to_string(kDepth) + ".ha", kSmallModel);
  EXPECT_EQ(ParseModelFile(dir.path() / "f0.ha").components().size(), 1u);
}

// The size limit bounds a model with its imports: five files of a fifth of the limit each pass
// it together, at the import that passes it.
TEST(ParseErrors, ImportsCountTowardsTheModelSizeLimit) {
  TempDir dir;
  const std::string padding((kMaxModelFileBytes / 5) + 1, '#');
  std::string main;
  for (int i = 0; i < 5; ++i) {
    dir.Write("part" + std::to_string(i) + ".ha", padding + "\n");
    main += "import \"part" + std::to_string(i) + ".ha\";\n";
  }
  const fs::path path = dir.Write("main.ha", main + std::string(kSmallModel));
  try {
    ParseModelFile(path);
    FAIL() << "parsed";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), 5);
    EXPECT_EQ(e.message(),
              "cannot import 'part4.ha': the model and its imports are larger than the " +
                  std::to_string(kMaxModelFileBytes) + "-byte limit for models");
  }
}

// A UTF-8 byte-order mark, which some editors write, used to be "expected 'automaton', ...".
TEST(Parser, LeadingByteOrderMarkIsSkipped) {
  const std::string bom = "\xEF\xBB\xBF";
  EXPECT_EQ(OnlyAutomaton(bom + kSmallModel).num_modes(), 1);
  TempDir dir;
  EXPECT_EQ(ParseModelFile(dir.Write("bom.ha", bom + kSmallModel)).name(), "a");
  // Columns of the first line count from after the mark.
  const ParseError first = ParseFailure(bom + "automaton 1 { }\n");
  EXPECT_EQ(first.line(), 1);
  EXPECT_EQ(first.column(), 11);
  EXPECT_EQ(first.message(), "expected a name");
  // Only one mark, only at the start: anywhere else it is a stray byte.
  const ParseError twice = ParseFailure(bom + bom + kSmallModel);
  EXPECT_EQ(twice.line(), 1);
  EXPECT_EQ(twice.column(), 1);
  EXPECT_EQ(twice.message(), "expected 'automaton', 'system' or 'import' at top level");
  const ParseError later = ParseFailure(std::string(kSmallModel) + bom);
  EXPECT_EQ(later.line(), 6);
  EXPECT_EQ(later.column(), 1);
}

// A model on a pipe (`hybrid info <(cat m.ha)`, /dev/stdin) used to fail with "Operation not
// supported": the file's size was asked before reading.
TEST(Parser, ModelOnAPipe) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const std::string text = kSmallModel;
  ASSERT_EQ(write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(fds[1]);
  const fs::path path = "/dev/fd/" + std::to_string(fds[0]);
  try {
    const System s = ParseModelFile(path);
    EXPECT_EQ(s.name(), "a");
    EXPECT_EQ(s.components()[0].automaton.num_modes(), 1);
  } catch (const ParseError& e) {
    ADD_FAILURE() << e.what();
  }
  close(fds[0]);
}

// Writes `text` into the FIFO `path` from another thread (a FIFO opens only with both ends).
class FifoWriter {
 public:
  FifoWriter(const fs::path& path, std::string text)
      : thread_([path, text = std::move(text)] {
          std::ofstream out(path, std::ios::binary);
          out << text;
        }) {}
  ~FifoWriter() { thread_.join(); }

 private:
  std::thread thread_;
};

TEST(Parser, ModelOnAFifoLargerThanAPipeBuffer) {
  TempDir dir;
  const fs::path fifo = dir.path() / "model.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // A megabyte of comment first: many reads, far beyond the 64 KiB a pipe holds.
  const std::string text = "#" + std::string(1u << 20, 'c') + "\n" + kSmallModel;
  FifoWriter writer(fifo, text);
  EXPECT_EQ(ParseModelFile(fifo).components()[0].automaton.num_modes(), 1);
}

TEST(ParseErrors, StreamLargerThanTheLimitIsRejected) {
  TempDir dir;
  const fs::path fifo = dir.path() / "huge.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  FifoWriter writer(fifo, std::string(kMaxModelFileBytes + 1, '#'));
  try {
    ParseModelFile(fifo);
    ADD_FAILURE() << "parsed";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), fifo.string());
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message(), "file is larger than the " + std::to_string(kMaxModelFileBytes) +
                               "-byte limit for model files");
  }
}

// The ids of the threads of this process (Linux: the entries of /proc/self/task).
std::set<std::string> ThreadIds() {
  std::set<std::string> ids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    ids.insert(entry.path().filename().string());
  }
  return ids;
}

// The parser runs on a large stack of its own thread, made once per calling thread and reused:
// one thread per parse cost a thread creation each time and, under AddressSanitizer, ~200 bytes
// kept per thread ever made (a long fuzzing run ran out of memory). Observed from a new calling
// thread: its first parse adds one thread, which stays, the same one, through later parses and
// ends with the caller. (With a thread per parse, no thread would stay after the first.)
TEST(Parser, ReusesOneThreadForItsStack) {
  constexpr std::string_view kModel =
      "automaton t { var x in [0, 30]; mode on { x' = 1; } init on { x = 20; } }";
  const std::set<std::string> outside = ThreadIds();
  std::set<std::string> before, after_first;
  std::vector<std::set<std::string>> during;
  std::thread caller([&] {
    before = ThreadIds();
    (void)ParseModel(kModel, "a.ha");
    after_first = ThreadIds();
    for (int i = 0; i < 20; ++i) {
      (void)ParseModel(kModel, "a.ha");
      (void)ParseSignal("step(0: 1, 10: -1)", "signal");
      during.push_back(ThreadIds());
    }
  });
  caller.join();
  EXPECT_EQ(after_first.size(), before.size() + 1);
  for (const auto& ids : during) EXPECT_EQ(ids, after_first);
  // The caller's parser thread has ended with it (its entry may take a moment to go).
  for (int i = 0; i < 100 && ThreadIds() != outside; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(ThreadIds(), outside);
}

// A child made by fork() has no copy of the parser's thread: it parses on its own stack rather
// than wait for a thread that does not exist (alarm() turns such a wait into a failure).
TEST(Parser, ParsesInAForkedChild) {
  (void)ParseModel("automaton t { var x in [0, 1]; mode m { x' = 0; } init m { x = 0; } }", "a.ha");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    alarm(10);
    try {
      const System s = ParseModel(
          "automaton t { var x in [0, 1]; mode m { x' = 0; } init m { x = 0; } }", "a.ha");
      _exit(s.name() == "t" ? 0 : 1);
    } catch (...) {
      _exit(2);
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child was killed (signal " << WTERMSIG(status) << ")";
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// ---------------------------------------------------------------------------------------------
// 10 MB inputs.

TEST(LargeInputs, TenMegabytesOfOpeningParentheses) {
  const std::string text(kTenMegabytes, '(');
  EXPECT_FALSE(ParsesOrFailsCleanly(text, kTimeLimit));
  const ParseError e = ParseFailure(text, "big.ha");
  EXPECT_EQ(e.line(), 1);
  EXPECT_EQ(e.column(), 1);
  EXPECT_EQ(e.message(), "expected 'automaton', 'system' or 'import' at top level");
}

TEST(LargeInputs, TenMegabytesOfParenthesesInsideAnExpression) {
  const std::string text =
      "automaton a {\n  var x;\n  mode m { x' = " + std::string(kTenMegabytes, '(') + "x; }\n}\n";
  EXPECT_FALSE(ParsesOrFailsCleanly(text, kTimeLimit));
  const ParseError e = ParseFailure(text, "big.ha");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.message(), "expression nested too deeply");
}

TEST(LargeInputs, TenMegabyteCommentFollowedByAValidModel) {
  const std::string text = "#" + std::string(kTenMegabytes, 'c') + "\n" + kSmallModel;
  EXPECT_TRUE(ParsesOrFailsCleanly(text, kTimeLimit));
  EXPECT_EQ(ParseModel(text, "big.ha").components()[0].automaton.num_modes(), 1);
}

TEST(LargeInputs, TenMegabytesOfRandomBytes) {
  std::mt19937 rng(20261121);
  std::string text(kTenMegabytes, '\0');
  for (char& c : text) c = static_cast<char>(rng() & 0xff);
  EXPECT_FALSE(ParsesOrFailsCleanly(text, kTimeLimit));
}

TEST(LargeInputs, TenMegabytesOfRandomPrintableText) {
  // No control bytes, so the grammar itself has to reject it.
  const std::string alphabet = "abcxyz_019 \n\t(){}[];:=<>+-*/^.,'#\"";
  std::mt19937 rng(7);
  std::string text(kTenMegabytes, ' ');
  for (char& c : text) c = alphabet[rng() % alphabet.size()];
  EXPECT_FALSE(ParsesOrFailsCleanly(text, kTimeLimit));
}

TEST(LargeInputs, TenMegabytesOfRandomTokensInsideAMode) {
  const std::vector<std::string> tokens = {"x", "1", "+", "-", "*", "(", ")", " ", "sin", ","};
  std::mt19937 rng(11);
  std::string text = "automaton a {\n  var x;\n  mode m { x' = ";
  while (text.size() < kTenMegabytes) text += tokens[rng() % tokens.size()];
  text += "; }\n  init m { x = 0; }\n}\n";
  ParsesOrFailsCleanly(text, kTimeLimit);
}

// ---------------------------------------------------------------------------------------------
// Valid models: the IR.

TEST(Parser, EveryBundledSpecParses) {
  int count = 0;
  for (const auto& entry : fs::recursive_directory_iterator(kSourceDir / "spec")) {
    if (entry.path().extension() != ".ha") continue;
    ++count;
    try {
      const System s = ParseModelFile(entry.path());
      EXPECT_FALSE(s.components().empty()) << entry.path();
    } catch (const ParseError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(count, 1);
}

TEST(Parser, FingerModel) {
  const System s = ParseModelFile(kSourceDir / "spec" / "finger.ha");
  ASSERT_EQ(s.components().size(), 1u);
  const Automaton& a = s.components()[0].automaton;
  EXPECT_EQ(a.name(), "finger");
  EXPECT_EQ(s.components()[0].instance, "");
  EXPECT_EQ(a.num_modes(), 31);
  EXPECT_EQ(a.variables().size(), 6u);  // theta1..3, g, theta3_s, g_s
  EXPECT_EQ(a.discrete_variables().size(), 6u);
  EXPECT_EQ(a.inputs().size(), 1u);
  EXPECT_EQ(a.parameters().size(), 13u);
  EXPECT_EQ(a.initial_states().size(), 1u);
  EXPECT_EQ(a.mode(a.initial_states()[0].mode).name, "c000_l000");
  EXPECT_EQ(a.properties().size(), 13u);
  EXPECT_EQ(s.properties().size(), 13u);
  ASSERT_TRUE(s.scenario().has_value());
  EXPECT_EQ(s.scenario()->until, 530.0);
  const auto m1 = a.symbols().Find("m1");
  ASSERT_TRUE(m1);
  EXPECT_EQ(a.symbols()[*m1].unit, "deg/count");
  EXPECT_DOUBLE_EQ(a.ParameterEnvironment()[*m1], 70.0 / 140.0);
}

TEST(Parser, UnitsDomainsAndParameters) {
  const Automaton a = OnlyAutomaton(R"(
automaton arm {
  param lo [deg] = -10;
  param hi [deg] = 2 * 45;
  var theta [deg] in [lo, hi], omega [deg/s];
  input torque [N*m] in [-1.5, 1.5];
  mode free { theta' = omega; omega' = torque; }
  init free { theta in [lo, 0]; omega = 0; }
})");
  const SymbolTable& s = a.symbols();
  ASSERT_EQ(s.size(), 5);
  EXPECT_EQ(s[0], (Symbol{"lo", SymbolKind::kParameter, "deg"}));
  EXPECT_EQ(s[1], (Symbol{"hi", SymbolKind::kParameter, "deg"}));
  EXPECT_EQ(s[2], (Symbol{"theta", SymbolKind::kVariable, "deg"}));
  EXPECT_EQ(s[3], (Symbol{"omega", SymbolKind::kVariable, "deg/s"}));
  EXPECT_EQ(s[4], (Symbol{"torque", SymbolKind::kInput, "N*m"}));
  EXPECT_EQ(a.parameters()[1].second, C(2) * C(45));
  ASSERT_EQ(a.variables().size(), 2u);
  ASSERT_TRUE(a.variables()[0].domain.has_value());
  EXPECT_EQ(*a.variables()[0].domain, (Range{Sym(a, "lo"), Sym(a, "hi")}));
  EXPECT_FALSE(a.variables()[1].domain.has_value());
  EXPECT_EQ(a.inputs()[0].bounds, (Range{C(-1.5), C(1.5)}));
  EXPECT_EQ(a.ParameterEnvironment(), (std::vector<double>{-10, 90, 0, 0, 0}));
  const InitialState& init = a.initial_states()[0];
  ASSERT_EQ(init.values.size(), 2u);
  EXPECT_FALSE(init.values[0].is_point);
  EXPECT_EQ(init.values[0].range, (Range{Sym(a, "lo"), C(0)}));
  EXPECT_TRUE(init.values[1].is_point);
  EXPECT_EQ(init.values[1].range, (Range{C(0), C(0)}));
}

// `param NAME [unit] = VALUE in [LO, HI];`: the range is optional, its bounds read earlier
// parameters; the value stays the nominal one.
TEST(Parser, ParameterRanges) {
  const Automaton a = OnlyAutomaton(R"(
automaton gripper {
  param gmax [count] = 256;
  param gob1 [count] = 256 in [0, gmax];
  param k = 2 in [-1, 2 * gmax]; # no unit
  param plain = 3;
  param e = 1in[1,1];
  var g;
  mode m { g' = 1; }
  init m { g = 0; }
})");
  const int gmax = *a.symbols().Find("gmax"), gob1 = *a.symbols().Find("gob1");
  EXPECT_EQ(a.symbols()[gob1], (Symbol{"gob1", SymbolKind::kParameter, "count"}));
  EXPECT_EQ(a.parameters()[1].second, C(256));
  EXPECT_EQ(a.ParameterRange(gmax), std::nullopt);
  EXPECT_EQ(a.ParameterRange(gob1), (Range{C(0), Sym(a, "gmax")}));
  EXPECT_EQ(a.ParameterRange(*a.symbols().Find("k")), (Range{C(-1), C(2) * Sym(a, "gmax")}));
  EXPECT_EQ(a.ParameterRange(*a.symbols().Find("plain")), std::nullopt);
  EXPECT_EQ(a.ParameterRange(*a.symbols().Find("e")), (Range{C(1), C(1)}));
  EXPECT_EQ(a.ParameterEnvironment()[gob1], 256.0);
}

// Each bad range is reported at the offending token: the parameter for a range the value does
// not satisfy, the name read for a bound that reads a non-parameter.
TEST(ParseErrors, BadParameterRanges) {
  auto error = [](const std::string& declaration) {
    const ParseError e = ParseFailure("automaton a {\n  param gmax = 256;\n  var x;\n  " +
                                      declaration + "\n  mode m { }\n  init m { x = 0; }\n}\n");
    return std::to_string(e.line()) + ":" + std::to_string(e.column()) + ": " + e.message();
  };
  EXPECT_EQ(error("param gob1 = 2 in [3, 1];"), "4:9: empty range [3, 1] for parameter 'gob1'");
  EXPECT_EQ(error("param gob1 [count] = 300 in [0, gmax];"),
            "4:9: value 300 of parameter 'gob1' is outside its range [0, 256]");
  EXPECT_EQ(error("param gob1 = -1 in [0, gmax];"),
            "4:9: value -1 of parameter 'gob1' is outside its range [0, 256]");
  EXPECT_EQ(error("param gob1 = 1 in [0, x];"),
            "4:25: variable 'x' is not allowed here: a parameter value, domain, bound or initial "
            "value may read only parameters");
  EXPECT_EQ(error("param gob1 = 1 in [0, gob1];"), "4:25: undefined name 'gob1'");
  EXPECT_EQ(error("param gob1 = 1 in [0, 1 / 0];"), "4:9: range of 'gob1': '1 / 0' is not finite");
  EXPECT_EQ(error("param gob1 = 1 in [0, 2;"), "4:26: expected ']'");
  EXPECT_EQ(error("param gob1 = 1 in 0, 2;"), "4:21: expected a range '[lo, hi]'");
  EXPECT_EQ(error("param gob1 = 1 within [0, 2];"), "4:18: expected ';' or a range 'in [lo, hi]'");
}

TEST(Parser, ExpressionsFollowPrecedenceAndAssociativity) {
  const Automaton a = OnlyAutomaton(R"(
automaton e {
  var x, y;
  mode m {
    x' = -2 * x + sin(y) ^ 2 - x / y / 2;   # comment after a flow
    y' = -x ^ 2 ^ 3 + atan2(y, 1.5e1) - min(.5, 2.) + 1e+2;
  }
  init m { x = 0; y = 0; }
})");
  const Expression x = Sym(a, "x"), y = Sym(a, "y");
  const auto& flows = a.modes()[0].flows;
  ASSERT_EQ(flows.size(), 2u);
  EXPECT_EQ(flows[0].second,
            C(-2) * x + Expression::Binary(Op::kPow, Expression::Unary(Op::kSin, y), C(2)) -
                x / y / C(2));
  EXPECT_EQ(flows[1].second,
            -Expression::Binary(Op::kPow, x, Expression::Binary(Op::kPow, C(2), C(3))) +
                Expression::Binary(Op::kAtan2, y, C(15)) -
                Expression::Binary(Op::kMin, C(0.5), C(2)) + C(100));
}

TEST(Parser, DiscreteValuesAndSignedNumbers) {
  const Automaton a = OnlyAutomaton(R"(
automaton d {
  var x;
  discrete c, l;
  mode m (l = - # a comment between the sign and the digits
           3, c = +1) { x' = 1; }
  mode n (c = 0, l = 2e0) { }
  init m { x = 0; }
})");
  const int c = *a.symbols().Find("c"), l = *a.symbols().Find("l");
  EXPECT_EQ(a.symbols()[c].kind, SymbolKind::kDiscrete);
  EXPECT_EQ(a.modes()[0].discrete_values, (std::vector<std::pair<int, int>>{{c, 1}, {l, -3}}));
  EXPECT_EQ(a.modes()[1].discrete_values, (std::vector<std::pair<int, int>>{{c, 0}, {l, 2}}));
  EXPECT_TRUE(a.modes()[1].flows.empty());
}

TEST(Parser, TransitionsGuardsResetsLabelsAndUrgency) {
  const Automaton a = OnlyAutomaton(R"(
automaton t {
  var x, y;
  input u in [0, 1];
  mode m { x' = u; inv x <= 10 and y >= -1; }
  mode n { x' = -1; }
  transition m -> n { guard x >= 5 and u > 0.5; reset y := x + 1, x := 0; label hit; }
  transition m -> n { lazy; }
  transition back: n -> m { guard x <= 0; urgent; }
  transition m -> n { guard true; }
  init m { x = 0; y = 0; }
})");
  const Expression x = Sym(a, "x"), y = Sym(a, "y"), u = Sym(a, "u");
  EXPECT_EQ(a.modes()[0].invariant.comparisons,
            (std::vector<Comparison>{{x, Relation::kLessEqual, C(10)},
                                     {y, Relation::kGreaterEqual, C(-1)}}));
  ASSERT_EQ(a.num_transitions(), 4);
  const Transition& t0 = a.transitions()[0];
  EXPECT_EQ(t0.name, "m_to_n");
  EXPECT_EQ(t0.source, ModeId(0));
  EXPECT_EQ(t0.target, ModeId(1));
  EXPECT_EQ(t0.label, "hit");
  EXPECT_EQ(t0.urgency, Urgency::kUrgent);
  EXPECT_EQ(t0.guard.comparisons, (std::vector<Comparison>{{x, Relation::kGreaterEqual, C(5)},
                                                           {u, Relation::kGreater, C(0.5)}}));
  // Resets are sorted by slot whatever the order written.
  EXPECT_EQ(t0.resets, (std::vector<Reset>{{0, C(0)}, {1, x + C(1)}}));
  EXPECT_EQ(a.transitions()[1].name, "m_to_n_2");
  EXPECT_EQ(a.transitions()[1].urgency, Urgency::kLazy);
  EXPECT_TRUE(a.transitions()[1].guard.empty());
  EXPECT_EQ(a.transitions()[2].name, "back");
  EXPECT_EQ(a.transitions()[2].urgency, Urgency::kUrgent);
  EXPECT_EQ(a.transitions()[3].name, "m_to_n_3");
  EXPECT_TRUE(a.transitions()[3].guard.empty());
}

// A default name skips every name an earlier transition has, named or not, and whatever base
// it came from: `m_to_n_2` is the default name of `m -> n_2`, so the next `m -> n` is `m_to_n_3`.
// A later explicit name equal to an earlier default is a duplicate.
TEST(Parser, DefaultTransitionNamesSkipEveryEarlierName) {
  const Automaton a = OnlyAutomaton(R"(
automaton t {
  mode m { }
  mode n { }
  mode n_2 { }
  transition m -> n { }
  transition m -> n_2 { }
  transition m -> n { }
  transition m_to_n_5: m -> n { }
  transition m -> n { }
  transition m -> n { }
  transition m -> n_2 { }
  transition m -> n { }
  init m { }
})");
  std::vector<std::string> names;
  for (const Transition& t : a.transitions()) names.push_back(t.name);
  EXPECT_EQ(names, (std::vector<std::string>{"m_to_n", "m_to_n_2", "m_to_n_3", "m_to_n_5",
                                             "m_to_n_4", "m_to_n_6", "m_to_n_2_2", "m_to_n_7"}));
  const ParseError e = ParseFailure(R"(automaton t {
  mode m { }
  mode n { }
  transition m -> n { }
  transition m_to_n: m -> n { }
  init m { }
})");
  EXPECT_EQ(e.line(), 5);
  EXPECT_EQ(e.message(), "duplicate transition 'm_to_n'");
}

// `count` unnamed transitions; transition i goes from mode `source(i)` to mode `target(i)`, modes
// q0 .. q(modes - 1).
std::string UnnamedTransitions(int modes, int count, const std::function<int(int)>& source,
                               const std::function<int(int)>& target) {
  std::string text = "automaton many {\n";
  for (int i = 0; i < modes; ++i) text += "  mode q" + std::to_string(i) + " { }\n";
  for (int i = 0; i < count; ++i) {
    text += "  transition q" + std::to_string(source(i)) + " -> q" + std::to_string(target(i)) +
            " { }\n";
  }
  return text + "  init q0 { }\n}\n";
}

// 10^5 unnamed transitions between two modes are numbered 2, 3, ... in order (naming them used
// to scan every earlier transition for every number tried: cubic, hours for 10^5).
TEST(LargeInputs, HundredThousandUnnamedTransitionsBetweenTwoModes) {
  constexpr int kCount = 100000;
  const Automaton a = ParseAutomaton(UnnamedTransitions(
                                         2, kCount, [](int) { return 0; }, [](int) { return 1; }),
                                     "many.ha");
  ASSERT_EQ(a.num_transitions(), kCount);
  EXPECT_EQ(a.transitions()[0].name, "q0_to_q1");
  for (int i = 1; i < kCount; ++i) {
    ASSERT_EQ(a.transitions()[i].name, "q0_to_q1_" + std::to_string(i + 1)) << i;
  }
}

// 10^5 unnamed transitions, each between its own pair of 317 modes, keep their plain names
// (naming them used to scan every earlier transition: quadratic, about 16 s for 10^5).
TEST(LargeInputs, HundredThousandUnnamedTransitionsOverDistinctModePairs) {
  constexpr int kCount = 100000, kModes = 317;  // 317^2 > kCount
  const System s = ParseModel(
      UnnamedTransitions(
          kModes, kCount, [](int i) { return i / kModes; }, [](int i) { return i % kModes; }),
      "many.ha");
  ASSERT_EQ(s.components().size(), 1u);
  const Automaton& a = s.components()[0].source;
  ASSERT_EQ(a.num_transitions(), kCount);
  for (int i = 0; i < kCount; ++i) {
    ASSERT_EQ(a.transitions()[i].name,
              "q" + std::to_string(i / kModes) + "_to_q" + std::to_string(i % kModes))
        << i;
  }
}

// A variable, flow, reset and initial value apiece for 5000 variables: each is checked for
// repetition against a set, not against every earlier one.
TEST(LargeInputs, FiveThousandVariablesWithFlowsResetsAndInitialValues) {
  constexpr int kCount = 5000;
  std::string vars, flows, resets, values;
  for (int i = 0; i < kCount; ++i) {
    const std::string x = "x" + std::to_string(i);
    vars += (i == 0 ? "" : ", ") + x;
    flows += " " + x + "' = 1;";
    resets += (i == 0 ? "" : ", ") + x + " := 0";
    values += " " + x + " = 0;";
  }
  const Automaton a = ParseAutomaton("automaton wide {\n  var " + vars + ";\n  mode m {" + flows +
                                         " }\n  transition m -> m { reset " + resets +
                                         "; }\n  init m {" + values + " }\n}\n",
                                     "wide.ha");
  ASSERT_EQ(a.variables().size(), static_cast<size_t>(kCount));
  EXPECT_EQ(a.modes()[0].flows.size(), static_cast<size_t>(kCount));
  EXPECT_EQ(a.transitions()[0].resets.size(), static_cast<size_t>(kCount));
  EXPECT_EQ(a.initial_states()[0].values.size(), static_cast<size_t>(kCount));
  // A repetition is still found, at the repeated name.
  const ParseError e = ParseFailure("automaton w {\n  var " + vars + ";\n  mode m {" + flows +
                                    " x7' = 2; }\n  init m {" + values + " }\n}\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.message(), "second flow for 'x7' in mode 'm'");
}

// `label l1, l2;` puts labels in an automaton's alphabet without a transition; composed, such a
// label blocks the other components' transitions on it. The printer writes it back.
TEST(Parser, DeclaredLabelsJoinTheAlphabetAndBlockPartners) {
  const System s = ParseModel(R"(
automaton idle {
  mode m { }
  label go, stop;
  label go;
  init m { }
}
automaton mover {
  mode a { }
  mode b { }
  transition a -> b { label go; }
  init a { }
}
system both {
  share go;
  instance I = idle;
  instance M = mover;
}
)",
                              "test.ha");
  const Automaton& idle = s.components()[0].source;
  EXPECT_EQ(idle.declared_labels(), (std::set<std::string>{"go", "stop"}));
  EXPECT_EQ(ParseAutomaton(PrintAutomaton(idle), "printed.ha"), idle);
  EXPECT_EQ(s.Alphabet(0), (std::set<std::string>{"go", "I.stop"}));
  const std::vector<int> start = {0, 0};
  EXPECT_TRUE(s.StepsFrom(start).empty());
  const ParseError e = ParseFailure("automaton a {\n  mode m { }\n  label ;\n  init m { }\n}\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.column(), 9);
}

TEST(Parser, ScenarioSignals) {
  const System s = ParseModel(R"(
automaton sc {
  var x;
  input u in [-1, 1];
  input v in [0, 10];
  input w in [0, 1];
  mode m { x' = u + v + w; }
  init m { x = 0; }
  scenario {
    until 20;
    u = step(0: 1, 5: -1, 10: 0);
    v = linear(-1: 0, 2.5: 10);
    w = 0.25;
  }
})",
                              "sc.ha");
  ASSERT_TRUE(s.scenario().has_value());
  const Scenario& sc = *s.scenario();
  EXPECT_EQ(sc.until, 20.0);
  ASSERT_EQ(sc.inputs.size(), 3u);
  EXPECT_EQ(sc.inputs[0].slot, *s.symbols().Find("u"));
  EXPECT_EQ(sc.inputs[0].shape, InputSignal::Shape::kStep);
  EXPECT_EQ(sc.inputs[0].points,
            (std::vector<std::pair<double, double>>{{0, 1}, {5, -1}, {10, 0}}));
  EXPECT_EQ(sc.inputs[1].shape, InputSignal::Shape::kLinear);
  EXPECT_EQ(sc.inputs[1].points, (std::vector<std::pair<double, double>>{{-1, 0}, {2.5, 10}}));
  EXPECT_EQ(sc.inputs[2].points, (std::vector<std::pair<double, double>>{{0, 0.25}}));
  EXPECT_EQ(s.components()[0].source.scenario(), s.scenario());
}

TEST(Parser, Properties) {
  const Automaton a = OnlyAutomaton(R"(
automaton p {
  var x;
  discrete d;
  mode low (d = 0) { x' = 1; }
  mode high (d = 1) { x' = -1; }
  init low { x = 0; }
  property safe: always x >= 0 and x <= 10;
  property never_high_and_big: never in high and x > 5 or d == 2 within 100;
  property reaches: reach not (in low) and (x > 1 or false);
})");
  const Expression x = Sym(a, "x"), d = Sym(a, "d");
  ASSERT_EQ(a.properties().size(), 3u);
  const Property& p0 = a.properties()[0];
  EXPECT_EQ(p0.name, "safe");
  EXPECT_EQ(p0.kind, Property::Kind::kAlways);
  EXPECT_FALSE(p0.horizon.has_value());
  EXPECT_EQ(p0.predicate, Predicate::And(Predicate::Compare({x, Relation::kGreaterEqual, C(0)}),
                                         Predicate::Compare({x, Relation::kLessEqual, C(10)})));
  const Property& p1 = a.properties()[1];
  EXPECT_EQ(p1.kind, Property::Kind::kNever);
  EXPECT_EQ(p1.horizon, 100.0);
  // `and` binds tighter than `or`.
  EXPECT_EQ(p1.predicate,
            Predicate::Or(Predicate::And(Predicate::InMode("high"),
                                         Predicate::Compare({x, Relation::kGreater, C(5)})),
                          Predicate::Compare({d, Relation::kEqual, C(2)})));
  const Property& p2 = a.properties()[2];
  EXPECT_EQ(p2.kind, Property::Kind::kReach);
  EXPECT_EQ(p2.predicate,
            Predicate::And(Predicate::Not(Predicate::InMode("low")),
                           Predicate::Or(Predicate::Compare({x, Relation::kGreater, C(1)}),
                                         Predicate::False())));
}

// `property p: ...` with a body that names an unknown variable or mode, reads an input or is
// not a predicate: the message says which, at the offending token.
TEST(ParseErrors, BadPropertyBodies) {
  auto error = [](const std::string& property) {
    const ParseError e = ParseFailure(
        "automaton a {\n  var theta1;\n  input u in [0, 1];\n  mode m { theta1' = u; }\n"
        "  init m { theta1 = 0; }\n  property p: " +
        property + ";\n}\n");
    return std::to_string(e.line()) + ":" + std::to_string(e.column()) + ": " + e.message();
  };
  EXPECT_EQ(error("always x_unknown >= 0"), "6:22: undefined name 'x_unknown'");
  EXPECT_EQ(error("reach in no_such_mode"), "6:24: unknown mode 'no_such_mode'");
  EXPECT_EQ(error("always u >= 0"),
            "6:22: input 'u' is not allowed here: a property may not read inputs");
  const std::string not_a_predicate =
      "' is not a predicate (expected a comparison such as x >= 0, 'in MODE', true or false)";
  EXPECT_EQ(error("always theta1 + 1"), "6:22: property 'p': 'theta1 + 1" + not_a_predicate);
  EXPECT_EQ(error("always theta1"), "6:22: property 'p': 'theta1" + not_a_predicate);
  EXPECT_EQ(error("never sin(theta1) within 5"),
            "6:21: property 'p': 'sin(theta1)" + not_a_predicate);
  EXPECT_EQ(error("always theta1 >= 0 and theta1 * 2"),
            "6:38: property 'p': 'theta1 * 2" + not_a_predicate);
  EXPECT_EQ(error("reach in m or 1"), "6:29: property 'p': '1" + not_a_predicate);
  EXPECT_EQ(error("always not (theta1)"), "6:27: property 'p': 'theta1" + not_a_predicate);
  EXPECT_EQ(error("always theta1 = 1"), "6:29: '=' is not a comparison: write '==' for equality");
  EXPECT_EQ(error("always"), "6:21: expected a predicate");
  EXPECT_EQ(error("always theta1 >= 0 and"), "6:37: expected a predicate");
}

// Expressions in parentheses still start comparisons: only a whole operand that is an
// expression is an error.
TEST(Parser, ParenthesesInPropertiesGroupExpressionsOrPredicates) {
  const Automaton a = OnlyAutomaton(R"(
automaton a {
  var x;
  mode m { x' = 1; }
  init m { x = 0; }
  property p: always (x + 1) >= 0 and ((x)) * 2 <= 4 or (x >= 1 and (in m));
  property q: never -(x) > 3 or not (x) == 2;
})");
  const Expression x = Sym(a, "x");
  EXPECT_EQ(
      a.properties()[0].predicate,
      Predicate::Or(Predicate::And(Predicate::Compare({x + C(1), Relation::kGreaterEqual, C(0)}),
                                   Predicate::Compare({x * C(2), Relation::kLessEqual, C(4)})),
                    Predicate::And(Predicate::Compare({x, Relation::kGreaterEqual, C(1)}),
                                   Predicate::InMode("m"))));
  EXPECT_EQ(a.properties()[1].predicate,
            Predicate::Or(Predicate::Compare({-x, Relation::kGreater, C(3)}),
                          Predicate::Not(Predicate::Compare({x, Relation::kEqual, C(2)}))));
}

// The same for properties of a system: names and modes are qualified by the instance.
TEST(ParseErrors, BadSystemPropertyBodies) {
  auto error = [](const std::string& property) {
    const ParseError e = ParseFailure(
        "automaton a {\n  var theta1;\n  input u in [0, 1];\n  mode m { theta1' = u; }\n"
        "  init m { theta1 = 0; }\n}\nsystem s {\n  instance A = a;\n  property p: " +
        property + ";\n}\n");
    return std::to_string(e.line()) + ":" + std::to_string(e.column()) + ": " + e.message();
  };
  EXPECT_EQ(error("always A.nope >= 0"), "9:22: undefined name 'A.nope'");
  EXPECT_EQ(error("always theta1 >= 0"), "9:22: undefined name 'theta1'");
  EXPECT_EQ(error("reach in A.nope"), "9:24: unknown mode 'A.nope'");
  EXPECT_EQ(error("reach in m"), "9:24: unknown mode 'm'");
  EXPECT_EQ(error("always A.u <= 1"),
            "9:22: input 'A.u' is not allowed here: a property may not read inputs");
  EXPECT_EQ(error("always A.theta1 + 1"),
            "9:22: property 'p': 'A.theta1 + 1' is not a predicate (expected a comparison such as "
            "x >= 0, 'in MODE', true or false)");
}

TEST(Parser, SystemWithInstancesAndShare) {
  const System s = ParseModel(R"(
automaton tank {
  param k = 2;
  var level, flow;
  input valve in [0, 1];
  mode filling { level' = k * valve - flow; }
  mode full { }
  transition filling -> full { guard level >= 10; label stop; }
  init filling { level = 0; flow = 1; }
}

system plant {
  share flow, valve, stop;
  instance A = tank;
  instance B = tank;
  property both_full: reach in A.full and in B.full;
  property low: always A.level <= 10;
  scenario { until 5; valve = 1; }
}
)",
                              "plant.ha");
  EXPECT_EQ(s.name(), "plant");
  EXPECT_EQ(s.shared(), (std::set<std::string>{"flow", "stop", "valve"}));
  ASSERT_EQ(s.components().size(), 2u);
  EXPECT_EQ(s.components()[0].instance, "A");
  EXPECT_EQ(s.components()[1].instance, "B");
  std::vector<std::string> names;
  for (int i = 0; i < s.symbols().size(); ++i) names.push_back(s.symbols()[i].name);
  EXPECT_EQ(names, (std::vector<std::string>{"A.k", "A.level", "flow", "valve", "B.k", "B.level"}));
  EXPECT_EQ(s.components()[0].global_slot, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(s.components()[1].global_slot, (std::vector<int>{4, 5, 2, 3}));
  // The shared label keeps its name; the source automaton is kept as declared.
  EXPECT_EQ(s.components()[1].automaton.transitions()[0].label, "stop");
  EXPECT_EQ(s.components()[1].source.symbols()[1].name, "level");
  EXPECT_EQ(s.QualifiedModeName(1, ModeId(1)), "B.full");
  ASSERT_EQ(s.properties().size(), 2u);
  EXPECT_EQ(s.properties()[0].predicate,
            Predicate::And(Predicate::InMode("A.full"), Predicate::InMode("B.full")));
  EXPECT_EQ(s.properties()[1].predicate,
            Predicate::Compare({Expression::Symbol("A.level", 1), Relation::kLessEqual, C(10)}));
  ASSERT_TRUE(s.scenario().has_value());
  EXPECT_EQ(s.scenario()->inputs[0].slot, 3);
}

TEST(Parser, InstanceWithoutAliasIsUnqualified) {
  const System s = ParseModel(std::string(kSmallModel) + "system s { instance a; }\n", "t.ha");
  ASSERT_EQ(s.components().size(), 1u);
  EXPECT_EQ(s.components()[0].instance, "");
  EXPECT_EQ(s.symbols()[0].name, "x");
}

TEST(Parser, Imports) {
  TempDir dir;
  fs::create_directories(dir.path() / "lib");
  dir.Write("lib/base.ha", "automaton base { var x; mode m { x' = 1; } init m { x = 0; } }\n");
  // Two files import base.ha: the diamond brings the same automaton twice, which is fine.
  dir.Write(
      "lib/left.ha",
      "import \"base.ha\";\nautomaton left { var y; mode m { y' = 1; } init m { y = 0; } }\n");
  dir.Write("lib/right.ha", "import \"base.ha\";\n");
  const fs::path main = dir.Write("main.ha", R"(# Imports are relative to the importing file.
import "lib/left.ha";
import "lib/right.ha";
system s {
  instance B = base;
  instance L = left;
}
)");
  const System s = ParseModelFile(main);
  ASSERT_EQ(s.components().size(), 2u);
  EXPECT_EQ(s.components()[0].source.name(), "base");
  EXPECT_EQ(s.components()[1].source.name(), "left");
  EXPECT_EQ(s.symbols()[0].name, "B.x");
  EXPECT_EQ(s.symbols()[1].name, "L.y");
}

TEST(Parser, ImportThatRedefinesAnAutomatonIsAnError) {
  TempDir dir;
  dir.Write("one.ha", "automaton a { var x; mode m { x' = 1; } init m { x = 0; } }\n");
  dir.Write("two.ha", "automaton a { var x; mode m { x' = 2; } init m { x = 0; } }\n");
  const fs::path main = dir.Write("main.ha", "import \"one.ha\";\nimport \"two.ha\";\n");
  try {
    ParseModelFile(main);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), main.string());
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.column(), 1);
    EXPECT_EQ(e.message(), "import redefines automaton 'a'");
  }
}

TEST(Parser, FileWithOnlyAnImportedAutomatonDeclaresNothing) {
  TempDir dir;
  dir.Write("lib.ha", kSmallModel);
  const fs::path main = dir.Write("main.ha", "import \"lib.ha\";\n");
  try {
    ParseModelFile(main);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.message(), "the file declares no automaton and no system");
  }
}

TEST(Parser, CommentsAndWhitespaceAnywhere) {
  const Automaton a = OnlyAutomaton(
      "#c\n\tautomaton#c\n a #c\n{ var #c\n x\r\n;mode m{x'#c\n=#c\n1#c\n;}init m{x=0;}}#end");
  EXPECT_EQ(a.num_modes(), 1);
  EXPECT_EQ(a.modes()[0].flows[0].second, C(1));
}

TEST(Parser, ErrorLocationsCountBytesAndLines) {
  // A tab is one column; CRLF ends a line.
  const ParseError e = ParseFailure("automaton a {\r\n\tvar x;\r\n\tmode m { x' = q; }\r\n}\r\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.column(), 16);
  EXPECT_EQ(e.message(), "undefined name 'q'");
}

}  // namespace
}  // namespace hybrid
