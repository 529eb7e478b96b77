// End-to-end tests of `hybrid finger` and `hybrid hand` (HYBRID_BINARY;
// gripper/commands/gripper_command.cc, docs/finger_model.md): the closed form of section 4 through
// the command line (free-space table 4.1, a link-1 contact given as gob1), objects given by
// geometry (the analytic contact position of a circle), --simulate agreeing with the closed form,
// the SVG outputs, the hand's three fingers, and every kind of bad input (exit 2 for bad options,
// malformed numbers and object descriptions and outputs naming one file, 1 for objects the gripper
// cannot hold, 3 for unwritable outputs; a message on stderr, nothing on stdout, no file left
// behind or changed).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_utilities/command_line.h"
#include "tests/test_utilities/robotiq_rig.h"

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

json RunJson(const std::string& args, int expected_exit = 0) {
  return testing::RunHybridJson(args, expected_exit);
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A rejected run: exit code `code` (never a crash: a signal shows as 128 + N through the shell),
// nothing on standard output, and a message on stderr containing each of `parts`.
void ExpectRejected(const std::string& args, int code, const std::vector<std::string>& parts) {
  const Result r = RunHybrid(args);
  EXPECT_EQ(r.exit_code, code) << "hybrid " << args << "\nstderr: " << r.err;
  EXPECT_LT(r.exit_code, 128) << "hybrid " << args;
  EXPECT_EQ(r.out, "") << "hybrid " << args;
  EXPECT_FALSE(r.err.empty()) << "hybrid " << args;
  for (const std::string& part : parts) {
    EXPECT_TRUE(Contains(r.err, part))
        << "hybrid " << args << "\nstderr lacks '" << part << "': " << r.err;
  }
}

// A complete SVG document.
void ExpectSvg(const fs::path& path) {
  const std::string svg = ReadAll(path);
  ASSERT_FALSE(svg.empty()) << path;
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << path << ": " << svg.substr(0, 80);
  const std::string end = "</svg>\n";
  ASSERT_GE(svg.size(), end.size());
  EXPECT_EQ(svg.substr(svg.size() - end.size()), end) << path;
}

double Deg(double radians) { return radians * 180.0 / std::numbers::pi; }
double Rad(double degrees) { return degrees * std::numbers::pi / 180.0; }

// "circle:X,Y,R" with every digit of the doubles (17 significant digits).
std::string Circle(double x, double y, double r) {
  std::ostringstream s;
  s.precision(17);
  s << "circle:" << x << "," << y << "," << r;
  return s.str();
}

// A circle of radius 5 mm whose centre is at distance 0.04 m from joint 1, 40 degrees from +y
// towards +x (the closing direction). Link 1 (0.05715 m, along theta1 from +y) is tangent to it
// when theta1 = 40 - asin(0.005 / 0.04): before theta1 reaches its limit (phase 1, m1 = 0.5), so
// gob1 = 2 (40 - asin(0.125)).
constexpr double kRho = 0.04, kAlphaDeg = 40.0, kRadius = 0.005;
std::string Link1Circle() {
  return Circle(kRho * std::sin(Rad(kAlphaDeg)), kRho * std::cos(Rad(kAlphaDeg)), kRadius);
}
double Link1CircleGob1() { return 2.0 * (kAlphaDeg - Deg(std::asin(kRadius / kRho))); }

const std::string kHandObject = "circle:0,0.06,0.02";  // centred between the fingers

// ---------------------------------------------------------------------------------------------
// The closed form (section 4) through `hybrid finger`.

// Phase 1' of table 4.1: at g = 120 theta1 = m1 g = 60 and link 3 is at its lower limit.
TEST(HybridFinger, TextAtG120IsPhase1Prime) {
  const Result r = RunHybrid("finger --g 120");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(Contains(r.out, "phase 1'")) << r.out;
  EXPECT_TRUE(Contains(r.out, "state c000_l00n")) << r.out;
  EXPECT_TRUE(Contains(r.out, "theta1 = 60.000000 deg")) << r.out;
  EXPECT_TRUE(Contains(r.out, "theta2 = 0.000000 deg")) << r.out;
  EXPECT_TRUE(Contains(r.out, "theta3 = -55.000000 deg")) << r.out;
  EXPECT_TRUE(Contains(r.out, "contacts: none")) << r.out;
  EXPECT_TRUE(Contains(r.out, "stops at g = 240")) << r.out;  // the palm (D3)
}

// The JSON report's keys: angles in degrees, the motor, phase, automaton state, contacts, stop.
TEST(HybridFinger, JsonAtG120HasEveryKey) {
  const json j = RunJson("finger --g 120");
  EXPECT_EQ(Field(j, "theta1"), 60.0);
  EXPECT_EQ(Field(j, "theta2"), 0.0);
  EXPECT_EQ(Field(j, "theta3"), -55.0);
  EXPECT_EQ(Field(j, "motor"), 120.0);
  EXPECT_EQ(Field(j, "phase"), "1'");
  EXPECT_EQ(Field(j, "mode"), "c000_l00n");
  EXPECT_EQ(Field(j, "discrete"),
            (json{{"c1", 0}, {"c2", 0}, {"c3", 0}, {"l1", 0}, {"l2", 0}, {"l3", -1}}));
  ASSERT_TRUE(Field(j, "contacts").is_array());
  EXPECT_TRUE(Field(j, "contacts").empty());
  EXPECT_EQ(Field(j, "stop"), 240.0);
}

// Table 4.1 (free space): theta1 = min(0.5 g, 70), theta2 = clamp(0.9 (g - 140), 0, 90),
// theta3 = max(-0.5 g, -55); the motor stops at 240 against the palm (C4, D3).
TEST(HybridFinger, FreeSpaceTableOfSection41) {
  for (double g : {0.0, 55.0, 110.0, 125.0, 140.0, 190.0, 240.0, 250.0}) {
    const json j = RunJson("finger --g " + std::to_string(g));
    SCOPED_TRACE("g = " + std::to_string(g));
    EXPECT_NEAR(Field(j, "theta1").get<double>(), std::min(0.5 * g, 70.0), 1e-9);
    EXPECT_NEAR(Field(j, "theta2").get<double>(), std::clamp(0.9 * (g - 140.0), 0.0, 90.0), 1e-9);
    EXPECT_NEAR(Field(j, "theta3").get<double>(), std::max(-0.5 * g, -55.0), 1e-9);
    EXPECT_NEAR(Field(j, "motor").get<double>(), std::min(g, 240.0), 1e-9);
    EXPECT_TRUE(Field(j, "contacts").empty());
  }
}

// Section 4.2, link 1 blocked at gob1 = 80 (theta1 = 40): link 2 reaches its limit at g = 180
// with theta3 at its minimum, then theta3 = -55 + 98 (g - 180) / (255 - g), reaching 43 (and
// stopping) half way between 180 and 255 (C3).
TEST(HybridFinger, Link1ContactFollowsTheContactTable) {
  const json j = RunJson("finger --gob1 80 --g 200");
  EXPECT_NEAR(Field(j, "theta1").get<double>(), 40.0, 1e-9);
  EXPECT_NEAR(Field(j, "theta2").get<double>(), 90.0, 1e-9);
  EXPECT_NEAR(Field(j, "theta3").get<double>(), -55.0 + 98.0 * (200.0 - 180.0) / (255.0 - 200.0),
              1e-9);
  EXPECT_EQ(Field(j, "phase"), "3");
  EXPECT_EQ(Field(j, "discrete", "c1"), 1);
  EXPECT_EQ(Field(j, "discrete", "l2"), 1);
  EXPECT_NEAR(Field(j, "stop").get<double>(), 217.5, 1e-9);
  ASSERT_EQ(Field(j, "contacts").size(), 1u) << j.dump(2);
  EXPECT_EQ(Field(j, "contacts", 0, "link"), 1);
  EXPECT_EQ(Field(j, "contacts", 0, "g"), 80.0);
  EXPECT_EQ(Field(j, "contacts", 0, "by"), "given");
}

// ---------------------------------------------------------------------------------------------
// Objects by geometry.

// A circle tangent to link 1: the contact is found at the analytic motor position (to 1e-6
// counts; GeometricFinger bisects to 1e-10) and attributed to the object.
TEST(HybridFinger, CircleBlocksLink1AtTheAnalyticPosition) {
  const json j = RunJson("finger --g 255 --object " + Link1Circle());
  ASSERT_EQ(Field(j, "contacts").size(), 1u) << j.dump(2);
  const json& c = Field(j, "contacts", 0);
  EXPECT_EQ(Field(c, "link"), 1);
  EXPECT_EQ(Field(c, "by"), "object 1");
  EXPECT_NEAR(Field(c, "g").get<double>(), Link1CircleGob1(), 1e-6);
  EXPECT_NEAR(Field(j, "theta1").get<double>(), 0.5 * Link1CircleGob1(), 1e-6);
  EXPECT_EQ(Field(j, "discrete", "c1"), 1);
  ASSERT_EQ(Field(j, "objects").size(), 1u);
  // Link 2 then reaches its limit 100 counts later and phase 3 ends half way to 255 (C3).
  EXPECT_NEAR(Field(j, "stop").get<double>(), (Link1CircleGob1() + 100.0 + 255.0) / 2.0, 1e-6);
  // The text form names the object too.
  const Result r = RunHybrid("finger --g 255 --object " + Link1Circle());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Contains(r.out, "link 1 at g = ")) << r.out;
  EXPECT_TRUE(Contains(r.out, "(object 1)")) << r.out;
}

// ---------------------------------------------------------------------------------------------
// --simulate: the automaton (spec/finger.ha, with contact guards given by gob or by distance)
// closing at u = 1 equals the closed form within 1e-6 degrees.

TEST(HybridFinger, SimulationAgreesWithAGivenContact) {
  const Result r = RunHybrid("finger --gob1 80 --g 200 --simulate");
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(Contains(r.out, "agrees")) << r.out;
  EXPECT_FALSE(Contains(r.out, "DISAGREES")) << r.out;
  const json j = RunJson("finger --gob1 80 --g 200 --simulate");
  EXPECT_EQ(Field(j, "simulation", "status"), "completed");
  EXPECT_EQ(Field(j, "simulation", "agrees"), true);
  EXPECT_LE(Field(j, "simulation", "max_angle_difference_deg").get<double>(), 1e-6);
  ASSERT_EQ(Field(j, "simulation", "contacts").size(), 1u) << j.dump(2);
  EXPECT_EQ(Field(j, "simulation", "contacts", 0, "link"), 1);
  EXPECT_NEAR(Field(j, "simulation", "contacts", 0, "g").get<double>(), 80.0, 1e-6);
}

TEST(HybridFinger, SimulationAgreesWithAnObject) {
  const Result r = RunHybrid("finger --g 255 --object " + Link1Circle() + " --simulate");
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(Contains(r.out, "agrees")) << r.out;
  EXPECT_FALSE(Contains(r.out, "DISAGREES")) << r.out;
  const json j = RunJson("finger --g 255 --object " + Link1Circle() + " --simulate");
  EXPECT_EQ(Field(j, "simulation", "status"), "completed");
  EXPECT_EQ(Field(j, "simulation", "agrees"), true);
  EXPECT_LE(Field(j, "simulation", "max_angle_difference_deg").get<double>(), 1e-6);
  ASSERT_EQ(Field(j, "simulation", "contacts").size(), 1u) << j.dump(2);
  EXPECT_NEAR(Field(j, "simulation", "contacts", 0, "g").get<double>(), Link1CircleGob1(), 1e-6);
}

// ---------------------------------------------------------------------------------------------
// SVG outputs.

// --draw (panels at --at) and --plot each write a whole SVG document; nothing else is created.
TEST(HybridFinger, DrawAndPlotWriteSvg) {
  TempDir dir;
  const Result d = RunHybrid("finger --draw " + Quote(dir.File("finger.svg")) + " --at 0,110,240");
  EXPECT_EQ(d.exit_code, 0) << d.err;
  ExpectSvg(dir.File("finger.svg"));
  const Result p = RunHybrid("finger --plot " + Quote(dir.File("plot.svg")));
  EXPECT_EQ(p.exit_code, 0) << p.err;
  ExpectSvg(dir.File("plot.svg"));
  // With an object and a given g too.
  const Result o =
      RunHybrid("finger --g 100 --object " + Link1Circle() + " --draw " +
                Quote(dir.File("object.svg")) + " --plot " + Quote(dir.File("object_plot.svg")));
  EXPECT_EQ(o.exit_code, 0) << o.err;
  ExpectSvg(dir.File("object.svg"));
  ExpectSvg(dir.File("object_plot.svg"));
  EXPECT_EQ(dir.Files(),
            (std::vector<std::string>{"finger.svg", "object.svg", "object_plot.svg", "plot.svg"}));
}

// An output that cannot be written: exit 3, a message naming the path, nothing left behind (the
// write is atomic: no temporary file either), nothing on stdout.
TEST(HybridFinger, UnwritableOutputIsExit3AndLeavesNoFile) {
  TempDir dir;
  const std::string missing = dir.File("no_such_dir/out.svg");
  ExpectRejected("finger --draw " + Quote(missing) + " --at 0,110,240", 3, {"cannot write"});
  ExpectRejected("finger --plot " + Quote(missing), 3, {"cannot write"});
  ExpectRejected("finger --g 100 --json --draw " + Quote(missing), 3, {"cannot write"});
  EXPECT_TRUE(dir.Files().empty());
  // The target is an existing directory.
  fs::create_directory(dir.path() / "a_directory");
  ExpectRejected("finger --plot " + Quote(dir.File("a_directory")), 3, {"cannot write"});
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"a_directory"});
  EXPECT_TRUE(fs::is_empty(dir.path() / "a_directory"));
}

// A run that fails on its second output leaves the first output's existing file untouched (the
// outputs are renamed into place only when all are written).
TEST(HybridFinger, FailedRunKeepsExistingFiles) {
  TempDir dir;
  const std::string keep = dir.File("keep.svg");
  { std::ofstream(keep) << "OLD"; }
  ExpectRejected(
      "finger --g 10 --draw " + Quote(keep) + " --plot " + Quote(dir.File("no_such_dir/p.svg")), 3,
      {"cannot write"});
  EXPECT_EQ(ReadAll(keep), "OLD");
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"keep.svg"});  // no temporaries left
}

// Two outputs naming one file, or an output naming the model --simulate reads, are refused before
// any work (exit 2 naming both options); the existing file keeps its content.
TEST(HybridFinger, OutputsNamingOneFileOrTheModelAreRefused) {
  TempDir dir;
  const std::string f = dir.Write("f.svg", "OLD");
  ExpectRejected("finger --g 10 --draw " + Quote(f) + " --plot " + Quote(f), 2,
                 {"--draw and --plot name the same file"});
  ExpectRejected("finger --g 10 --draw " + Quote(f) + " --plot " +
                     Quote((dir.path() / "." / "f.svg").string()),
                 2, {"--draw and --plot name the same file"});
  EXPECT_EQ(ReadAll(f), "OLD");
  const std::string model = dir.Write("finger.ha", ReadAll(HYBRID_SOURCE_DIR "/spec/finger.ha"));
  ExpectRejected("finger --g 10 --simulate --model " + Quote(model) + " --plot " + Quote(model), 2,
                 {"--plot", "names the input --model"});
  EXPECT_EQ(ReadAll(model), ReadAll(HYBRID_SOURCE_DIR "/spec/finger.ha"));
  ExpectRejected("hand --simulate --model " + Quote(model) + " --draw " + Quote(model), 2,
                 {"--draw", "names the input --model"});
  EXPECT_EQ(ReadAll(model), ReadAll(HYBRID_SOURCE_DIR "/spec/finger.ha"));
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"f.svg", "finger.ha"}));
}

// A given contact position that is never reached (link 1 is at its limit from g = 140) does not
// take effect and is not listed.
TEST(HybridFinger, ContactsListOnlyThoseThatTakeEffect) {
  const json j = RunJson("finger --g 255 --gob1 200");
  EXPECT_TRUE(Field(j, "contacts").empty()) << j.dump(2);
  EXPECT_EQ(Field(j, "mode"), "c000_l11n");
  EXPECT_EQ(Field(RunJson("finger --g 255 --gob1 100"), "contacts").size(), 1u);
}

// --simulate with a model that is not a finger automaton: exit 1, naming the file.
TEST(HybridFinger, SimulateWithAModelThatIsNotAFingerIsExit1) {
  const std::string spec = std::string(HYBRID_SOURCE_DIR) + "/spec/";
  ExpectRejected("finger --g 10 --gob1 5 --simulate --model " + Quote(spec + "thermostat.ha"), 1,
                 {"thermostat.ha", "not a finger model", "theta1"});
  ExpectRejected("finger --g 10 --simulate --model " + Quote(spec + "hand.ha"), 1,
                 {"hand.ha", "not a finger model"});
  ExpectRejected("hand --simulate --model " + Quote(spec + "bouncing_ball.ha"), 1,
                 {"bouncing_ball.ha", "no automaton named 'finger'"});
}

// --model sets the closed form's constants: a finger whose link 2 ends at 80 degrees and whose
// link 3 reaches its limit 0.3 of the way from where link 2 stopped to 255. The simulation of that
// model agrees with that closed form.
TEST(HybridFinger, ModelSetsTheClosedFormsConstants) {
  TempDir dir;
  std::string text = ReadAll(HYBRID_SOURCE_DIR "/spec/finger.ha");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"param theta2_max [deg] = 90;",
                                            "param theta2_max [deg] = 80;"},
        {"param theta3_fraction = 0.5;", "param theta3_fraction = 0.3;"}}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  const std::string model = Quote(dir.Write("changed.ha", text));
  // Free: link 2 at m2 = 0.8 deg per count.
  EXPECT_NEAR(Field(RunJson("finger --model " + model + " --g 200"), "theta2").get<double>(), 48.0,
              1e-9);
  // Link 1 blocked at 30: link 2 stops at 130, the finger at 130 + 0.3 (255 - 130) = 167.5.
  const json j = RunJson("finger --model " + model + " --gob1 30 --g 200 --simulate");
  EXPECT_NEAR(Field(j, "stop").get<double>(), 167.5, 1e-9) << j.dump(2);
  EXPECT_EQ(Field(j, "simulation", "agrees"), true) << j.dump(2);
  // Without --model: the report's constants.
  EXPECT_NEAR(Field(RunJson("finger --g 200"), "theta2").get<double>(), 54.0, 1e-9);
}

// --requests: the settled state after each request of a history that closes past the stop and
// reopens, against the independent rig (motor min(request, stop), the rig's angles), with an
// object on link 1 and with a model whose theta3 fraction is 0.3; the firmware status is 2
// while the request is at or past the stop, 3 otherwise.
TEST(HybridFinger, RequestHistoryFollowsTheIndependentRig) {
  TempDir dir;
  std::string text = ReadAll(HYBRID_SOURCE_DIR "/spec/finger.ha");
  const std::string from = "param theta3_fraction = 0.5;";
  text.replace(text.find(from), from.size(), "param theta3_fraction = 0.3;");
  const std::string model = Quote(dir.Write("fraction.ha", text));
  const std::vector<double> requests = {60, 150, 255, 240, 200, 170, 120, 0};
  testing::RigFinger finger;
  finger.theta3_fraction = 0.3;
  testing::RigObject object;
  object.gob1 = 80;
  const auto rig = testing::RigRun(requests, finger, object, {}, {});
  const json j =
      RunJson("finger --model " + model + " --gob1 80 --requests 60,150,255,240,200,170,120,0");
  const json& history = Field(j, "requests");
  ASSERT_EQ(history.size(), requests.size()) << j.dump(2);
  const double stop = testing::RigStopPosition(finger, object);
  for (size_t k = 0; k < requests.size(); ++k) {
    SCOPED_TRACE("request " + std::to_string(requests[k]));
    EXPECT_EQ(history[k]["request"].get<double>(), requests[k]);
    EXPECT_NEAR(history[k]["motor"].get<double>(), std::min(requests[k], stop), 1e-9);
    EXPECT_EQ(history[k]["status"].get<int>(), requests[k] >= stop ? 2 : 3);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(history[k]["theta" + std::to_string(i + 1)].get<double>(), rig[k].theta[i], 1e-9);
    }
  }
  const Result bad = RunHybrid("finger --requests 10,256");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--requests must be a motor position in [0, 255] (got 256)"),
            std::string::npos)
      << bad.err;
}

// --data overlays the runs measured with the finger's object on --plot: the demo's runs against
// link 1 at 80 (two of them), dots in the plot; another object, no --plot, or --plot naming
// the data are refused.
TEST(HybridFinger, DataOverlaysTheRunsWithTheFingersObject) {
  TempDir dir;
  const std::string data = Quote(std::string(HYBRID_SOURCE_DIR) + "/data/finger_demo.csv");
  const std::string plot = (dir.path() / "p.svg").string();
  const Result r = RunHybrid("finger --gob1 80 --plot " + Quote(plot) + " --data " + data);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string svg = ReadAll(plot);
  EXPECT_NE(svg.find(">(2 runs)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">g_ob link 1 = 80</text>"), std::string::npos);
  const Result other = RunHybrid("finger --gob1 81 --plot " + Quote(plot) + " --data " + data);
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("no run has the finger's object (gob1 = 81)"), std::string::npos)
      << other.err;
  EXPECT_EQ(RunHybrid("finger --g 3 --data " + data).exit_code, 2);
  EXPECT_EQ(RunHybrid("finger --plot " + data + " --data " + data).exit_code, 2);
}

// --model that is not a finger automaton, also without --simulate: exit 1, naming the file.
TEST(HybridFinger, ModelThatIsNotAFingerIsExit1) {
  const std::string spec = std::string(HYBRID_SOURCE_DIR) + "/spec/";
  ExpectRejected("finger --g 10 --model " + Quote(spec + "thermostat.ha"), 1,
                 {"thermostat.ha", "not a finger model", "theta1_min"});
}

// ---------------------------------------------------------------------------------------------
// Bad input to `hybrid finger`.

// Bad option values: exit 2 and a message naming the option.
TEST(HybridFinger, BadOptionValuesAreExit2) {
  ExpectRejected("finger --g 300", 2, {"--g", "[0, 255]", "300"});
  ExpectRejected("finger --g -1", 2, {"--g", "[0, 255]"});
  ExpectRejected("finger --g nan", 2, {"--g", "nan"});
  ExpectRejected("finger --gob1 300 --g 10", 2, {"--gob1"});
  ExpectRejected("finger --gob2 nan --g 10", 2, {"--gob2", "nan"});
  TempDir dir;
  ExpectRejected("finger --draw " + Quote(dir.File("x.svg")) + " --at 0,300", 2, {"--at", "300"});
  EXPECT_TRUE(dir.Files().empty());
  ExpectRejected("finger --gob1 80 --object " + Link1Circle() + " --g 100", 2,
                 {"--gob", "--object"});
}

// Asked nothing else, `finger` answers for g = 255 as `hand` does: the free finger against the
// palm (table 4.1 with decision D3: theta = (70, 90, -55)).
TEST(HybridFinger, GDefaultsToTheFullyClosingCommand) {
  const Result r = RunHybrid("finger --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(Field(j, "g"), 255.0);
  EXPECT_NEAR(Field(j, "theta1").get<double>(), 70.0, 1e-12);
  EXPECT_NEAR(Field(j, "theta2").get<double>(), 90.0, 1e-12);
  EXPECT_NEAR(Field(j, "theta3").get<double>(), -55.0, 1e-12);
  EXPECT_EQ(RunHybrid("finger").out, RunHybrid("finger --g 255").out);
  // With another question, no default position is added.
  const Result batch = RunHybrid("finger --g-range 0:10:2 --json");
  ASSERT_EQ(batch.exit_code, 0) << batch.err;
  EXPECT_EQ(json::parse(batch.out).size(), 2u);
}

// Numbers are numbers: an empty value is not 0, hexadecimal, doubled signs, inf, blanks and
// trailing text are refused naming the option (exit 2), for every numeric option.
TEST(HybridFinger, MalformedNumbersAreExit2NamingTheOption) {
  for (const std::string option : {"--g", "--gob1", "--gob2", "--gob3"}) {
    const std::string rest = option == "--g" ? "" : " --g 10";
    ExpectRejected("finger " + option + " ''" + rest, 2, {option + ": empty"});
    ExpectRejected("finger " + option + " 0x10" + rest, 2,
                   {option + ": '0x10' is not a decimal number"});
    ExpectRejected("finger " + option + " +-5" + rest, 2, {option + ": '+-5' is not"});
    ExpectRejected("finger " + option + " 5x" + rest, 2, {option + ": '5x' is not"});
    ExpectRejected("finger " + option + " ' 5'" + rest, 2, {option + ": ' 5' is not"});
    ExpectRejected("finger " + option + " inf" + rest, 2, {option + ": 'inf' is not"});
  }
  TempDir dir;
  const std::string draw = "finger --draw " + Quote(dir.File("x.svg"));
  ExpectRejected(draw + " --at ''", 2, {"--at: empty"});
  ExpectRejected(draw + " --at 0,,30", 2, {"--at: empty"});
  ExpectRejected(draw + " --at 0,30,", 2, {"--at: empty"});
  ExpectRejected(draw + " --at 0,0x1e", 2, {"--at: '0x1e' is not a decimal number"});
  EXPECT_TRUE(dir.Files().empty());
  // Signs, fractions and exponents are numbers.
  const json j = RunJson("finger --g +2.0e2 --gob1 .8E2");
  EXPECT_EQ(Field(j, "g"), 200.0);
  EXPECT_EQ(Field(j, "contacts", 0, "g"), 80.0);
  ASSERT_EQ(RunHybrid(draw + " --at +0,30. --at 1e2").exit_code, 0);
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"x.svg"});
}

// Malformed objects are bad option values: exit 2, the message names --object and the column of
// the fault; the numbers of a description follow the same syntax as the options'.
TEST(HybridFinger, MalformedObjectsAreExit2WithTheColumn) {
  ExpectRejected("finger --g 100 --object circle:0.05,abc,0.01", 2, {"--object", "column 13"});
  ExpectRejected("finger --g 100 --object square:1,2,3", 2, {"--object", "column 1:"});
  ExpectRejected("finger --g 100 --object circle:0.1,0.2", 2, {"--object", "column 15"});
  ExpectRejected("finger --g 100 --object circle:0.05,0.05,-0.01", 2,
                 {"--object", "column 18", "radius"});
  // A doubled sign is not a sign: "+-0.06" was read as -0.06.
  ExpectRejected("finger --g 100 --object circle:+-0.06,0.1,0.01", 2,
                 {"--object", "column 9", "malformed number '+-0.06'"});
  ExpectRejected("finger --g 100 --object circle:0x1,0.1,0.01", 2, {"--object", "column 9"});
  ExpectRejected("finger --g 100 --object circle:inf,0.1,0.01", 2, {"--object", "column 8"});
  ExpectRejected("finger --g 100 --object circle:,0.1,0.01", 2,
                 {"--object", "column 8", "expected a number"});
  // Thinner than 0.1 mm: could be crossed between two samples of the contact search.
  ExpectRejected("finger --g 100 --object circle:0.03,0.05,0.00005", 2, {"at least 0.0001 m"});
}

// Objects the finger cannot hold: overlapping the palm (G1) or the open finger, or out of reach.
TEST(HybridFinger, ObjectsTheFingerCannotHoldAreExit1ButUnreachedOnesAreNot) {
  ExpectRejected("finger --g 100 --object circle:0.05,-0.03,0.01", 1, {"overlaps the palm"});
  ExpectRejected("finger --g 100 --object circle:0,0.05,0.01", 1, {"overlaps", "open finger"});
  // Out of reach is an outcome, not an error; so is a command before the first contact.
  const json far = RunJson("finger --g 100 --object circle:-0.2,0.05,0.01");
  EXPECT_EQ(Field(far, "status"), "out_of_reach");
  EXPECT_TRUE(Field(far, "first_contact").is_null());
  const json early = RunJson("finger --g 20 --object circle:0.06,0.08,0.01");
  EXPECT_EQ(Field(early, "status"), "free");
  EXPECT_EQ(Field(RunJson("finger --g 255 --object circle:0.06,0.08,0.01"), "first_contact"),
            Field(early, "first_contact"));
  // Inside the open finger at the knuckle of joint 2 (0.05715 m up), where contact segments
  // leave a 2 mm gap: still an overlap.
  ExpectRejected("finger --g 100 --object circle:0,0.05815,0.0005", 1, {"overlaps", "open finger"});
}

// ---------------------------------------------------------------------------------------------
// `hybrid hand`.

// A cylinder centred between the fingers (basic mode): each finger's link 2 meets it.
TEST(HybridHand, EveryFingerTouchesACentredCylinderWithLink2) {
  const Result r = RunHybrid("hand --object " + kHandObject);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"finger A", "finger B", "finger C"}) {
    EXPECT_TRUE(Contains(r.out, f)) << r.out;
  }
  const json j = RunJson("hand --object " + kHandObject);
  EXPECT_EQ(Field(j, "mode"), "basic");
  EXPECT_EQ(Field(j, "spread"), 137.0);
  ASSERT_EQ(Field(j, "fingers").size(), 3u) << j.dump(2);
  for (int f = 0; f < 3; ++f) {
    const json& finger = Field(j, "fingers", f);
    SCOPED_TRACE(std::string("finger ") + "ABC"[f]);
    EXPECT_EQ(Field(finger, "finger"), std::string(1, "ABC"[f]));
    for (const char* k : {"theta1", "theta2", "theta3", "motor", "command", "discrete", "stop"}) {
      EXPECT_TRUE(finger.contains(k)) << k;
    }
    ASSERT_EQ(Field(finger, "contacts").size(), 1u) << finger.dump(2);
    EXPECT_EQ(Field(finger, "contacts", 0, "link"), 2);
    EXPECT_EQ(Field(finger, "contacts", 0, "by"), "object 1");
    EXPECT_EQ(Field(finger, "discrete", "c2"), 1);
  }
  ASSERT_TRUE(Field(j, "finger_touches").is_array());
  EXPECT_TRUE(Field(j, "finger_touches").empty());
}

// The composed automata (spec/hand.ha, one shared u) agree with the quasistatic hand on every
// finger.
TEST(HybridHand, SimulationAgreesWithTheClosedForm) {
  const json j = RunJson("hand --object " + kHandObject + " --simulate");
  EXPECT_EQ(Field(j, "simulation", "status"), "completed");
  EXPECT_EQ(Field(j, "simulation", "agrees"), true);
  EXPECT_LE(Field(j, "simulation", "max_angle_difference_deg").get<double>(), 1e-6);
  EXPECT_LE(Field(j, "simulation", "max_motor_difference").get<double>(), 1e-6);
  EXPECT_EQ(Field(j, "simulation", "contacts").size(), 3u) << j.dump(2);
}

// Pinch mode: the fingers touch each other, and the composed automata, whose contact guards also
// measure the distance to the other fingers (H3), find the same touches: every finger agrees,
// and each finger's link-3 contact in the simulation is at the touch's motor position.
TEST(HybridHand, PinchSimulationFindsTheFingerTouches) {
  const json j = RunJson("hand --mode pinch --object " + kHandObject + " --simulate");
  ASSERT_FALSE(Field(j, "finger_touches").empty()) << j.dump(2);
  EXPECT_EQ(Field(j, "simulation", "status"), "completed");
  EXPECT_EQ(Field(j, "simulation", "agrees"), true) << Field(j, "simulation").dump(2);
  const double touch = Field(j, "finger_touches", 0, "g").get<double>();
  int at_touch = 0;
  for (const json& c : Field(j, "simulation", "contacts")) {
    if (std::abs(Field(c, "g").get<double>() - touch) <= 1e-6) ++at_touch;
  }
  EXPECT_GE(at_touch, 2) << Field(j, "simulation").dump(2);  // both fingers of the first touch
}

// Pinch mode (spread 255) with finger A commanded to 100: the fingers touch each other (H3), and
// finger A's motor never passes its command.
TEST(HybridHand, PinchWithPerFingerCommandReportsFingerTouches) {
  const json j = RunJson("hand --mode pinch --g-a 100 --object " + kHandObject);
  EXPECT_EQ(Field(j, "mode"), "pinch");
  EXPECT_EQ(Field(j, "spread"), 255.0);
  ASSERT_EQ(Field(j, "fingers").size(), 3u);
  EXPECT_EQ(Field(j, "fingers", 0, "command"), 100.0);
  EXPECT_LE(Field(j, "fingers", 0, "motor").get<double>(), 100.0);
  ASSERT_TRUE(Field(j, "finger_touches").is_array());
  EXPECT_FALSE(Field(j, "finger_touches").empty()) << j.dump(2);
  for (const json& t : Field(j, "finger_touches")) {
    ASSERT_EQ(Field(t, "fingers").size(), 2u);  // two finger names, as in fingers[].finger
    EXPECT_NE(Field(t, "fingers", 0).get<std::string>(), Field(t, "fingers", 1).get<std::string>());
    EXPECT_EQ(Field(t, "links").size(), 2u);
  }
}

// Without objects the fingers close freely and stop against the palm at (70, 90, -55) (table
// 4.1, D3).
TEST(HybridHand, NoObjectClosesFreely) {
  const json j = RunJson("hand");
  EXPECT_EQ(Field(j, "mode"), "basic");
  ASSERT_EQ(Field(j, "fingers").size(), 3u);
  for (const json& finger : Field(j, "fingers")) {
    SCOPED_TRACE(Field(finger, "finger").dump());
    EXPECT_NEAR(Field(finger, "theta1").get<double>(), 70.0, 1e-9);
    EXPECT_NEAR(Field(finger, "theta2").get<double>(), 90.0, 1e-9);
    EXPECT_NEAR(Field(finger, "theta3").get<double>(), -55.0, 1e-9);
    EXPECT_NEAR(Field(finger, "motor").get<double>(), 240.0, 1e-9);
    EXPECT_TRUE(Field(finger, "contacts").empty());
  }
  EXPECT_TRUE(Field(j, "finger_touches").empty());
}

// Bad options (exit 2) and an object overlapping the palm (exit 1).
// Each finger's contacts are searched only up to its command: with g = 10 no finger touches the
// cylinder yet (link 2 meets it at about 43), a valid state ("free") whose report says where the
// first contact of the full closing is.
TEST(HybridHand, ContactsBeyondTheCommandDoNotCount) {
  const json before = RunJson("hand --g 10 --object " + kHandObject);
  EXPECT_EQ(Field(before, "status"), "free");
  const json full = RunJson("hand --object " + kHandObject);
  EXPECT_EQ(Field(full, "status"), "contact");
  double first = 255.0;
  for (const auto& finger : Field(full, "fingers")) {
    for (const auto& c : finger.at("contacts")) first = std::min(first, c.at("g").get<double>());
  }
  EXPECT_GT(first, 10.0);
  EXPECT_EQ(Field(before, "first_contact").get<double>(), first);
  EXPECT_EQ(Field(full, "first_contact").get<double>(), first);
  for (const auto& finger : Field(before, "fingers")) {
    EXPECT_TRUE(finger.at("contacts").empty());
    EXPECT_EQ(finger.at("motor").get<double>(), 10.0);
  }
  const Result text = RunHybrid("hand --g 10 --object " + kHandObject);
  EXPECT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("the first contact is at g = 42.8"), std::string::npos) << text.out;
  const json j = RunJson("hand --g-a 30 --object " + kHandObject);
  EXPECT_TRUE(Field(j, "fingers", 0, "contacts").empty()) << Field(j, "fingers", 0).dump(2);
  EXPECT_TRUE(Field(j, "fingers", 0, "stop").is_null());
  EXPECT_EQ(Field(j, "fingers", 1, "contacts").size(), 1u);
}

TEST(HybridHand, BadInputIsRejected) {
  ExpectRejected("hand --mode bogus", 2, {"bogus"});
  ExpectRejected("hand --g-b 400", 2, {"--g-b", "400"});
  ExpectRejected("hand --g nan", 2, {"--g"});
  ExpectRejected("hand --spread 300", 2, {"--spread"});
  // --spread overrides the operating mode: the report names none.
  const Result spread = RunHybrid("hand --spread 50 --json");
  ASSERT_EQ(spread.exit_code, 0) << spread.err;
  EXPECT_TRUE(Field(json::parse(spread.out), "mode").is_null()) << spread.out;
  EXPECT_EQ(Field(json::parse(spread.out), "spread"), 50.0);
  EXPECT_EQ(Field(json::parse(RunHybrid("hand --mode pinch --json").out), "mode"), "pinch");
  ExpectRejected("hand --object circle:0,-0.01,0.02", 1, {"overlaps the palm"});
  ExpectRejected("hand --object circle:0,0.06,abc", 2, {"--object", "column 15"});
  // An object out of reach is an outcome, not an error.
  const json far = RunJson("hand --object circle:0.3,0.5,0.01");
  EXPECT_EQ(Field(far, "status"), "out_of_reach");
  EXPECT_TRUE(Field(far, "first_contact").is_null());
  for (const std::string option : {"--spread", "--g", "--g-a", "--g-b", "--g-c"}) {
    ExpectRejected("hand " + option + " ''", 2, {option + ": empty"});
    ExpectRejected("hand " + option + " 0x10", 2, {option + ": '0x10' is not a decimal number"});
    ExpectRejected("hand " + option + " --5", 2, {option});
  }
  ExpectRejected("hand --draw x.svg --at ''", 2, {"--at: empty"});
}

// ---------------------------------------------------------------------------------------------
// Help.

TEST(HybridGripperHelp, FingerAndHandDescribeObjects) {
  for (const std::string command : {"finger", "hand"}) {
    const Result r = RunHybrid(command + " --help");
    EXPECT_EQ(r.exit_code, 0) << command << "\n" << r.err;
    EXPECT_TRUE(Contains(r.out, "--object")) << command << "\n" << r.out;
    EXPECT_TRUE(Contains(r.out, "circle:X,Y,R")) << command << "\n" << r.out;
  }
}

}  // namespace
}  // namespace hybrid
