// Tests of `hybrid simulate` (HYBRID_BINARY): the bundled models run to completion, the JSON
// summary, the trajectory and event CSVs, input overrides from the command line and from a CSV
// file, every kind of bad input (exit 1, a clear message, no output file), and runs that stop
// early (exit 5, outputs still written).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_utilities/command_line.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::Quote;
using testing::ReadAll;
using testing::Result;
using testing::RunHybrid;
using testing::TempDir;

const fs::path kSourceDir = HYBRID_SOURCE_DIR;

std::string Spec(const std::string& name) {
  return (kSourceDir / "spec" / (name + ".ha")).string();
}

// Runs `hybrid simulate ARGS` through the shell (quote the arguments that need it).
Result Simulate(const std::string& args) { return RunHybrid("simulate " + args); }

json SimulateJson(const std::string& args, int expected_exit = 0) {
  return testing::RunHybridJson("simulate " + args, expected_exit);
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
    const Result r = Simulate(Quote(Spec(name)));
    EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.err << r.out;
    EXPECT_NE(r.out.find("status: completed"), std::string::npos) << name << "\n" << r.out;
    EXPECT_NE(r.out.find("final state:"), std::string::npos) << r.out;
  }
}

TEST(HybridSimulate, JsonHasStatusEventsAndStatesByName) {
  const json j = SimulateJson(Quote(Spec("finger")));
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["message"], "");
  EXPECT_EQ(j["until"], 530.0);
  ASSERT_EQ(j["events"].size(), 6u) << j.dump(2);
  const json& first = j["events"][0];
  EXPECT_NEAR(first["time"].get<double>(), 110.0, 1e-9);
  EXPECT_EQ(first["cause"], "crossing");
  EXPECT_EQ(first["transitions"], json::array({"t5_c000_l000_to_c000_l00n"}));
  EXPECT_EQ(first["mode_before"], "c000_l000");
  EXPECT_EQ(first["mode_after"], "c000_l00n");
  for (const char* v : {"theta1", "theta2", "theta3", "g"}) {
    EXPECT_TRUE(first["before"].contains(v)) << v;
    EXPECT_TRUE(first["after"].contains(v)) << v;
  }
  EXPECT_NEAR(first["before"]["theta3"].get<double>(), -55.0, 1e-8);
  EXPECT_NEAR(first["before"]["g"].get<double>(), 110.0, 1e-8);
  EXPECT_EQ(j["events"][3]["cause"], "enabled");  // u reverses at t = 265
  EXPECT_EQ(j["final"]["time"], 530.0);
  EXPECT_EQ(j["final"]["mode"], "c000_l000");
  EXPECT_NEAR(j["final"]["state"]["g"].get<double>(), 0.0, 1e-8);
  EXPECT_GE(j["steps"].get<long>(), 0);  // CVODE steps: none for constant-rate modes
  EXPECT_FALSE(j.contains("zeno"));
  // A composed model: qualified variable and mode names.
  const json hand = SimulateJson(Quote(Spec("hand")));
  EXPECT_EQ(hand["status"], "completed");
  EXPECT_TRUE(hand["final"]["state"].contains("B.theta2"));
  EXPECT_EQ(hand["events"][0]["transitions"], json::array({"A.t5_c000_l000_to_c000_l00n"}));
}

TEST(HybridSimulate, TraceCsvHasEveryEventAndSample) {
  TempDir dir;
  const std::string trace = dir.File("trace.csv"), events = dir.File("events.csv");
  const json j = SimulateJson(Quote(Spec("thermostat")) + " --sample 2.5 --out " + Quote(trace) +
                              " --events " + Quote(events));
  ASSERT_EQ(j["status"], "completed");
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
  ASSERT_EQ(before.size(), j["events"].size());
  ASSERT_EQ(after.size(), j["events"].size());
  for (size_t k = 0; k < before.size(); ++k) {
    EXPECT_EQ(before[k], j["events"][k]["time"].get<double>());
    EXPECT_EQ(after[k], before[k]);
  }
  // Samples at 2.5, 5, ..., 117.5.
  ASSERT_EQ(samples.size(), 47u);
  for (size_t k = 0; k < samples.size(); ++k) EXPECT_NEAR(samples[k], 2.5 * (k + 1), 1e-12);

  const auto log = ReadCsv(events);
  ASSERT_EQ(log.size(), j["events"].size() + 1);
  EXPECT_EQ(log[0], (std::vector<std::string>{"time", "cause", "transitions", "label",
                                              "mode_before", "mode_after", "x_before", "x_after"}));
  EXPECT_EQ(log[1][1], "invariant");
  EXPECT_EQ(log[1][2], "switch_on");
  EXPECT_EQ(log[1][3], "heat");
  EXPECT_EQ(log[1][4], "off");
  EXPECT_EQ(log[1][5], "on");
  EXPECT_NEAR(std::stod(log[1][6]), 18.0, 1e-9);
  EXPECT_EQ(std::stod(log[1][0]), j["events"][0]["time"].get<double>());
}

// --set overrides a parameter: an object blocking link 1 at g = 80 (the finger's gob1) gives the
// closed form's events: contact at 80, theta3 at its minimum at 80 + (55 - 40) / 0.9, link 2 at
// its limit at 180, theta3 at its maximum half way to 255 (217.5).
TEST(HybridSimulate, SetOverridesAParameter) {
  const json j = SimulateJson(Quote(Spec("finger")) + " --set gob1=80 --until 255");
  EXPECT_EQ(j["status"], "completed");
  ASSERT_EQ(j["events"].size(), 4u) << j.dump(2);
  const std::vector<double> times = {80.0, 80.0 + 15.0 / 0.9, 180.0, 217.5};
  for (size_t k = 0; k < times.size(); ++k) {
    EXPECT_NEAR(j["events"][k]["time"].get<double>(), times[k], 1e-6) << k;
  }
  const Result unknown = Simulate(Quote(Spec("finger")) + " --set nope=1");
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("--set nope"), std::string::npos) << unknown.err;
  const Result bad = Simulate(Quote(Spec("finger")) + " --set gob1=abc");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("not a finite number"), std::string::npos) << bad.err;
  EXPECT_EQ(Simulate(Quote(Spec("finger")) + " --set gob1").exit_code, 1);
}

TEST(HybridSimulate, InputOverridesTheScenario) {
  // Close for 10 s only: no joint reaches a limit.
  const json j = SimulateJson(Quote(Spec("finger")) + " --input " + Quote("u=step(0: 1, 10: 0)") +
                              " --until 50");
  ASSERT_EQ(j["status"], "completed");
  EXPECT_TRUE(j["events"].empty());
  EXPECT_EQ(j["until"], 50.0);
  EXPECT_NEAR(j["final"]["state"]["g"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["final"]["state"]["theta1"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(j["final"]["state"]["theta3"].get<double>(), -5.0, 1e-9);
  // A constant and a linear signal.
  const json c = SimulateJson(Quote(Spec("finger")) + " --input u=0.5 --until 20");
  EXPECT_NEAR(c["final"]["state"]["g"].get<double>(), 10.0, 1e-9);
  const json l = SimulateJson(Quote(Spec("finger")) + " --input " + Quote("u=linear(0: 0, 10: 1)") +
                              " --until 20");
  EXPECT_NEAR(l["final"]["state"]["g"].get<double>(), 5.0 + 10.0, 1e-9);  // t^2/20, then t
  // The last --input for a name wins.
  const json last = SimulateJson(Quote(Spec("finger")) + " --input u=1 --input u=0.25 --until 20");
  EXPECT_NEAR(last["final"]["state"]["g"].get<double>(), 5.0, 1e-9);
}

TEST(HybridSimulate, InputCsvDrivesTheInputs) {
  TempDir dir;
  const std::string steps = dir.Write("steps.csv", "# close, then hold\ntime,u\n0,1\n10,0\n");
  const json j =
      SimulateJson(Quote(Spec("finger")) + " --input-csv " + Quote(steps) + " --until 50");
  ASSERT_EQ(j["status"], "completed");
  EXPECT_NEAR(j["final"]["state"]["g"].get<double>(), 10.0, 1e-9);
  const std::string ramp = dir.Write("ramp.csv", "time, u\n0, 0\n10, 1\n");
  const json l = SimulateJson(Quote(Spec("finger")) + " --input-csv " + Quote(ramp) +
                              " --csv-shape linear --until 20");
  EXPECT_NEAR(l["final"]["state"]["g"].get<double>(), 15.0, 1e-9);
  // --input overrides the CSV.
  const json o = SimulateJson(Quote(Spec("finger")) + " --input-csv " + Quote(steps) +
                              " --input u=0.5 --until 20");
  EXPECT_NEAR(o["final"]["state"]["g"].get<double>(), 10.0, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Bad input: exit 1, a message naming the problem, no output files.

void ExpectRefused(const std::string& args, const std::string& needle) {
  TempDir dir;
  const std::string trace = dir.File("trace.csv"), events = dir.File("events.csv");
  const Result r =
      Simulate(args + " --out " + Quote(trace) + " --events " + Quote(events) + " --json");
  EXPECT_EQ(r.exit_code, 1) << "hybrid simulate " << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos)
      << "hybrid simulate " << args << "\nstderr: " << r.err;
  EXPECT_EQ(r.out, "") << args;
  EXPECT_TRUE(dir.Files().empty()) << args << ": left " << dir.Files().front();
}

TEST(HybridSimulate, RefusesBadOptions) {
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --input v=1", "'v' is not an input of the model (inputs: u)");
  ExpectRefused(thermostat + " --input u", "expected NAME=SIGNAL");
  ExpectRefused(thermostat + " --input =1", "expected NAME=SIGNAL");
  ExpectRefused(thermostat + " --until -1", "horizon must be positive and finite");
  ExpectRefused(thermostat + " --until 0", "horizon must be positive and finite");
  ExpectRefused(thermostat + " --until inf", "horizon must be positive and finite");
  ExpectRefused(thermostat + " --until nan", "horizon must be positive and finite");
  ExpectRefused(thermostat + " --input u=50", "outside its bounds [-20, 30]");
  ExpectRefused(thermostat + " --input " + Quote("u=step(0: 1, 5: -21)"), "outside its bounds");
  ExpectRefused(thermostat + " --sample -1", "--sample");
  ExpectRefused(thermostat + " --input-csv x.csv --csv-shape cubic", "--csv-shape");
  const std::string x = Quote(Spec("finger"));  // u in [-1, 1]
  ExpectRefused(x + " --input u=5", "outside its bounds [-1, 1]");
}

TEST(HybridSimulate, RefusesMalformedSignalsWithTheirPosition) {
  const std::string thermostat = Quote(Spec("thermostat"));
  ExpectRefused(thermostat + " --input " + Quote("u=step(1: 0, 0: 1)"),
                "--input u:1:12: signal times must increase strictly");
  ExpectRefused(thermostat + " --input " + Quote("u=step(0 1)"), "--input u:1:");
  ExpectRefused(thermostat + " --input " + Quote("u=ramp(0: 1)"), "--input u:1:");
  ExpectRefused(thermostat + " --input " + Quote("u="), "--input u:1:");
  ExpectRefused(thermostat + " --input " + Quote("u=1 2"), "--input u:1:");
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
  const json j =
      SimulateJson(Quote(model) + " --out " + Quote(trace) + " --events " + Quote(events), 5);
  EXPECT_EQ(j["status"], "zeno");
  EXPECT_NE(j["message"].get<std::string>().find("accumulate"), std::string::npos);
  ASSERT_TRUE(j.contains("zeno"));
  const double tz = std::sqrt(2.0 * 10.0 / 9.81) * 1.8 / 0.2;
  EXPECT_NEAR(j["zeno"]["accumulation_time"].get<double>(), tz, 1e-9 * tz);
  EXPECT_EQ(j["zeno"]["cycle"], json::array({"bounce"}));
  const auto rows = ReadCsv(trace);
  ASSERT_GT(rows.size(), 2u);
  EXPECT_EQ(rows.back()[1], "end");
  EXPECT_LT(std::stod(rows.back()[0]), tz);
  EXPECT_EQ(ReadCsv(events).size(), j["events"].size() + 1);
  // The text summary says so too.
  const Result text = Simulate(Quote(model));
  EXPECT_EQ(text.exit_code, 5);
  EXPECT_NE(text.out.find("status: zeno"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("zeno: events accumulate at t = "), std::string::npos) << text.out;
}

TEST(HybridSimulate, InvariantViolationExitsFiveAndWritesItsOutputs) {
  TempDir dir;
  const std::string model = dir.Write("stuck.ha", std::string(testing::kInvariantViolationModel));
  const std::string trace = dir.File("trace.csv");
  const json j = SimulateJson(Quote(model) + " --sample 0.25 --out " + Quote(trace), 5);
  EXPECT_EQ(j["status"], "invariant_violated");
  EXPECT_NE(j["message"].get<std::string>().find("x <= 1"), std::string::npos) << j["message"];
  EXPECT_NEAR(j["final"]["time"].get<double>(), 1.0, 1e-12);
  const auto rows = ReadCsv(trace);
  // Header, start, samples 0.25 .. 0.75, end: x' = 1 is a constant rate, so the boundary x = 1
  // is found exactly at t = 1, where the run stops before recording a sample there.
  ASSERT_EQ(rows.size(), 1u + 1u + 3u + 1u);
  EXPECT_EQ(rows.back()[1], "end");
  // Endless event iteration is Zeno too.
  const std::string ping = dir.Write("ping.ha", std::string(testing::kPingPongModel));
  const json z = SimulateJson(Quote(ping), 5);
  EXPECT_EQ(z["status"], "zeno");
  EXPECT_EQ(z["events"].size(), 100u);
}

}  // namespace
}  // namespace hybrid
