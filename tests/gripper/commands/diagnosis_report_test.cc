// Tests of the SVG files of `hybrid diagnose --report DIR` (gripper/commands/diagnosis_report.h):
// file names (sanitised, unique run labels), a naive well-formedness check (root element, balanced
// groups, no "nan"/"inf"), one polyline per stretch of finite model values, one dot per finite
// measured sample or residual, XML escaping of labels and causes, the noise lines and ticks, the
// size of a long run's file, and the empty directory.

#include "gripper/commands/diagnosis_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace hybrid::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Files = std::vector<std::pair<std::string, std::string>>;

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size())) {
    ++n;
  }
  return n;
}

/// The contents of every <g ...> whose attributes contain `attribute`, in order, up to its first
/// "</g>" (the groups searched for hold no nested group).
std::vector<std::string> Groups(const std::string& svg, const std::string& attribute) {
  std::vector<std::string> groups;
  for (std::size_t at = svg.find("<g "); at != std::string::npos; at = svg.find("<g ", at + 1)) {
    const std::size_t end_of_tag = svg.find('>', at);
    const std::string tag = svg.substr(at, end_of_tag - at);
    if (tag.find(attribute) == std::string::npos) continue;
    const std::size_t close = svg.find("</g>", end_of_tag);
    groups.push_back(svg.substr(end_of_tag + 1, close - end_of_tag - 1));
  }
  return groups;
}

/// Maximal stretches of finite values.
int Stretches(const std::vector<double>& v) {
  int n = 0;
  bool in = false;
  for (double x : v) {
    if (std::isfinite(x) && !in) ++n;
    in = std::isfinite(x);
  }
  return n;
}

int Finite(const std::vector<double>& v) {
  return static_cast<int>(
      std::count_if(v.begin(), v.end(), [](double x) { return std::isfinite(x); }));
}

// `v` where the run's request g is finite too, NaN elsewhere: what the panels plot against g.
std::vector<double> WhereGIsFinite(const std::vector<double>& v, const std::vector<double>& g) {
  std::vector<double> out = v;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (i >= g.size() || !std::isfinite(g[i])) out[i] = std::nan("");
  }
  return out;
}

void ExpectWellFormed(const std::string& name, const std::string& svg) {
  SCOPED_TRACE(name);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  ASSERT_GE(svg.size(), 7u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(Count(svg, "<svg"), 1);
  EXPECT_NE(svg.find("viewBox=\"0 0 "), std::string::npos);
  // Balanced and properly nested groups.
  int depth = 0;
  for (std::size_t i = 0; i < svg.size(); ++i) {
    if (svg.compare(i, 3, "<g ") == 0 || svg.compare(i, 3, "<g>") == 0) ++depth;
    if (svg.compare(i, 4, "</g>") == 0) {
      --depth;
      ASSERT_GE(depth, 0) << "at " << i;
    }
  }
  EXPECT_EQ(depth, 0);
  EXPECT_EQ(Count(svg, "<text"), Count(svg, "</text>"));
  std::string lower = svg;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  EXPECT_EQ(lower.find("nan"), std::string::npos);
  EXPECT_EQ(lower.find("inf"), std::string::npos);
  // Numbers have at most 4 significant digits: never five digits after a decimal point.
  EXPECT_FALSE(std::regex_search(svg, std::regex("\\.[0-9]{5}")));
}

RunCurves MakeRun(const std::string& label, int n, double g0, double dg) {
  RunCurves run;
  run.label = label;
  for (int i = 0; i < n; ++i) {
    const double g = g0 + dg * i;
    run.g.push_back(g);
    for (int j = 0; j < 3; ++j) {
      const double model = (j + 1) * 0.3 * g + 1.0 / 3.0;
      run.baseline[j].push_back(model);
      run.extended[j].push_back(model + 0.5 * j);
      run.measured[j].push_back(model + 0.5 * j + 0.1 * std::sin(1.7 * i + j));
    }
  }
  return run;
}

/// Two runs, closing and opening, with missing samples and labels to sanitise and escape.
Diagnosis Sample() {
  Diagnosis d;
  RunCurves closing = MakeRun("a/b c", 20, 0.0, 10.0);
  closing.measured[0][3] = kNaN;
  closing.measured[0][4] = kNaN;
  closing.measured[2][19] = kNaN;
  closing.baseline[1][7] = kNaN;   // two stretches
  closing.baseline[2][0] = kNaN;   // still one
  closing.extended[2][10] = kNaN;  // two stretches
  closing.extended[2][12] = kNaN;  // three stretches, one of them a single point
  RunCurves opening = MakeRun("run<&>2", 15, 190.0, -12.0);
  opening.g[5] = kNaN;  // breaks the motor strip; no residual at sample 5
  opening.measured[1][0] = kNaN;
  opening.baseline[0] = std::vector<double>(15, kNaN);  // no baseline at all for theta1
  d.curves = {closing, opening};
  d.cause = {"backlash", "a<b&c"};
  d.parameters = {{EffectParameter{Cause::kBacklash, 0}, 4.25}};
  d.baseline_mse = {2.5, 1.0, 0.75};
  d.extended_mse = {0.02, 0.015, kNaN};
  d.noise.variance = {0.01, 0.0004, 0.0};
  d.noise.dof = {10, 10, 0};
  return d;
}

TEST(DiagnosisReport, FileNamesAreSanitisedAndInOrder) {
  const Files files = DiagnosisReportFiles(Sample(), "out/report");
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(files[0].first, "out/report/run_a_b_c.svg");
  EXPECT_EQ(files[1].first, "out/report/run_run___2.svg");
  EXPECT_EQ(files[2].first, "out/report/residuals.svg");
  EXPECT_EQ(files[3].first, "out/report/summary.svg");
}

TEST(DiagnosisReport, DuplicateSanitisedLabelsGetDistinctNames) {
  Diagnosis d;
  for (const char* label : {"x y", "x/y", "x_y", "", "x_y_2", "1"})
    d.curves.push_back(MakeRun(label, 3, 0, 1));
  const Files files = DiagnosisReportFiles(d, "r");
  ASSERT_EQ(files.size(), 8u);
  const std::vector<std::string> expected = {"r/run_x_y.svg",     "r/run_x_y_2.svg",
                                             "r/run_x_y_3.svg",   "r/run_4.svg",
                                             "r/run_x_y_2_2.svg", "r/run_1.svg"};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(files[i].first, expected[i]);
  for (const auto& [name, svg] : files) ExpectWellFormed(name, svg);
}

TEST(DiagnosisReport, EveryFileIsWellFormed) {
  for (const auto& [name, svg] : DiagnosisReportFiles(Sample(), "dir")) ExpectWellFormed(name, svg);
}

TEST(DiagnosisReport, RunFilesHaveOnePolylinePerFiniteStretchAndOneDotPerSample) {
  const Diagnosis d = Sample();
  const Files files = DiagnosisReportFiles(d, "dir");
  for (std::size_t r = 0; r < d.curves.size(); ++r) {
    SCOPED_TRACE(files[r].first);
    const RunCurves& run = d.curves[r];
    const std::string& svg = files[r].second;
    const auto measured = Groups(svg, "class=\"measured\"");
    const auto baseline = Groups(svg, "class=\"baseline\"");
    const auto extended = Groups(svg, "class=\"extended\"");
    ASSERT_EQ(measured.size(), 3u);
    ASSERT_EQ(baseline.size(), 3u);
    ASSERT_EQ(extended.size(), 3u);
    int polylines = 0, dots = 0;
    for (int j = 0; j < 3; ++j) {
      SCOPED_TRACE(j);
      // Against g: samples whose g is missing are left out.
      const std::vector<double> m = WhereGIsFinite(run.measured[j], run.g);
      const std::vector<double> b = WhereGIsFinite(run.baseline[j], run.g);
      const std::vector<double> e = WhereGIsFinite(run.extended[j], run.g);
      EXPECT_EQ(Count(measured[j], "<circle"), Finite(m));
      EXPECT_EQ(Count(measured[j], "r=\"1.2\""), Finite(m));
      EXPECT_EQ(Count(measured[j], "<polyline"), 0);
      EXPECT_EQ(Count(baseline[j], "<polyline"), Stretches(b));
      EXPECT_EQ(Count(extended[j], "<polyline"), Stretches(e));
      EXPECT_EQ(Count(baseline[j], "<circle"), 0);
      polylines += Stretches(b) + Stretches(e);
      dots += Finite(m);
    }
    // Plus the motor strip.
    EXPECT_EQ(Count(svg, "<polyline"), polylines + Stretches(run.g));
    EXPECT_EQ(Count(svg, "<circle"), dots);
    EXPECT_NE(svg.find("stroke-dasharray"), std::string::npos);
    for (const char* axis :
         {"theta1 (deg)", "theta2 (deg)", "theta3 (deg)", ">sample<", ">g (counts)<",
          ">request g (counts)<", "measured", "baseline model", "extended model"}) {
      EXPECT_NE(svg.find(axis), std::string::npos) << axis;
    }
  }
  EXPECT_EQ(Count(files[0].second, "<polyline"), 1 + 2 + 1 + 1 + 1 + 3 + 1);
  // The opening run's missing g at sample 5 breaks every curve drawn against g, and the strip.
  EXPECT_EQ(Count(files[1].second, "<polyline"), 0 + 2 + 2 + 2 + 2 + 2 + 2);
}

TEST(DiagnosisReport, TicksHaveNumbers) {
  const Files files = DiagnosisReportFiles(Sample(), "dir");
  // The closing run: g from 0 to 190 on the x axis, theta1 from about 0 to 57 deg.
  EXPECT_NE(files[0].second.find(">10</text>"), std::string::npos);
  EXPECT_NE(files[0].second.find(">50</text>"), std::string::npos);
  EXPECT_NE(files[2].second.find(">100</text>"), std::string::npos);
}

TEST(DiagnosisReport, LabelsAndCausesAreEscaped) {
  const Files files = DiagnosisReportFiles(Sample(), "dir");
  EXPECT_NE(files[1].second.find("run&lt;&amp;&gt;2"), std::string::npos);
  EXPECT_EQ(files[1].second.find("<&>"), std::string::npos);
  EXPECT_NE(files[0].second.find("a/b c"), std::string::npos);
  const std::string& summary = files[3].second;
  EXPECT_NE(summary.find("Cause: backlash, a&lt;b&amp;c"), std::string::npos);
  EXPECT_EQ(summary.find("a<b"), std::string::npos);
  EXPECT_NE(summary.find("backlash = 4.25 count"), std::string::npos);
}

TEST(DiagnosisReport, ResidualsHaveOneDotPerFiniteResidualAndNoiseLines) {
  const Diagnosis d = Sample();
  const Files files = DiagnosisReportFiles(d, "dir");  // owns the text `svg` refers to
  ASSERT_EQ(files.size(), 4u);
  const std::string& svg = files[2].second;
  const auto baseline = Groups(svg, "class=\"baseline\"");
  const auto extended = Groups(svg, "class=\"extended\"");
  const auto noise = Groups(svg, "class=\"noise\"");
  ASSERT_EQ(baseline.size(), 3u);
  ASSERT_EQ(extended.size(), 3u);
  ASSERT_EQ(noise.size(), 2u);  // theta3's noise variance is 0: no lines
  for (const std::string& lines : noise) EXPECT_EQ(Count(lines, "<line"), 2);
  int total = 0;
  for (int j = 0; j < 3; ++j) {
    SCOPED_TRACE(j);
    int expected_baseline = 0, expected_extended = 0;
    for (const RunCurves& run : d.curves) {
      for (std::size_t i = 0; i < run.g.size(); ++i) {
        if (!std::isfinite(run.g[i]) || !std::isfinite(run.measured[j][i])) continue;
        expected_baseline += std::isfinite(run.baseline[j][i]);
        expected_extended += std::isfinite(run.extended[j][i]);
      }
    }
    EXPECT_EQ(Count(baseline[j], "<circle"), expected_baseline);
    EXPECT_EQ(Count(extended[j], "<circle"), expected_extended);
    total += expected_baseline + expected_extended;
  }
  EXPECT_EQ(Count(svg, "<circle"), total);
  EXPECT_EQ(Count(svg, "r=\"1.2\""), total);
  EXPECT_EQ(Count(svg, "<polyline"), 0);
  EXPECT_NE(svg.find("#1f77b4"), std::string::npos);
  EXPECT_NE(svg.find("#d62728"), std::string::npos);
}

TEST(DiagnosisReport, SummaryHasBarsAndNoiseTicks) {
  const Files files = DiagnosisReportFiles(Sample(), "dir");  // owns the text `svg` refers to
  ASSERT_EQ(files.size(), 4u);
  const std::string& svg = files[3].second;
  const auto joints = Groups(svg, "class=\"joint\"");
  ASSERT_EQ(joints.size(), 3u);
  EXPECT_EQ(Count(joints[0], "<rect"), 2);
  EXPECT_EQ(Count(joints[1], "<rect"), 2);
  EXPECT_EQ(Count(joints[2], "<rect"), 1);  // the extended MSE of theta3 is missing
  for (const std::string& joint : joints) EXPECT_EQ(Count(joint, "class=\"noise\""), 1);
  EXPECT_NE(svg.find("held-out MSE"), std::string::npos);
}

TEST(DiagnosisReport, EmptyDiagnosisStillWritesWellFormedFiles) {
  Diagnosis d;
  d.curves.push_back(RunCurves{});  // no samples at all
  const Files files = DiagnosisReportFiles(d, "dir");
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].first, "dir/run_1.svg");
  for (const auto& [name, svg] : files) ExpectWellFormed(name, svg);
  EXPECT_NE(files[2].second.find("Cause: none"), std::string::npos);
}

TEST(DiagnosisReport, ConstantAndNonFiniteDataGiveWellFormedFiles) {
  Diagnosis d;
  RunCurves run = MakeRun("flat", 10, 5.0, 0.0);  // constant g
  for (int j = 0; j < 3; ++j) {
    run.measured[j].assign(10, 7.0);
    run.baseline[j].assign(10, std::numeric_limits<double>::infinity());
    run.extended[j].assign(10, -std::numeric_limits<double>::infinity());
  }
  d.curves = {run};
  d.baseline_mse = {kNaN, std::numeric_limits<double>::infinity(), 0.0};
  d.noise.variance = {kNaN, -1.0, 0.0};
  for (const auto& [name, svg] : DiagnosisReportFiles(d, "dir")) ExpectWellFormed(name, svg);
}

TEST(DiagnosisReport, LongRunFileIsSmall) {
  Diagnosis d;
  d.curves = {MakeRun("long", 512, 0.0, 0.5)};
  const Files files = DiagnosisReportFiles(d, "dir");
  EXPECT_LT(files[0].second.size(), 200u * 1024u);
  EXPECT_EQ(Count(files[0].second, "<circle"), 3 * 512);
  ExpectWellFormed(files[0].first, files[0].second);
}

TEST(DiagnosisReport, EmptyDirectoryThrows) {
  EXPECT_THROW(DiagnosisReportFiles(Sample(), ""), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid::cli
