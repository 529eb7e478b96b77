// Tests of measured data (include/hybrid/gripper/measured_data.h): reading the CSV of runs
// (comments, blank lines, CRLF, missing samples, optional columns, any column order) and every
// error it reports with its line and column; the report's outlier rule (spikes clamped, ramps and
// genuine steps kept, missing samples skipped); the noise floor from repeated runs and from second
// differences on synthetic data with known noise.

#include "hybrid/gripper/measured_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "tests/test_utilities/command_line.h"

namespace hybrid {
namespace {

using testing::TempDir;  // hybrid::testing, tests/test_utilities/command_line.h

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------
// Helpers.

constexpr std::string_view kHeader = "run,g,theta1,theta2,theta3\n";
constexpr std::string_view kContactHeader = "run,g,theta1,theta2,theta3,gob,contact_link\n";

MeasuredData Read(const std::string& text) {
  std::istringstream in(text);
  return ReadMeasuredData(in, "data.csv");
}

// `n` rows of run `label`: "label,i,10,20,30" (g = i = 0, 1, ...), each followed by `suffix`.
std::string Rows(std::string_view label, int n, std::string_view suffix = "") {
  std::string out;
  for (int i = 0; i < n; ++i) {
    out += std::string(label) + "," + std::to_string(i) + ",10,20,30" + std::string(suffix) + "\n";
  }
  return out;
}

// A file of run "1" whose fifth line is `row` (lines 2-4 and 6-15 are valid rows).
std::string WithRow(std::string_view row) {
  return std::string(kHeader) + Rows("1", 3) + std::string(row) + "\n" + Rows("1", 10);
}

// The same with the optional columns, the valid rows of a contact run (gob 100, link 1).
std::string WithContactRow(std::string_view row) {
  return std::string(kContactHeader) + Rows("1", 3, ",100,1") + std::string(row) + "\n" +
         Rows("1", 10, ",100,1");
}

// Whether reading `text` throws a DataError at `line`:`column` whose message contains
// `fragment`, with what() = "data.csv:LINE:COLUMN: message".
::testing::AssertionResult FailsAt(const std::string& text, int line, int column,
                                   std::string_view fragment) {
  try {
    Read(text);
  } catch (const DataError& e) {
    const std::string what = e.what();
    const std::string prefix =
        "data.csv:" + std::to_string(line) + ":" + std::to_string(column) + ": ";
    if (e.line() != line || e.column() != column || what.find(fragment) == std::string::npos ||
        what != prefix + e.message() || e.source() != "data.csv") {
      return ::testing::AssertionFailure()
             << "got '" << what << "' (line " << e.line() << ", column " << e.column()
             << "), expected " << line << ":" << column << " with '" << fragment << "'";
    }
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no error; expected '" << fragment << "'";
}

// ---------------------------------------------------------------------------------------------
// Reading valid files.

TEST(ReadMeasuredData, ReadsAMinimalFile) {
  const MeasuredData data = Read(std::string(kHeader) + Rows("1", 10));
  EXPECT_EQ(data.source, "data.csv");
  ASSERT_EQ(data.runs.size(), 1u);
  const MeasuredRun& run = data.runs[0];
  EXPECT_EQ(run.label, "1");
  ASSERT_EQ(run.g.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(run.g[i], i);
    EXPECT_EQ(run.theta[0][i], 10.0);
    EXPECT_EQ(run.theta[1][i], 20.0);
    EXPECT_EQ(run.theta[2][i], 30.0);
    EXPECT_EQ(run.lines[i], i + 2);
  }
  EXPECT_FALSE(run.gob.has_value());
  EXPECT_FALSE(run.contact_link.has_value());
  EXPECT_EQ(data.samples(), 10);
}

TEST(ReadMeasuredData, SkipsCommentsAndBlankLinesAndAcceptsCrlfAndSpaces) {
  std::string text =
      "# gripper, 2026-01-10\r\n"              // 1
      "\r\n"                                   // 2
      " run , g ,theta1,\ttheta2 ,theta3\r\n"  // 3: the header
      "   # a comment after blanks\r\n";       // 4
  for (int i = 0; i < 10; ++i) {               // 5..14, with a blank line after the fifth row
    text += "  a , " + std::to_string(2 * i) + " , 1.5 ,\t-2 , 3e1 \r\n";
    if (i == 4) text += "  \t \r\n";
  }
  const MeasuredData data = Read(text);
  ASSERT_EQ(data.runs.size(), 1u);
  const MeasuredRun& run = data.runs[0];
  EXPECT_EQ(run.label, "a");
  EXPECT_EQ(run.lines, (std::vector<int>{5, 6, 7, 8, 9, 11, 12, 13, 14, 15}));
  EXPECT_EQ(run.g[9], 18.0);
  EXPECT_EQ(run.theta[0][3], 1.5);
  EXPECT_EQ(run.theta[1][3], -2.0);
  EXPECT_EQ(run.theta[2][3], 30.0);
}

TEST(ReadMeasuredData, SkipsAByteOrderMark) {
  const MeasuredData data = Read("\xEF\xBB\xBF" + std::string(kHeader) + Rows("1", 10));
  ASSERT_EQ(data.runs.size(), 1u);
  EXPECT_EQ(data.runs[0].lines.front(), 2);
}

TEST(ReadMeasuredData, EmptyAngleCellsAreMissingSamples) {
  const MeasuredData data = Read(std::string(kHeader) + Rows("1", 3) +
                                 "1,3,,20,30\n"  // 5
                                 "1,4,10, ,\n"   // 6
                                 "1,5,,,\n" +    // 7
                                 Rows("1", 4));
  const MeasuredRun& run = data.runs.at(0);
  ASSERT_EQ(run.g.size(), 10u);
  EXPECT_TRUE(std::isnan(run.theta[0][3]));
  EXPECT_EQ(run.theta[1][3], 20.0);
  EXPECT_EQ(run.theta[0][4], 10.0);
  EXPECT_TRUE(std::isnan(run.theta[1][4]));
  EXPECT_TRUE(std::isnan(run.theta[2][4]));
  for (int j = 0; j < 3; ++j) EXPECT_TRUE(std::isnan(run.theta[j][5]));
  EXPECT_EQ(run.g[5], 5.0);
  EXPECT_EQ(run.lines[5], 7);
}

TEST(ReadMeasuredData, AcceptsNumberForms) {
  const MeasuredData data = Read(std::string(kHeader) + Rows("1", 5) +
                                 "1,0,1.5e1,-0.25,.5\n"
                                 "1,255,5.,-0,1E-3\n"
                                 "1,254.5,0,0,0\n" +
                                 Rows("1", 2));
  const MeasuredRun& run = data.runs.at(0);
  EXPECT_EQ(run.theta[0][5], 15.0);
  EXPECT_EQ(run.theta[1][5], -0.25);
  EXPECT_EQ(run.theta[2][5], 0.5);
  EXPECT_EQ(run.g[6], 255.0);
  EXPECT_EQ(run.theta[0][6], 5.0);
  EXPECT_EQ(run.theta[2][6], 1e-3);
  EXPECT_EQ(run.g[7], 254.5);
}

// One sign is a sign, here as in every option of the command line ("+5" was refused by the
// data reader while `--input-csv` and `--set` read it).
TEST(ReadMeasuredData, AcceptsALeadingPlus) {
  const MeasuredData data =
      Read(std::string(kHeader) + Rows("1", 5) + "1,+7,+1.5e+1,-2,+.5\n" + Rows("1", 4));
  const MeasuredRun& run = data.runs.at(0);
  EXPECT_EQ(run.g[5], 7.0);
  EXPECT_EQ(run.theta[0][5], 15.0);
  EXPECT_EQ(run.theta[1][5], -2.0);
  EXPECT_EQ(run.theta[2][5], 0.5);
}

TEST(ReadMeasuredData, ColumnOrderDoesNotMatter) {
  std::string reordered = "theta3,g,contact_link,run,theta1,gob,theta2\n";
  std::string ordered(kContactHeader);
  for (int i = 0; i < 10; ++i) {
    const std::string g = std::to_string(10 + i), t1 = std::to_string(i), t2 = "-" + t1,
                      t3 = std::to_string(3 * i);
    reordered += t3 + "," + g + ",2,r," + t1 + ",120.5," + t2 + "\n";
    ordered += "r," + g + "," + t1 + "," + t2 + "," + t3 + ",120.5,2\n";
  }
  const MeasuredData a = Read(reordered);
  const MeasuredData b = Read(ordered);
  ASSERT_EQ(a.runs.size(), 1u);
  ASSERT_EQ(b.runs.size(), 1u);
  EXPECT_EQ(a.runs[0].label, b.runs[0].label);
  EXPECT_EQ(a.runs[0].g, b.runs[0].g);
  EXPECT_EQ(a.runs[0].theta, b.runs[0].theta);
  EXPECT_EQ(a.runs[0].gob, b.runs[0].gob);
  EXPECT_EQ(a.runs[0].contact_link, b.runs[0].contact_link);
  EXPECT_EQ(a.runs[0].lines, b.runs[0].lines);
  EXPECT_EQ(a.runs[0].gob, 120.5);
  EXPECT_EQ(a.runs[0].contact_link, 2);
  EXPECT_EQ(a.runs[0].theta[1][3], -3.0);
}

TEST(ReadMeasuredData, ReadsSeveralRunsWithOptionalColumns) {
  const MeasuredData data = Read(std::string(kContactHeader) + Rows("free_a", 10, ",,") +
                                 Rows("2", 12, ",100,1") + Rows("3", 11, ", 80 , 2 "));
  ASSERT_EQ(data.runs.size(), 3u);
  EXPECT_EQ(data.runs[0].label, "free_a");
  EXPECT_FALSE(data.runs[0].gob.has_value());
  EXPECT_FALSE(data.runs[0].contact_link.has_value());
  EXPECT_EQ(data.runs[1].label, "2");
  EXPECT_EQ(data.runs[1].gob, 100.0);
  EXPECT_EQ(data.runs[1].contact_link, 1);
  EXPECT_EQ(data.runs[1].lines.front(), 12);
  EXPECT_EQ(data.runs[2].gob, 80.0);
  EXPECT_EQ(data.runs[2].contact_link, 2);
  EXPECT_EQ(data.runs[2].g.size(), 11u);
  EXPECT_EQ(data.samples(), 33);
}

// The optional `position` column: the motor position the gripper reports, one per sample (NaN
// where empty); absent, the run has no positions.
TEST(ReadMeasuredData, ReadsTheReportedMotorPosition) {
  std::string text = "run,g,position,theta1,theta2,theta3\n";
  for (int i = 0; i < 12; ++i) {
    const int request = 230 + 2 * i;  // past the palm stop at 240: the motor stays there
    const std::string position = i == 5 ? "" : std::to_string(std::min(request, 240));
    text += "1," + std::to_string(request) + "," + position + ",70,90,-55\n";
  }
  const MeasuredData data = Read(text);
  const MeasuredRun& run = data.runs.at(0);
  ASSERT_EQ(run.position.size(), 12u);
  EXPECT_EQ(run.position[0], 230.0);
  EXPECT_EQ(run.position[11], 240.0);
  EXPECT_EQ(run.g[11], 252.0);
  EXPECT_TRUE(std::isnan(run.position[5]));
  EXPECT_TRUE(Read(std::string(kHeader) + Rows("1", 10)).runs[0].position.empty());
}

TEST(ReadMeasuredDataErrors, PositionPastTheRequestOrOutOfRange) {
  const std::string header = "run,g,theta1,theta2,theta3,position\n";
  const std::string rows = Rows("1", 3, ",0") + "1,100,10,20,30,%\n" + Rows("1", 10, ",0");
  auto with = [&](const std::string& position) {
    std::string text = header + rows;
    text.replace(text.find('%'), 1, position);
    return text;
  };
  // Half a count of rounding is allowed; more is a motor ahead of its request.
  EXPECT_NO_THROW(Read(with("100.5")));
  EXPECT_TRUE(
      FailsAt(with("101"), 5, 6, "column 'position': the motor (101) is past the request g = 100"));
  EXPECT_TRUE(FailsAt(with("256"), 5, 6, "column 'position': outside [0, 255]"));
  EXPECT_TRUE(FailsAt(with("-1"), 5, 6, "column 'position': outside [0, 255]"));
  EXPECT_TRUE(FailsAt(with("x"), 5, 6, "column 'position': not a number"));
}

TEST(ReadMeasuredDataErrors, RequestOutsideTheMotorRange) {
  EXPECT_TRUE(FailsAt(WithRow("1,255.5,10,20,30"), 5, 2, "column 'g': outside [0, 255]"));
  EXPECT_TRUE(FailsAt(WithRow("1,-2,10,20,30"), 5, 2, "column 'g': outside [0, 255]"));
}

TEST(ReadMeasuredDataFile, ReadsAFile) {
  TempDir dir;
  const std::string path = dir.Write("runs.csv", std::string(kHeader) + Rows("1", 10)).string();
  const MeasuredData data = ReadMeasuredDataFile(path);
  EXPECT_EQ(data.source, path);
  EXPECT_EQ(data.samples(), 10);
}

TEST(ReadMeasuredDataFile, MissingFileIsAnErrorAtLineZero) {
  TempDir dir;
  const std::string path = dir.File("no_such.csv");
  try {
    ReadMeasuredDataFile(path);
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.source(), path);
    EXPECT_EQ(std::string(e.what()).rfind(path + ":0:0: cannot open the file", 0), 0u) << e.what();
  }
}

TEST(ReadMeasuredDataFile, DirectoryIsAnError) {
  TempDir dir;
  try {
    ReadMeasuredDataFile(dir.path().string());
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.column(), 0);
    EXPECT_EQ(e.message(), "is a directory");
  }
}

// ---------------------------------------------------------------------------------------------
// Errors in the file and the header.

TEST(ReadMeasuredDataErrors, EmptyFile) { EXPECT_TRUE(FailsAt("", 0, 0, "empty file: no header")); }

TEST(ReadMeasuredDataErrors, OnlyCommentsAndBlankLines) {
  EXPECT_TRUE(FailsAt("# nothing\n\n  \n", 0, 0, "no header"));
}

TEST(ReadMeasuredDataErrors, HeaderWithoutRows) {
  EXPECT_TRUE(FailsAt("# c\n" + std::string(kHeader) + "# more\n", 2, 0, "no data rows"));
}

TEST(ReadMeasuredDataErrors, MissingRequiredColumnNamesIt) {
  EXPECT_TRUE(FailsAt("#c\nrun,g,theta1,theta3\n1,0,1,3\n", 2, 0, "missing column 'theta2'"));
  EXPECT_TRUE(FailsAt("g,theta1,theta2,theta3\n", 1, 0, "missing column 'run'"));
}

TEST(ReadMeasuredDataErrors, DuplicateColumn) {
  EXPECT_TRUE(
      FailsAt("run,g,theta1,theta2,theta3,g\n", 1, 6, "duplicate column 'g' (also column 2)"));
}

TEST(ReadMeasuredDataErrors, UnknownColumnIsNamed) {
  EXPECT_TRUE(FailsAt("run,g,theta1,theta2,thetaa\n", 1, 5, "unknown column 'thetaa'"));
  EXPECT_TRUE(
      FailsAt("run,g,theta1,theta2,theta3,temperature\n", 1, 6, "unknown column 'temperature'"));
  EXPECT_TRUE(FailsAt("run,G,theta1,theta2,theta3\n", 1, 2, "unknown column 'G'"));
  EXPECT_TRUE(FailsAt("run,g,theta1,theta2,theta3,motor\n", 1, 6,
                      "(the columns are run, g, theta1, theta2, theta3, gob, contact_link, "
                      "position)"));
}

TEST(ReadMeasuredDataErrors, EmptyColumnName) {
  EXPECT_TRUE(FailsAt("run,g,theta1,theta2,theta3,\n", 1, 6, "empty column name"));
}

TEST(ReadMeasuredDataErrors, QuotesInTheHeader) {
  EXPECT_TRUE(FailsAt("run,\"g\",theta1,theta2,theta3\n", 1, 2, "quotes are not supported"));
}

TEST(ReadMeasuredDataErrors, GobAndContactLinkComeTogether) {
  EXPECT_TRUE(FailsAt("run,g,gob,theta1,theta2,theta3\n", 1, 3,
                      "column 'gob' requires column 'contact_link'"));
  EXPECT_TRUE(FailsAt("contact_link,run,g,theta1,theta2,theta3\n", 1, 1,
                      "column 'contact_link' requires column 'gob'"));
}

// ---------------------------------------------------------------------------------------------
// Errors in rows.

TEST(ReadMeasuredDataErrors, TooFewOrTooManyCells) {
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,20"), 5, 0, "too few cells: 4 where the header has 5"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,20,30,"), 5, 0, "too many cells: 6 where the header has 5"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,20,30,40"), 5, 0, "too many cells"));
}

TEST(ReadMeasuredDataErrors, NotANumberQuotesTheCell) {
  EXPECT_TRUE(FailsAt(WithRow("1,3,abc,20,30"), 5, 3, "column 'theta1': not a number: 'abc'"));
  EXPECT_TRUE(FailsAt(WithRow("1, x ,10,20,30"), 5, 2, "column 'g': not a number: 'x'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,20,12abc"), 5, 5, "column 'theta3': not a number: '12abc'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,0x10,30"), 5, 4, "not a number: '0x10'"));
  // The decimal syntax of the command line (automaton/number_syntax.h): one sign at most.
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,+-5,30"), 5, 4, "not a number: '+-5'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,--5,30"), 5, 4, "not a number: '--5'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,0x1p3,30"), 5, 4, "not a number: '0x1p3'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,1e,30"), 5, 4, "not a number: '1e'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,.,30"), 5, 4, "not a number: '.'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,2 0,30"), 5, 4, "not a number: '2 0'"));
  EXPECT_TRUE(
      FailsAt(WithContactRow("1,3,10,20,30,1OO,1"), 5, 6, "column 'gob': not a number: '1OO'"));
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,100,one"), 5, 7,
                      "column 'contact_link': not a number: 'one'"));
}

TEST(ReadMeasuredDataErrors, NonFiniteValues) {
  for (const std::string cell : {"nan", "NaN", "inf", "-inf", "infinity", "-NAN"}) {
    SCOPED_TRACE(cell);
    EXPECT_TRUE(
        FailsAt(WithRow("1,3,10,20," + cell), 5, 5, "column 'theta3': not finite: '" + cell + "'"));
    EXPECT_TRUE(FailsAt(WithRow("1," + cell + ",10,20,30"), 5, 2, "column 'g': not finite"));
  }
  EXPECT_TRUE(FailsAt(WithRow("1,3,1e999,20,30"), 5, 3, "not finite (out of the range"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,1e-999,20,30"), 5, 3, "too small for a double: '1e-999'"));
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,inf,1"), 5, 6, "column 'gob': not finite"));
}

TEST(ReadMeasuredDataErrors, GOutsideItsRange) {
  EXPECT_TRUE(FailsAt(WithRow("1,-1,10,20,30"), 5, 2, "column 'g': outside [0, 255]: '-1'"));
  EXPECT_TRUE(FailsAt(WithRow("1,255.5,10,20,30"), 5, 2, "outside [0, 255]: '255.5'"));
  EXPECT_TRUE(FailsAt(WithRow("1,1e3,10,20,30"), 5, 2, "outside [0, 255]: '1e3'"));
}

// An angle of 1e308 degrees was read, and its square overflowed the noise estimate to NaN (a
// finding of fuzz_measured_data). Angles are at most one turn either way.
TEST(ReadMeasuredDataErrors, AngleOutsideOneTurn) {
  EXPECT_TRUE(FailsAt(WithRow("1,3,1e308,20,30"), 5, 3,
                      "column 'theta1': outside [-360, 360] degrees: '1e308'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,-360.5,30"), 5, 4, "outside [-360, 360] degrees: '-360.5'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,10,20,361"), 5, 5, "outside [-360, 360] degrees: '361'"));
}

TEST(ReadMeasuredDataErrors, EmptyGOrRun) {
  EXPECT_TRUE(FailsAt(WithRow("1, ,10,20,30"), 5, 2, "column 'g': empty"));
  EXPECT_TRUE(FailsAt(WithRow(",3,10,20,30"), 5, 1, "column 'run': empty run label"));
}

TEST(ReadMeasuredDataErrors, QuotesInACell) {
  EXPECT_TRUE(FailsAt(WithRow("\"1\",3,10,20,30"), 5, 1,
                      "column 'run': quotes are not supported: '\"1\"'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,\"10\",20,30"), 5, 3, "quotes are not supported"));
}

TEST(ReadMeasuredDataErrors, GobOutsideItsRange) {
  EXPECT_TRUE(
      FailsAt(WithContactRow("1,3,10,20,30,256,1"), 5, 6, "column 'gob': outside [0, 255]: '256'"));
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,-0.5,1"), 5, 6, "outside [0, 255]"));
}

TEST(ReadMeasuredDataErrors, ContactLinkIsOneOrTwo) {
  for (const std::string cell : {"0", "3", "1.5", "-1"}) {
    SCOPED_TRACE(cell);
    EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,100," + cell), 5, 7,
                        "column 'contact_link': not 1 or 2: '" + cell + "'"));
  }
}

TEST(ReadMeasuredDataErrors, GobAndContactLinkBothOrNeither) {
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,100,"), 5, 7,
                      "column 'contact_link': empty while 'gob' is given"));
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,,2"), 5, 6,
                      "column 'gob': empty while 'contact_link' is given"));
  // Also on a run's first row.
  EXPECT_TRUE(FailsAt(std::string(kContactHeader) + "1,3,10,20,30,,2\n" + Rows("1", 10, ",,2"), 2,
                      6, "column 'gob': empty while"));
}

TEST(ReadMeasuredDataErrors, GobAndContactLinkAreConstantWithinARun) {
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,101,1"), 5, 6,
                      "column 'gob': 101 differs from 100 on the run's first row (line 2)"));
  EXPECT_TRUE(FailsAt(WithContactRow("1,3,10,20,30,100,2"), 5, 7,
                      "column 'contact_link': 2 differs from 1 on the run's first row (line 2)"));
  EXPECT_TRUE(
      FailsAt(WithContactRow("1,3,10,20,30,,"), 5, 6, "column 'gob': empty differs from 100"));
  // A free-space run that later names a contact.
  EXPECT_TRUE(FailsAt(std::string(kContactHeader) + Rows("1", 3, ",,") + "1,3,10,20,30,90,1\n" +
                          Rows("1", 10, ",,"),
                      5, 6, "column 'gob': 90 differs from empty"));
}

TEST(ReadMeasuredDataErrors, ShortRunPointsAtItsFirstRow) {
  // Run "a" (lines 3-11, 9 rows) ends when run "b" starts.
  EXPECT_TRUE(FailsAt("#\n" + std::string(kHeader) + Rows("a", 9) + Rows("b", 10), 3, 1,
                      "run 'a' has 9 samples; a run needs at least 10"));
  // The last run; here `run` is the third column.
  EXPECT_TRUE(
      FailsAt("g,theta1,run,theta2,theta3\n"
              "0,1,a,2,3\n"
              "1,1,b,2,3\n",
              2, 3, "run 'a' has 1 sample;"));
  EXPECT_TRUE(
      FailsAt(std::string(kHeader) + Rows("a", 10) + Rows("b", 4), 12, 1, "run 'b' has 4 samples"));
}

TEST(ReadMeasuredDataErrors, RunLabelReusedAfterAnotherRun) {
  // a: lines 2-11, b: lines 12-21, a again at line 22.
  EXPECT_TRUE(FailsAt(std::string(kHeader) + Rows("a", 10) + Rows("b", 10) + Rows("a", 10), 22, 1,
                      "run 'a' (from line 2) reappears after run 'b'"));
}

// Messages quote cells, column names and run labels escaped (automaton/quoted_text.h): an ESC
// sequence in a file reaches the terminal as text, not as a command (clear screen, colours).
TEST(ReadMeasuredDataErrors, ControlCharactersInQuotedCellsAreEscaped) {
  EXPECT_TRUE(FailsAt(WithRow("1,3,\x1b[2J,20,30"), 5, 3, "not a number: '\\x1b[2J'"));
  EXPECT_TRUE(FailsAt("run,g,theta1,theta2,the\x1bta3\n", 1, 5, "unknown column 'the\\x1bta3'"));
  EXPECT_TRUE(FailsAt(std::string(kHeader) + Rows("a\x1b[31m", 9) + Rows("b", 10), 2, 1,
                      "run 'a\\x1b[31m' has 9 samples"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,1\x7f,20,30"), 5, 3, "not a number: '1\\x7f'"));
  try {
    Read(std::string(kHeader) + Rows("a\x1b[31m", 9));
    ADD_FAILURE() << "no error";
  } catch (const DataError& e) {
    EXPECT_EQ(std::string(e.what()).find('\x1b'), std::string::npos) << e.what();
  }
  // The source name too, in what(); source() keeps it as given.
  const DataError e("d\x1b.csv", 1, 2, "m\n");
  EXPECT_EQ(std::string(e.what()), "d\\x1b.csv:1:2: m\\n");
  EXPECT_EQ(e.source(), "d\x1b.csv");
}

TEST(ReadMeasuredDataErrors, CellsAreCheckedFromLeftToRight) {
  EXPECT_TRUE(FailsAt(WithRow("1,300,abc,20,nan"), 5, 2, "column 'g'"));
  EXPECT_TRUE(FailsAt(WithRow("1,3,abc,20,nan"), 5, 3, "column 'theta1'"));
}

// ---------------------------------------------------------------------------------------------
// Outlier cleaning.

// A run `label` with g = 0, 1, ..., lines 2, 3, ..., and the given angles (the other joints 0).
MeasuredRun MakeRun(std::string label, std::vector<double> theta1, std::vector<double> theta2 = {},
                    std::vector<double> theta3 = {}) {
  MeasuredRun run;
  run.label = std::move(label);
  const size_t n = theta1.size();
  if (theta2.empty()) theta2.assign(n, 0.0);
  if (theta3.empty()) theta3.assign(n, 0.0);
  run.theta = {std::move(theta1), std::move(theta2), std::move(theta3)};
  for (size_t i = 0; i < n; ++i) {
    run.g.push_back(static_cast<double>(i));
    run.lines.push_back(static_cast<int>(i) + 2);
  }
  return run;
}

MeasuredData MakeData(std::vector<MeasuredRun> runs) {
  MeasuredData data;
  data.source = "synthetic";
  data.runs = std::move(runs);
  return data;
}

// Cleans theta1 of a single run and returns it.
std::vector<double> Clean(std::vector<double> theta1, double threshold = 5.0) {
  MeasuredData data = MakeData({MakeRun("r", std::move(theta1))});
  CleanOutliers(data, threshold);
  return data.runs[0].theta[0];
}

// Element-wise equality where NaN equals NaN.
::testing::AssertionResult SameSamples(const std::vector<double>& actual,
                                       const std::vector<double>& expected) {
  bool same = actual.size() == expected.size();
  for (size_t i = 0; same && i < actual.size(); ++i) {
    same = (std::isnan(actual[i]) && std::isnan(expected[i])) || actual[i] == expected[i];
  }
  if (same) return ::testing::AssertionSuccess();
  auto text = [](const std::vector<double>& v) {
    std::ostringstream out;
    for (const double x : v) out << x << " ";
    return out.str();
  };
  return ::testing::AssertionFailure() << "got " << text(actual) << "expected " << text(expected);
}

TEST(CleanOutliers, ClampsAnIsolatedSpikeWithinThresholdOfItsNeighbours) {
  MeasuredData data = MakeData({MakeRun("r", {0, 0, 0, 10, 0, 0, 0, 0, 0, 0})});
  const OutlierReport report = CleanOutliers(data);
  EXPECT_TRUE(SameSamples(data.runs[0].theta[0], {0, 0, 0, 5, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(report.clamped, (std::array<int, 3>{1, 0, 0}));
  ASSERT_EQ(report.entries.size(), 1u);
  EXPECT_EQ(report.entries[0].run, "r");
  EXPECT_EQ(report.entries[0].line, 5);
  EXPECT_EQ(report.entries[0].joint, 1);
  EXPECT_EQ(report.entries[0].measured, 10.0);
  EXPECT_EQ(report.entries[0].cleaned, 5.0);
}

TEST(CleanOutliers, ClampsIntoTheIntervalWithinThresholdOfBothNeighbours) {
  // Previous inlier 0, next 4: the interval is [-1, 5].
  EXPECT_TRUE(SameSamples(Clean({0, 0, -20, 4, 4}), {0, 0, -1, 4, 4}));
  EXPECT_TRUE(SameSamples(Clean({0, 0, 20, 4, 4}), {0, 0, 5, 4, 4}));
}

TEST(CleanOutliers, EmptyIntervalMovesThresholdFromThePreviousInlierTowardsTheSample) {
  // Previous 0, next 12: [7, 5] is empty, so 0 + 5.
  EXPECT_TRUE(SameSamples(Clean({0, 0, 20, 12, 12, 12}), {0, 0, 5, 12, 12, 12}));
  EXPECT_TRUE(SameSamples(Clean({0, 0, -20, -12, -12, -12}), {0, 0, -5, -12, -12, -12}));
}

TEST(CleanOutliers, CleanedSampleDoesNotBecomeThePreviousInlier) {
  // 10 is cleaned to -2 (within 5 of 0 and of -7); -7 is then compared with 0, not with -2: it is
  // 7 away from 0 and from the next sample 0, so it is an outlier too.
  EXPECT_TRUE(SameSamples(Clean({0, 0, 10, -7, 0, 0}), {0, 0, -2, -5, 0, 0}));
}

TEST(CleanOutliers, LeavesASteadyRampAlone) {
  std::vector<double> ramp;
  for (int i = 0; i < 40; ++i) ramp.push_back(i);
  EXPECT_TRUE(SameSamples(Clean(ramp), ramp));
  std::vector<double> steep;
  for (int i = 0; i < 40; ++i) steep.push_back(-4.9 * i);
  EXPECT_TRUE(SameSamples(Clean(steep), steep));
}

TEST(CleanOutliers, KeepsAGenuineStepToAPlateau) {
  const std::vector<double> step = {0, 0, 0, 0, 6, 6, 6, 6, 6, 6};
  MeasuredData data = MakeData({MakeRun("r", step)});
  const OutlierReport report = CleanOutliers(data);
  EXPECT_TRUE(SameSamples(data.runs[0].theta[0], step));
  EXPECT_TRUE(report.entries.empty());
  EXPECT_EQ(report.clamped, (std::array<int, 3>{0, 0, 0}));
  // Also two equal spikes in a row: the second confirms the first.
  const std::vector<double> pair = {0, 0, 9, 9, 0, 0};
  EXPECT_TRUE(SameSamples(Clean(pair), pair));
}

TEST(CleanOutliers, SkipsMissingSamples) {
  // The spike's neighbours are found across the missing samples, which stay missing.
  EXPECT_TRUE(SameSamples(Clean({0, kNaN, 10, kNaN, kNaN, 0, 0}), {0, kNaN, 5, kNaN, kNaN, 0, 0}));
  // The next present sample confirms the step across missing ones.
  EXPECT_TRUE(SameSamples(Clean({0, 0, 10, kNaN, kNaN, 10, 10}), {0, 0, 10, kNaN, kNaN, 10, 10}));
  // Missing samples at the start: the first present one is the first inlier.
  EXPECT_TRUE(SameSamples(Clean({kNaN, kNaN, 3, 3, 30, 3}), {kNaN, kNaN, 3, 3, 8, 3}));
  // All missing.
  EXPECT_TRUE(SameSamples(Clean({kNaN, kNaN, kNaN}), {kNaN, kNaN, kNaN}));
}

TEST(CleanOutliers, LastSampleHasNoNextSampleToConfirmIt) {
  EXPECT_TRUE(SameSamples(Clean({0, 0, 0, 9}), {0, 0, 0, 5}));
  EXPECT_TRUE(SameSamples(Clean({0, 0, 0, -9, kNaN}), {0, 0, 0, -5, kNaN}));
  EXPECT_TRUE(SameSamples(Clean({0, 0, 0, 4.5}), {0, 0, 0, 4.5}));
}

TEST(CleanOutliers, FirstSampleIsAnInlier) {
  EXPECT_TRUE(SameSamples(Clean({30, 0, 0, 0}), {30, 0, 0, 0}));
}

TEST(CleanOutliers, ThresholdIsAParameter) {
  EXPECT_TRUE(SameSamples(Clean({0, 0, 3, 0, 0}, 2.0), {0, 0, 2, 0, 0}));
  EXPECT_TRUE(SameSamples(Clean({0, 0, 3, 0, 0}), {0, 0, 3, 0, 0}));
  // A change of exactly the threshold is not an outlier.
  EXPECT_TRUE(SameSamples(Clean({0, 0, 5, 0, 0}), {0, 0, 5, 0, 0}));
}

TEST(CleanOutliers, RejectsAThresholdThatIsNotPositive) {
  MeasuredData data = MakeData({MakeRun("r", {0, 1, 2})});
  EXPECT_THROW(CleanOutliers(data, 0.0), std::invalid_argument);
  EXPECT_THROW(CleanOutliers(data, -1.0), std::invalid_argument);
  EXPECT_THROW(CleanOutliers(data, kNaN), std::invalid_argument);
}

TEST(CleanOutliers, CountsPerJointOverRuns) {
  MeasuredData data = MakeData({
      MakeRun("a", {0, 1, 2, 3, 4}, {0, 0, 20, 0, 0}, {5, 5, 5, 5, 5}),
      MakeRun("b", {0, 0, 0, 0, 0}, {1, 1, 1, 1, 1}, {0, -8, 0, 0, 8}),
  });
  const OutlierReport report = CleanOutliers(data);
  EXPECT_EQ(report.clamped, (std::array<int, 3>{0, 1, 2}));
  ASSERT_EQ(report.entries.size(), 3u);
  EXPECT_EQ(report.entries[0].run, "a");
  EXPECT_EQ(report.entries[0].joint, 2);
  EXPECT_EQ(report.entries[0].line, 4);
  EXPECT_EQ(report.entries[0].cleaned, 5.0);
  EXPECT_EQ(report.entries[1].run, "b");
  EXPECT_EQ(report.entries[1].joint, 3);
  EXPECT_EQ(report.entries[1].line, 3);
  EXPECT_EQ(report.entries[1].measured, -8.0);
  EXPECT_EQ(report.entries[1].cleaned, -5.0);
  EXPECT_EQ(report.entries[2].line, 6);
  EXPECT_EQ(report.entries[2].cleaned, 5.0);
  EXPECT_TRUE(SameSamples(data.runs[1].theta[2], {0, -5, 0, 0, 5}));
  EXPECT_TRUE(SameSamples(data.runs[0].theta[0], {0, 1, 2, 3, 4}));
}

// ---------------------------------------------------------------------------------------------
// Noise floor.

constexpr std::array<double, 3> kSigma = {0.7, 0.7, 1.2};

// Standard normal deviates by Box-Muller on the raw output of std::mt19937 (the standard's
// distributions differ between libraries; the engine does not).
class Gaussian {
 public:
  explicit Gaussian(uint32_t seed) : engine_(seed) {}
  double operator()() {
    constexpr double kTwoPi = 2.0 * std::numbers::pi;
    const double u1 = (engine_() + 0.5) / 4294967296.0;
    const double u2 = (engine_() + 0.5) / 4294967296.0;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
  }

 private:
  std::mt19937 engine_;
};

// The smooth angle curves of the synthetic runs, degrees, at motor position g.
double Curve(int joint, double g) {
  return 20.0 * std::sin(g / 40.0 + joint) + 10.0 * joint + 0.05 * g;
}

// A run of `n` samples at g = offset + 250 i / (n - 1): the curves plus noise of kSigma.
MeasuredRun NoisyRun(std::string label, int n, double offset, Gaussian& noise) {
  MeasuredRun run;
  run.label = std::move(label);
  for (int i = 0; i < n; ++i) {
    const double g = offset + 250.0 * i / (n - 1);
    run.g.push_back(g);
    for (int j = 0; j < 3; ++j) run.theta[j].push_back(Curve(j, g) + kSigma[j] * noise());
    run.lines.push_back(i + 2);
  }
  return run;
}

void ExpectNearNoise(const NoiseFloor& floor) {
  for (int j = 0; j < 3; ++j) {
    const double expected = kSigma[j] * kSigma[j];
    EXPECT_NEAR(floor.variance[j], expected, 0.1 * expected) << "joint " << j + 1;
  }
}

TEST(EstimateNoiseFloor, PoolsTheVarianceOfRepeatedRuns) {
  Gaussian noise(20260110);
  std::vector<MeasuredRun> runs;
  for (int r = 0; r < 4; ++r) runs.push_back(NoisyRun("free" + std::to_string(r), 500, 0, noise));
  for (int r = 0; r < 3; ++r) {
    runs.push_back(NoisyRun("contact" + std::to_string(r), 600, 2, noise));
    runs.back().gob = 100;
    runs.back().contact_link = 1;
  }
  // Not a repeat of the contact runs (other link), nor of the free runs (other g): ignored.
  runs.push_back(NoisyRun("lone", 600, 2, noise));
  runs.back().gob = 100;
  runs.back().contact_link = 2;
  // Within 1e-9 of the free runs' g: still a repeat.
  runs[1].g[7] += 1e-10;
  // Missing theta1 at two samples of one free run: those samples do not count for theta1.
  runs[2].theta[0][10] = kNaN;
  runs[2].theta[0][11] = kNaN;
  const NoiseFloor floor = EstimateNoiseFloor(MakeData(std::move(runs)));
  EXPECT_EQ(floor.method, "repeated_runs");
  const int dof = 500 * 3 + 600 * 2;
  // The spike rule (SpikeMask at 4 sigma) leaves out the rare Gaussian samples it flags: a few
  // per thousand at most.
  const std::array<int, 3> all = {dof - 2 * 3, dof, dof};
  for (int j = 0; j < 3; ++j) {
    EXPECT_LE(floor.dof[j], all[j]);
    EXPECT_GE(floor.dof[j], 0.99 * all[j]);
  }
  ExpectNearNoise(floor);
}

TEST(EstimateNoiseFloor, RepeatedRunsVarianceIsTheWithinGroupVariance) {
  // Two runs, 10 samples, differing by 2 at every sample: deviations of 1 from the mean, so a sum
  // of squares of 2 per sample over 1 degree of freedom.
  std::vector<double> a(10, 0.0), b(10, 2.0);
  MeasuredData data = MakeData({MakeRun("a", a, a, a), MakeRun("b", b, a, b)});
  const NoiseFloor floor = EstimateNoiseFloor(data);
  EXPECT_EQ(floor.method, "repeated_runs");
  EXPECT_EQ(floor.dof, (std::array<int, 3>{10, 10, 10}));
  EXPECT_DOUBLE_EQ(floor.variance[0], 2.0);
  EXPECT_DOUBLE_EQ(floor.variance[1], 0.0);
  EXPECT_DOUBLE_EQ(floor.variance[2], 2.0);
}

TEST(EstimateNoiseFloor, UsesSecondDifferencesWithoutRepeats) {
  Gaussian noise(7);
  std::vector<MeasuredRun> runs;
  // Different g grids (and one other gob): no two runs are repeats.
  for (int r = 0; r < 4; ++r) runs.push_back(NoisyRun(std::to_string(r), 1000, r, noise));
  runs.push_back(NoisyRun("4", 1000, 0, noise));
  runs.back().gob = 80;
  runs.back().contact_link = 2;
  const MeasuredData data = MakeData(std::move(runs));
  const NoiseFloor floor = EstimateNoiseFloor(data);
  EXPECT_EQ(floor.method, "second_differences");
  for (int j = 0; j < 3; ++j) {  // but for the rare samples the spike rule flags
    EXPECT_LE(floor.dof[j], 5 * 998);
    EXPECT_GE(floor.dof[j], 0.99 * 5 * 998);
  }
  ExpectNearNoise(floor);

  // Robust: three spikes of 30 degrees per run (each in 3 of the 998 second differences, which
  // would add about 16 deg^2 to a plain variance) move the estimate by less than 5%.
  MeasuredData spiky = data;
  for (MeasuredRun& run : spiky.runs) {
    for (const int i : {100, 400, 700}) {
      for (int j = 0; j < 3; ++j) run.theta[j][i] += 30.0;
    }
  }
  const NoiseFloor robust = EstimateNoiseFloor(spiky);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(robust.variance[j], floor.variance[j], 0.05 * floor.variance[j])
        << "joint " << j + 1;
  }
}

TEST(EstimateNoiseFloor, SecondDifferencesSkipMissingSamples) {
  // theta1 missing at one sample: the three second differences that use it are skipped; theta3
  // missing everywhere: no estimate.
  std::vector<double> x(12, 1.0), none(12, kNaN);
  x[5] = kNaN;
  MeasuredRun run = MakeRun("a", x, std::vector<double>(12, 1.0), none);
  const NoiseFloor floor = EstimateNoiseFloor(MakeData({run}));
  EXPECT_EQ(floor.method, "second_differences");
  EXPECT_EQ(floor.dof, (std::array<int, 3>{7, 10, 0}));
  EXPECT_EQ(floor.variance, (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(EstimateNoiseFloor, RunsWithOtherGAreNotRepeats) {
  MeasuredRun a = MakeRun("a", std::vector<double>(12, 1.0));
  MeasuredRun b = a;
  b.label = "b";
  b.g[3] += 1e-6;
  EXPECT_EQ(EstimateNoiseFloor(MakeData({a, b})).method, "second_differences");
  b.g[3] = a.g[3];
  b.g.push_back(12);  // another number of samples
  for (auto& t : b.theta) t.push_back(1.0);
  b.lines.push_back(14);
  EXPECT_EQ(EstimateNoiseFloor(MakeData({a, b})).method, "second_differences");
  b = a;
  b.gob = 50;
  b.contact_link = 1;
  EXPECT_EQ(EstimateNoiseFloor(MakeData({a, b})).method, "second_differences");
  b.gob.reset();
  b.contact_link.reset();
  EXPECT_EQ(EstimateNoiseFloor(MakeData({a, b})).method, "repeated_runs");
}

}  // namespace
}  // namespace hybrid
