// Tests of `hybrid simulate` (HYBRID_BINARY): the bundled models run to completion, the JSON
// summary, the trajectory and event CSVs, input overrides from the command line and from a CSV
// file, every kind of bad input (exit 2 for a bad option value, 1 for a bad model or file, a clear
// message, no output file), outputs that name one file or an input, outputs written all or
// nothing, and runs that stop early (exit 5, outputs still written).

#include "commands/simulate_command.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "commands/trajectory_plot.h"
#include "tests/test_utilities/command_line.h"
#include "tests/test_utilities/in_process.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::Field;
using testing::Quote;
using testing::ReadAll;
using testing::Result;
using testing::RunHybrid;
using testing::TempDir;

const fs::path kSourceDir = HYBRID_SOURCE_DIR;

using testing::ArgsOf;
using testing::InProcess;

std::string Spec(const std::string& name) {
  return (kSourceDir / "spec" / (name + ".ha")).string();
}

// Runs `hybrid simulate ARGS` through the shell (quote the arguments that need it).
Result Simulate(const std::string& args) { return RunHybrid("simulate " + args); }

json SimulateJson(const std::string& args, int expected_exit = 0) {
  return testing::RunHybridJson("simulate " + args, expected_exit);
}

// `hybrid simulate` run in this process (cli::RunSimulate): its exit code and standard output.
InProcess SimulateHere(const cli::SimulateArgs& args) {
  return testing::RunInProcess([&] { return cli::RunSimulate(args); });
}

// SimulateHere with `json` set: expects `expected_exit` and parses standard output (an output
// that is not JSON is a test failure and gives an empty object).
json SimulateJsonHere(cli::SimulateArgs args, int expected_exit = 0) {
  args.json = true;
  const InProcess r = SimulateHere(args);
  EXPECT_EQ(r.exit_code, expected_exit) << "simulate " << args.model;
  try {
    return json::parse(r.out);
  } catch (const json::exception& e) {
    ADD_FAILURE() << "simulate " << args.model << ": not JSON (" << e.what() << "):\n" << r.out;
    return json::object();
  }
}

// Rows of a CSV file, split at commas.
std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(ReadAll(path));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream fields(line);
    while (std::getline(fields, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

// ---------------------------------------------------------------------------------------------
// Runs that complete.

TEST(HybridSimulate, BundledModelsComplete) {
  for (const std::string name : {"bouncing_ball", "thermostat", "finger", "hand"}) {
    const InProcess r = SimulateHere(ArgsOf<cli::SimulateArgs>(Spec(name)));
    EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.out;
    EXPECT_NE(r.out.find("status: completed"), std::string::npos) << name << "\n" << r.out;
    EXPECT_NE(r.out.find("final state:"), std::string::npos) << r.out;
  }
}

TEST(HybridSimulate, JsonHasStatusEventsAndStatesByName) {
  const json j = SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger")));
  EXPECT_EQ(Field(j, "status"), "completed");
  EXPECT_EQ(Field(j, "message"), "");
  EXPECT_EQ(Field(j, "until"), 530.0);
  ASSERT_EQ(Field(j, "events").size(), 6u) << j.dump(2);
  const json& first = Field(j, "events", 0);
  EXPECT_NEAR(Field(first, "time").get<double>(), 110.0, 1e-9);
  EXPECT_EQ(Field(first, "cause"), "crossing");
  EXPECT_EQ(Field(first, "transitions"), json::array({"t5_c000_l000_to_c000_l00n"}));
  EXPECT_EQ(Field(first, "mode_before"), "c000_l000");
  EXPECT_EQ(Field(first, "mode_after"), "c000_l00n");
  for (const char* v : {"theta1", "theta2", "theta3", "g"}) {
    EXPECT_TRUE(Field(first, "before").contains(v)) << v;
    EXPECT_TRUE(Field(first, "after").contains(v)) << v;
  }
  EXPECT_NEAR(Field(first, "before", "theta3").get<double>(), -55.0, 1e-8);
  EXPECT_NEAR(Field(first, "before", "g").get<double>(), 110.0, 1e-8);
  EXPECT_EQ(Field(j, "events", 3, "cause"), "enabled");  // u reverses at t = 265
  EXPECT_EQ(Field(j, "final", "time"), 530.0);
  EXPECT_EQ(Field(j, "final", "mode"), "c000_l000");
  EXPECT_NEAR(Field(j, "final", "values", "g").get<double>(), 0.0, 1e-8);
  EXPECT_GE(Field(j, "steps").get<long>(), 0);  // CVODE steps: none for constant-rate modes
  EXPECT_FALSE(j.contains("zeno"));
  // A composed model: qualified variable and mode names.
  const json hand = SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("hand")));
  EXPECT_EQ(Field(hand, "status"), "completed");
  EXPECT_TRUE(Field(hand, "final", "values").contains("B.theta2"));
  EXPECT_EQ(Field(hand, "events", 0, "transitions"), json::array({"A.t5_c000_l000_to_c000_l00n"}));
}

TEST(HybridSimulate, TraceCsvHasEveryEventAndSample) {
  TempDir dir;
  const std::string trace = dir.File("trace.csv"), events = dir.File("events.csv");
  const json j =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("thermostat"), [&](cli::SimulateArgs& a) {
        a.sample = 2.5;
        a.out = trace;
        a.events = events;
      }));
  ASSERT_EQ(Field(j, "status"), "completed");
  const auto rows = ReadCsv(trace);
  ASSERT_GT(rows.size(), 2u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"time", "kind", "mode", "x"}));
  std::vector<double> before, after, samples;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 4u) << "row " << i;
    const double t = std::stod(rows[i][0]);
    const std::string& kind = rows[i][1];
    if (kind == "before_event") before.push_back(t);
    if (kind == "after_event") after.push_back(t);
    if (kind == "sample") samples.push_back(t);
    if (i > 1) {
      EXPECT_GE(t, std::stod(rows[i - 1][0])) << "row " << i;
    }
    EXPECT_TRUE(rows[i][2] == "off" || rows[i][2] == "on") << rows[i][2];
  }
  EXPECT_EQ(rows[1][1], "start");
  EXPECT_EQ(rows[1][0], "0");
  EXPECT_EQ(rows[1][3], "20");
  EXPECT_EQ(rows.back()[1], "end");
  EXPECT_EQ(rows.back()[0], "120");
  // Both sides of every event, at the event's time (printed with 17 digits).
  ASSERT_EQ(before.size(), Field(j, "events").size());
  ASSERT_EQ(after.size(), Field(j, "events").size());
  for (size_t k = 0; k < before.size(); ++k) {
    EXPECT_EQ(before[k], Field(j, "events", k, "time").get<double>());
    EXPECT_EQ(after[k], before[k]);
  }
  // Samples at 2.5, 5, ..., 117.5.
  ASSERT_EQ(samples.size(), 47u);
  for (size_t k = 0; k < samples.size(); ++k) EXPECT_NEAR(samples[k], 2.5 * (k + 1), 1e-12);

  const auto log = ReadCsv(events);
  ASSERT_EQ(log.size(), Field(j, "events").size() + 1);
  EXPECT_EQ(log[0], (std::vector<std::string>{"time", "cause", "transitions", "label",
                                              "mode_before", "mode_after", "x_before", "x_after"}));
  EXPECT_EQ(log[1][1], "invariant");
  EXPECT_EQ(log[1][2], "switch_on");
  EXPECT_EQ(log[1][3], "heat");
  EXPECT_EQ(log[1][4], "off");
  EXPECT_EQ(log[1][5], "on");
  EXPECT_NEAR(std::stod(log[1][6]), 18.0, 1e-9);
  EXPECT_EQ(std::stod(log[1][0]), Field(j, "events", 0, "time").get<double>());
}

// --plot without --sample draws the ball from states between its bounces (the plot's own run),
// while the trace, the event log and the JSON summary stay those of the run without samples:
// byte for byte what the same command writes without --plot, and no "sample" rows.
TEST(HybridSimulate, PlotWithoutSampleIsDenseAndLeavesTheOtherOutputs) {
  TempDir dir;
  cli::SimulateArgs plain;
  plain.model = Spec("bouncing_ball");
  plain.out = dir.File("plain.csv");
  plain.events = dir.File("plain_events.csv");
  plain.json = true;
  cli::SimulateArgs plotted = plain;
  plotted.out = dir.File("plotted.csv");
  plotted.events = dir.File("plotted_events.csv");
  plotted.plot = dir.File("ball.svg");
  const InProcess a = SimulateHere(plain), b = SimulateHere(plotted);
  ASSERT_EQ(a.exit_code, 0);
  ASSERT_EQ(b.exit_code, 0);
  EXPECT_EQ(a.out, b.out);
  EXPECT_EQ(ReadAll(plain.out), ReadAll(plotted.out));
  EXPECT_EQ(ReadAll(plain.events), ReadAll(plotted.events));
  EXPECT_EQ(ReadAll(plotted.out).find(",sample,"), std::string::npos);
  // 34 bounces: the trace has the start, both sides of each and the end; the plot's height curve
  // more than kPlotSamples points.
  EXPECT_EQ(ReadCsv(plotted.out).size(), 1u + 2u + 2u * 34u);
  const std::string svg = ReadAll(plotted.plot);
  const auto points = svg.find("points=\"");
  ASSERT_NE(points, std::string::npos);
  const std::string first = svg.substr(points, svg.find('"', points + 8) - points);
  EXPECT_GT(std::count(first.begin(), first.end(), ','), cli::kPlotSamples);
}

// --set overrides a parameter: an object blocking link 1 at g = 80 (the finger's gob1) gives the
// closed form's events: contact at 80, theta3 at its minimum at 80 + (55 - 40) / 0.9, link 2 at
// its limit at 180, theta3 at its maximum half way to 255 (217.5).
TEST(HybridSimulate, SetOverridesAParameter) {
  const json j =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.parameters = {"gob1=80"};
        a.until = 255.0;
      }));
  EXPECT_EQ(Field(j, "status"), "completed");
  ASSERT_EQ(Field(j, "events").size(), 4u) << j.dump(2);
  const std::vector<double> times = {80.0, 80.0 + 15.0 / 0.9, 180.0, 217.5};
  for (size_t k = 0; k < times.size(); ++k) {
    EXPECT_NEAR(Field(j, "events", k, "time").get<double>(), times[k], 1e-6) << k;
  }
  // Bad --set values are option errors (exit 2) naming the option, in plain words.
  const Result unknown = Simulate(Quote(Spec("finger")) + " --set nope=1");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("--set nope"), std::string::npos) << unknown.err;
  EXPECT_EQ(unknown.err.find("::"), std::string::npos) << unknown.err;
  const Result bad = Simulate(Quote(Spec("finger")) + " --set gob1=abc");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--set gob1: 'abc' is not a decimal number"), std::string::npos)
      << bad.err;
  EXPECT_EQ(Simulate(Quote(Spec("finger")) + " --set gob1").exit_code, 2);
}

TEST(HybridSimulate, InputOverridesTheScenario) {
  // Close for 10 s only: no joint reaches a limit.
  const json j =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.inputs = {"u=step(0: 1, 10: 0)"};
        a.until = 50.0;
      }));
  ASSERT_EQ(Field(j, "status"), "completed");
  EXPECT_TRUE(Field(j, "events").empty());
  EXPECT_EQ(Field(j, "until"), 50.0);
  EXPECT_NEAR(Field(j, "final", "values", "g").get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(Field(j, "final", "values", "theta1").get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(Field(j, "final", "values", "theta3").get<double>(), -5.0, 1e-9);
  // A constant and a linear signal.
  const json c =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.inputs = {"u=0.5"};
        a.until = 20.0;
      }));
  EXPECT_NEAR(Field(c, "final", "values", "g").get<double>(), 10.0, 1e-9);
  const json l =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.inputs = {"u=linear(0: 0, 10: 1)"};
        a.until = 20.0;
      }));
  EXPECT_NEAR(Field(l, "final", "values", "g").get<double>(), 5.0 + 10.0, 1e-9);  // t^2/20, then t
  // The last --input for a name wins.
  const json last =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.inputs = {"u=1", "u=0.25"};
        a.until = 20.0;
      }));
  EXPECT_NEAR(Field(last, "final", "values", "g").get<double>(), 5.0, 1e-9);
}

TEST(HybridSimulate, InputCsvDrivesTheInputs) {
  TempDir dir;
  const std::string steps = dir.Write("steps.csv", "# close, then hold\ntime,u\n0,1\n10,0\n");
  const json j =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.input_csv = steps;
        a.until = 50.0;
      }));
  ASSERT_EQ(Field(j, "status"), "completed");
  EXPECT_NEAR(Field(j, "final", "values", "g").get<double>(), 10.0, 1e-9);
  const std::string ramp = dir.Write("ramp.csv", "time, u\n0, 0\n10, 1\n");
  const json l =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.input_csv = ramp;
        a.csv_shape = "linear";
        a.until = 20.0;
      }));
  EXPECT_NEAR(Field(l, "final", "values", "g").get<double>(), 15.0, 1e-9);
  // --input overrides the CSV.
  const json o =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("finger"), [&](cli::SimulateArgs& a) {
        a.inputs = {"u=0.5"};
        a.input_csv = steps;
        a.until = 20.0;
      }));
  EXPECT_NEAR(Field(o, "final", "values", "g").get<double>(), 10.0, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Bad input: exit 2 for a bad option value, 1 for a bad model or input file or an input the
// model refuses, a message naming the problem, no output files.

void ExpectRefused(const std::string& args, const std::string& needle, int exit_code = 1) {
  TempDir dir;
  const std::string trace = dir.File("trace.csv"), events = dir.File("events.csv");
  const Result r =
      Simulate(args + " --out " + Quote(trace) + " --events " + Quote(events) + " --json");
  EXPECT_EQ(r.exit_code, exit_code) << "hybrid simulate " << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos)
      << "hybrid simulate " << args << "\nstderr: " << r.err;
  EXPECT_EQ(r.out, "") << args;
  EXPECT_TRUE(dir.Files().empty()) << args << ": left " << dir.Files().front();
}

TEST(HybridSimulate, RefusesBadOptions) {
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --input v=1", "'v' is not an input of the model (inputs: u)", 2);
  ExpectRefused(thermostat + " --input u", "expected NAME=SIGNAL", 2);
  ExpectRefused(thermostat + " --input =1", "expected NAME=SIGNAL", 2);
  ExpectRefused(thermostat + " --until -1", "--until: the horizon must be positive and finite", 2);
  ExpectRefused(thermostat + " --until 0", "--until: the horizon must be positive and finite", 2);
  ExpectRefused(thermostat + " --until inf", "--until: 'inf' is not a decimal number", 2);
  ExpectRefused(thermostat + " --until nan", "--until: 'nan' is not a decimal number", 2);
  ExpectRefused(thermostat + " --sample -1", "--sample", 2);
  // Too many recorded states (it grew to 3.6 GB): refused before the run, naming the option.
  ExpectRefused(thermostat + " --sample 1e-9",
                "recording the state every 1e-09 (--sample) up to t = 120 (--until) would record",
                2);
  ExpectRefused(thermostat + " --input-csv x.csv --csv-shape cubic", "--csv-shape", 2);
  // Values the model refuses: exit 1.
  ExpectRefused(thermostat + " --input u=50", "outside its bounds [-20, 30]");
  ExpectRefused(thermostat + " --input " + Quote("u=step(0: 1, 5: -21)"), "outside its bounds");
  const std::string x = Quote(Spec("finger"));  // u in [-1, 1]
  ExpectRefused(x + " --input u=5", "outside its bounds [-1, 1]");
}

// Numbers are numbers: every numeric option and --set value in the one decimal syntax; an empty,
// hexadecimal, doubled-sign or trailing-garbage value is refused naming the option (exit 2).
TEST(HybridSimulate, RefusesMalformedNumbersNamingTheOption) {
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --until ''", "--until: empty", 2);
  ExpectRefused(thermostat + " --until 0x10", "--until: '0x10' is not a decimal number", 2);
  ExpectRefused(thermostat + " --until +-5", "--until: '+-5' is not a decimal number", 2);
  ExpectRefused(thermostat + " --until 5s", "--until: '5s' is not a decimal number", 2);
  ExpectRefused(thermostat + " --until 1e999", "--until: '1e999' is out of range", 2);
  ExpectRefused(thermostat + " --sample ''", "--sample: empty", 2);
  ExpectRefused(thermostat + " --sample 0x1p-3", "--sample: '0x1p-3' is not a decimal number", 2);
  ExpectRefused(thermostat + " --set a=", "--set a: empty", 2);
  ExpectRefused(thermostat + " --set a=0x10", "--set a: '0x10' is not a decimal number", 2);
  ExpectRefused(thermostat + " --set a=+-0.1", "--set a: '+-0.1' is not a decimal number", 2);
  ExpectRefused(thermostat + " --set a=inf", "--set a: 'inf' is not a decimal number", 2);
  // The same syntax accepted everywhere: a sign, digits, a fraction, an exponent.
  const json j = SimulateJson(thermostat + " --until +1.5e1 --sample 5. --set a=+.1");
  EXPECT_EQ(Field(j, "until"), 15.0);
}

TEST(HybridSimulate, RefusesMalformedSignalsWithTheirPosition) {
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --input " + Quote("u=step(1: 0, 0: 1)"),
                "--input u:1:12: signal times must increase strictly", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=step(0 1)"), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=ramp(0: 1)"), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u="), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=1 2"), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=0x10"), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=+-1"), "--input u:1:", 2);
  ExpectRefused(thermostat + " --input " + Quote("u=step(0: +-1)"), "--input u:1:", 2);
}

TEST(HybridSimulate, RefusesBadCsvFiles) {
  TempDir inputs;
  const std::string thermostat = Quote(Spec("thermostat"));
  const std::string cell = inputs.Write("cell.csv", "time,u\n0,1\n5,abc\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(cell), "(CSV row 3, column 2)");
  ExpectRefused(thermostat + " --input-csv " + Quote(cell), cell + ":3:2:");
  const std::string time = inputs.Write("time.csv", "time,u\n0,1\nsoon,2\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(time), "(CSV row 3, column 1)");
  const std::string header = inputs.Write("header.csv", "t,u\n0,1\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(header), "time,INPUT");
  const std::string name = inputs.Write("name.csv", "time,w\n0,1\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(name), "'w' is not an input");
  const std::string order = inputs.Write("order.csv", "time,u\n0,1\n5,2\n5,3\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(order), "increase strictly");
  const std::string ragged = inputs.Write("ragged.csv", "time,u\n0,1,2\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(ragged), "expected 2 cells, found 3");
  const std::string empty = inputs.Write("empty.csv", "time,u\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(empty), "no data rows");
  const std::string bounds = inputs.Write("bounds.csv", "time,u\n0,1\n5,99\n");
  ExpectRefused(thermostat + " --input-csv " + Quote(bounds), "outside its bounds");
  // CSV cells are numbers in the same decimal syntax as the options (no hexadecimal, no doubled
  // sign, no inf or nan, nothing empty).
  for (const std::string bad : {"0x10", "+-1", "inf", "nan", "", "1e999", "1 5"}) {
    const std::string file = inputs.Write("number.csv", "time,u\n0,1\n5," + bad + "\n");
    ExpectRefused(thermostat + " --input-csv " + Quote(file), file + ":3:2:");
  }
  const std::string signs = inputs.Write("signs.csv", "time,u\n+0,+1\n5.,-1e0\n");
  const json ok =
      SimulateJsonHere(ArgsOf<cli::SimulateArgs>(Spec("thermostat"), [&](cli::SimulateArgs& a) {
        a.input_csv = signs;
        a.until = 10.0;
      }));
  EXPECT_EQ(Field(ok, "status"), "completed");
  const std::string missing = (inputs.path() / "missing.csv").string();
  ExpectRefused(thermostat + " --input-csv " + Quote(missing), "cannot open input CSV");
}

TEST(HybridSimulate, RefusesAnInitialStateOutsideItsInvariant) {
  TempDir dir;
  const std::string model =
      dir.Write("cold.ha", testing::ReplaceOnce(testing::SpecText("thermostat"),
                                                "init off { x = 20; }", "init off { x = 17; }"));
  ExpectRefused(Quote(model), "the initial state violates the invariant 'x >= 18'");
}

// Outputs are checked before any work: two outputs naming one file, or an output naming the model
// or the input CSV, exit 2 naming both options, and no file is written or changed.
TEST(HybridSimulate, RefusesOutputsNamingOneFileOrAnInput) {
  TempDir dir;
  const std::string model = dir.Write("m.ha", testing::SpecText("thermostat"));
  const std::string csv = dir.Write("u.csv", "time,u\n0,1\n");
  const std::string kept = dir.Write("t.csv", "kept\n");
  std::filesystem::create_directory(dir.path() / "sub");
  const auto refused = [&](const std::string& args, const std::string& needle) {
    const Result r = Simulate(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << args;
    EXPECT_EQ(ReadAll(model), testing::SpecText("thermostat")) << args;
    EXPECT_EQ(ReadAll(csv), "time,u\n0,1\n") << args;
    EXPECT_EQ(ReadAll(kept), "kept\n") << args;
    EXPECT_EQ(dir.Files(), (std::vector<std::string>{"m.ha", "sub", "t.csv", "u.csv"})) << args;
  };
  refused(Quote(model) + " --out " + Quote(kept) + " --events " + Quote(kept),
          "--out and --events name the same file");
  // The same file under another name: "./", "..", a symbolic link.
  const std::string other = (dir.path() / "." / "sub" / ".." / "t.csv").string();
  refused(Quote(model) + " --out " + Quote(kept) + " --events " + Quote(other),
          "--out and --events name the same file");
  std::filesystem::create_symlink(kept, dir.path() / "link.csv");
  const Result via_link =
      Simulate(Quote(model) + " --out " + Quote(kept) + " --events " + Quote(dir.File("link.csv")));
  EXPECT_EQ(via_link.exit_code, 2) << via_link.err;
  EXPECT_EQ(ReadAll(kept), "kept\n");
  std::filesystem::remove(dir.path() / "link.csv");
  // Not yet existing files too.
  refused(Quote(model) + " --out " + Quote(dir.File("new.csv")) + " --events " +
              Quote((dir.path() / "." / "new.csv").string()),
          "--out and --events name the same file");
  refused(Quote(model) + " --out " + Quote(model), "--out '" + model + "' names the input MODEL");
  refused(Quote(model) + " --events " + Quote(model), "names the input MODEL");
  refused(Quote(model) + " --input-csv " + Quote(csv) + " --out " + Quote(csv),
          "names the input --input-csv");
  // Devices are not files: both outputs may go to /dev/null.
  const Result null = Simulate(Quote(model) + " --out /dev/null --events /dev/null");
  EXPECT_EQ(null.exit_code, 0) << null.err;
}

// A missing directory is found before the simulation, and nothing is written: the trajectory of
// a run whose event log cannot be written is not left behind.
TEST(HybridSimulate, OutputsAreAllOrNothing) {
  TempDir dir;
  const std::string trace = dir.File("trace.csv");
  const Result r = Simulate(Quote(Spec("thermostat")) + " --out " + Quote(trace) + " --events " +
                            Quote(dir.File("no_such_dir/events.csv")));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("--events"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_TRUE(dir.Files().empty()) << dir.Files().front();
  // An existing events file that cannot be replaced (a directory) leaves the trajectory alone.
  const std::string old_trace = dir.Write("trace.csv", "old\n");
  std::filesystem::create_directory(dir.path() / "events.csv");
  const Result d = Simulate(Quote(Spec("thermostat")) + " --out " + Quote(old_trace) +
                            " --events " + Quote(dir.File("events.csv")));
  EXPECT_EQ(d.exit_code, 3) << d.err;
  EXPECT_EQ(ReadAll(old_trace), "old\n");
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"events.csv", "trace.csv"}));
}

TEST(HybridSimulate, UnwritableOutputExitsThree) {
  TempDir dir;
  const Result r = Simulate(Quote(Spec("thermostat")) + " --out " +
                            Quote((dir.path() / "no_such_dir" / "trace.csv").string()));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
}

// ---------------------------------------------------------------------------------------------
// Runs that stop early: exit 5, status reported, outputs written.

TEST(HybridSimulate, ZenoRunExitsFiveAndWritesItsOutputs) {
  TempDir dir;
  const std::string model = dir.Write(
      "zeno.ha", testing::WithParameter(testing::SpecText("bouncing_ball"), "v_rest", "0"));
  const std::string trace = dir.File("trace.csv"), events = dir.File("events.csv");
  const json j = SimulateJsonHere(ArgsOf<cli::SimulateArgs>(model,
                                                            [&](cli::SimulateArgs& a) {
                                                              a.out = trace;
                                                              a.events = events;
                                                            }),
                                  5);
  EXPECT_EQ(Field(j, "status"), "zeno");
  EXPECT_NE(Field(j, "message").get<std::string>().find("accumulate"), std::string::npos);
  ASSERT_TRUE(j.contains("zeno"));
  const double tz = std::sqrt(2.0 * 10.0 / 9.81) * 1.8 / 0.2;
  EXPECT_NEAR(Field(j, "zeno", "accumulation_time").get<double>(), tz, 1e-9 * tz);
  EXPECT_EQ(Field(j, "zeno", "cycle"), json::array({"bounce"}));
  const auto rows = ReadCsv(trace);
  ASSERT_GT(rows.size(), 2u);
  EXPECT_EQ(rows.back()[1], "end");
  EXPECT_LT(std::stod(rows.back()[0]), tz);
  EXPECT_EQ(ReadCsv(events).size(), Field(j, "events").size() + 1);
  // The text summary says so too.
  const InProcess text = SimulateHere(ArgsOf<cli::SimulateArgs>(model));
  EXPECT_EQ(text.exit_code, 5);
  EXPECT_NE(text.out.find("status: zeno"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("zeno: events accumulate at t = "), std::string::npos) << text.out;
}

TEST(HybridSimulate, InvariantViolationExitsFiveAndWritesItsOutputs) {
  TempDir dir;
  const std::string model = dir.Write("stuck.ha", std::string(testing::kInvariantViolationModel));
  const std::string trace = dir.File("trace.csv");
  const json j = SimulateJsonHere(ArgsOf<cli::SimulateArgs>(model,
                                                            [&](cli::SimulateArgs& a) {
                                                              a.sample = 0.25;
                                                              a.out = trace;
                                                            }),
                                  5);
  EXPECT_EQ(Field(j, "status"), "invariant_violated");
  EXPECT_NE(Field(j, "message").get<std::string>().find("x <= 1"), std::string::npos)
      << Field(j, "message");
  EXPECT_NEAR(Field(j, "final", "time").get<double>(), 1.0, 1e-12);
  const auto rows = ReadCsv(trace);
  // Header, start, samples 0.25 .. 0.75, end: x' = 1 is a constant rate, so the boundary x = 1
  // is found exactly at t = 1, where the run stops before recording a sample there.
  ASSERT_EQ(rows.size(), 1u + 1u + 3u + 1u);
  EXPECT_EQ(rows.back()[1], "end");
  // Endless event iteration is Zeno too.
  const std::string ping = dir.Write("ping.ha", std::string(testing::kPingPongModel));
  const json z = SimulateJsonHere(ArgsOf<cli::SimulateArgs>(ping), 5);
  EXPECT_EQ(Field(z, "status"), "zeno");
  EXPECT_EQ(Field(z, "events").size(), 100u);
}

// ---------------------------------------------------------------------------------------------
// SpaceEx habits: the configuration's time-horizon, --config, --init (docs/spaceex.md).

const fs::path kFischerXml = kSourceDir / "spec" / "spaceex" / "fischer_2.xml";
const fs::path kFischerCfg = kSourceDir / "spec" / "spaceex" / "fischer_2.cfg";

// The number of the line `time-horizon = N` of the configuration text `cfg`, read here apart from
// the import (-1 and a test failure if there is none).
double TimeHorizonOf(const std::string& cfg) {
  std::istringstream in(cfg);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("time-horizon", 0) == 0) return std::stod(line.substr(line.find('=') + 1));
  }
  ADD_FAILURE() << "no time-horizon in:\n" << cfg;
  return -1.0;
}

// `cfg` with its time-horizon line replaced by `line`.
std::string WithHorizonLine(const std::string& cfg, const std::string& line) {
  const std::size_t start = cfg.find("time-horizon");
  EXPECT_NE(start, std::string::npos) << cfg;
  return cfg.substr(0, start) + line + cfg.substr(cfg.find('\n', start));
}

TEST(HybridSimulate, SpaceExHorizonIsTheConfigurationsTimeHorizon) {
  const double horizon = TimeHorizonOf(ReadAll(kFischerCfg));
  EXPECT_EQ(horizon, 100.0);  // spec/spaceex/fischer_2.cfg as written
  const json j = testing::RunHybridJson("simulate " + Quote(kFischerXml) + " --json");
  EXPECT_EQ(Field(j, "status"), "completed");
  EXPECT_EQ(Field(j, "until").get<double>(), horizon);
  EXPECT_EQ(Field(j, "final", "time").get<double>(), horizon);
  // Nothing fires in Fischer's protocol before it must: both clocks run from 0 to the horizon.
  EXPECT_EQ(Field(j, "final", "values", "P1.x").get<double>(), horizon);
  // An explicit --until wins.
  const json until =
      testing::RunHybridJson("simulate " + Quote(kFischerXml) + " --until 2.5 --json");
  EXPECT_EQ(Field(until, "until").get<double>(), 2.5);
  EXPECT_EQ(Field(until, "final", "time").get<double>(), 2.5);
}

TEST(HybridSimulate, ConfigSelectsAnotherConfiguration) {
  TempDir dir;
  const std::string cfg =
      dir.Write("short.cfg", WithHorizonLine(ReadAll(kFischerCfg), "time-horizon = 7.25")).string();
  const std::string config = " --config " + Quote(cfg);
  const json j = testing::RunHybridJson("simulate " + Quote(kFischerXml) + config + " --json");
  EXPECT_EQ(Field(j, "until").get<double>(), 7.25);
  EXPECT_EQ(Field(j, "final", "values", "P2.x").get<double>(), 7.25);
  // info and dot read it too: info prints the scenario and the property's horizon.
  const Result info = RunHybrid("info " + Quote(kFischerXml) + config);
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("until 7.25;"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("within 7.25;"), std::string::npos) << info.out;
  EXPECT_EQ(RunHybrid("dot " + Quote(kFischerXml) + config).exit_code, 0);
  // An output may not overwrite the configuration given.
  const Result overwrite =
      RunHybrid("simulate " + Quote(kFischerXml) + config + " -o " + Quote(cfg));
  EXPECT_EQ(overwrite.exit_code, 2);
  EXPECT_NE(overwrite.err.find("an output may not overwrite an input"), std::string::npos)
      << overwrite.err;
}

TEST(HybridSimulate, RefusesBadConfigurations) {
  TempDir dir;
  // Line 7, column 16: the value after "time-horizon = " in fischer_2.cfg's layout.
  const std::string original = ReadAll(kFischerCfg);
  const std::string bad =
      dir.Write("bad.cfg", WithHorizonLine(original, "time-horizon = soon")).string();
  int line = 1;
  for (std::size_t i = 0; i < original.find("time-horizon"); ++i) line += original[i] == '\n';
  ExpectRefused(Quote(kFischerXml) + " --config " + Quote(bad),
                bad + ":" + std::to_string(line) +
                    ":16: time-horizon: 'soon' is not a decimal number: give the time the "
                    "analysis covers as a positive number (negative: no bound)");
  ExpectRefused(Quote(kFischerXml) + " --config " + Quote(dir.File("none.cfg")),
                dir.File("none.cfg") + ":0:0: cannot read file");
  // A configuration belongs to a SpaceEx model only: exit 2, naming the option.
  ExpectRefused(Quote(Spec("thermostat")) + " --config " + Quote(kFischerCfg),
                "hybrid: --config names a SpaceEx configuration, read with a SpaceEx model (.xml) "
                "only, and MODEL '" +
                    Spec("thermostat") + "' is not one",
                2);
  // A negative time-horizon (SpaceEx's -1) sets no bound: a run needs --until.
  const std::string unbounded =
      dir.Write("unbounded.cfg", WithHorizonLine(original, "time-horizon = -1")).string();
  ExpectRefused(Quote(kFischerXml) + " --config " + Quote(unbounded),
                "no horizon: give one (--until) or declare a scenario in the model");
}

// x' = 1 - x / 2: x(t) = 2 + (x0 - 2) e^(-t/2), the closed form the runs are checked against.
constexpr const char* kDecay =
    "automaton decay {\n"
    "  var x in [-10, 10];\n"
    "  mode m { x' = -0.5 * x + 1; }\n"
    "  init m { x = 0; }\n"
    "  scenario { until 3; }\n"
    "}\n";

double Decay(double x0, double t) { return 2.0 + (x0 - 2.0) * std::exp(-t / 2.0); }

TEST(HybridSimulate, InitSetsTheInitialValueOfTheRun) {
  TempDir dir;
  const std::string model = Quote(dir.Write("decay.ha", kDecay));
  const json declared = testing::RunHybridJson("simulate " + model + " --json");
  EXPECT_NEAR(Field(declared, "final", "values", "x").get<double>(), Decay(0.0, 3.0), 1e-7);
  const json five = testing::RunHybridJson("simulate " + model + " --init x=5 --json");
  EXPECT_NEAR(Field(five, "final", "values", "x").get<double>(), Decay(5.0, 3.0), 1e-7);
  // The later value of a variable wins; the domain's ends are allowed.
  const json last = testing::RunHybridJson("simulate " + model + " --init x=5 --init x=-10 --json");
  EXPECT_NEAR(Field(last, "final", "values", "x").get<double>(), Decay(-10.0, 3.0), 1e-6);
  // In a composed system the names are qualified: A starts at 5, B as declared.
  const std::string system = Quote(dir.Write(
      "two.ha", std::string(kDecay) + "system two {\n  instance A = decay;\n  instance B = decay;\n"
                                      "  scenario { until 3; }\n}\n"));
  const json two = testing::RunHybridJson("simulate " + system + " --init A.x=5 --json");
  EXPECT_NEAR(Field(two, "final", "values", "A.x").get<double>(), Decay(5.0, 3.0), 1e-7);
  EXPECT_NEAR(Field(two, "final", "values", "B.x").get<double>(), Decay(0.0, 3.0), 1e-7);
  ExpectRefused(system + " --init x=1",
                "hybrid: --init: 'x' is not a continuous variable of the model; did you mean "
                "'A.x' or 'B.x'? (a composed system's names are qualified by the instance)",
                2);
}

TEST(HybridSimulate, RefusesBadInitialValues) {
  TempDir dir;
  const std::string model = Quote(dir.Write("decay.ha", kDecay));
  ExpectRefused(model + " --init y=1",
                "hybrid: --init: 'y' is not a continuous variable of the model; did you mean "
                "'x'?",
                2);
  ExpectRefused(model + " --init x=11",
                "hybrid: --init x: 11 lies outside the declared domain [-10, 10] of 'x'", 2);
  ExpectRefused(model + " --init x=-10.5",
                "hybrid: --init x: -10.5 lies outside the declared domain [-10, 10] of 'x'", 2);
  ExpectRefused(model + " --init x=nan", "hybrid: --init x: 'nan' is not a decimal number", 2);
  ExpectRefused(model + " --init x=1e999", "hybrid: --init x: '1e999' is out of range", 2);
  ExpectRefused(model + " --init x", "hybrid: --init 'x': expected NAME=VALUE", 2);
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --init u=1",
                "hybrid: --init: 'u' is an input, not a continuous variable (drive it with "
                "--input)",
                2);
}

}  // namespace
}  // namespace hybrid
