// The finger behind its controller (spec/controlled_finger.ha = spec/driven_finger.ha +
// spec/controller.ha): the driven finger is the generator's output and differs from
// spec/finger.ha only where documented; simulated, the motor stops where the independent rig
// (tests/test_utilities/robotiq_rig.h: the report's closed form and the controller as the manual
// describes it) stops, stays there until a more open request, and the angles are the rig's; the
// controller's invariants are proved, and broken controllers come back violated with a trace
// the simulator replays.

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/properties.h"
#include "tests/test_utilities/robotiq_rig.h"
#include "tests/test_utilities/trace_states.h"

namespace hybrid {
namespace {

namespace fs = std::filesystem;
using testing::ReplaceOnce;
using testing::SpecText;

const std::string kSource = HYBRID_SOURCE_DIR;

std::string Generated(const std::string& arguments) {
  const std::string command = "python3 " + kSource + "/tools/generate_finger.py " + arguments;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return "";
  std::string out;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  EXPECT_EQ(pclose(pipe), 0);
  return out;
}

TEST(ControlledFingerTest, CommittedDrivenFingerIsTheGeneratorOutput) {
  EXPECT_EQ(Generated("--driven"), SpecText("driven_finger"))
      << "run: python3 tools/generate_finger.py --driven > spec/driven_finger.ha";
}

// The driven finger is spec/finger.ha's automaton with u a variable, no flow for g, no
// invariants, and the label `stall` on exactly the transitions from another phase into phase 4
// (c3 = 1, l3 = 1, or the palm: l1 = l2 = 1 with l3 = -1).
TEST(ControlledFingerTest, DrivenFingerDiffersFromTheFingerOnlyWhereDocumented) {
  const Automaton finger = ParseModel(SpecText("finger"), "finger.ha").components()[0].automaton;
  const Automaton driven =
      ParseModel(SpecText("driven_finger"), "driven_finger.ha").components()[0].automaton;
  ASSERT_EQ(driven.num_modes(), finger.num_modes());
  ASSERT_EQ(driven.num_transitions(), finger.num_transitions());
  EXPECT_EQ(driven.symbols()[*driven.symbols().Find("u")].kind, SymbolKind::kVariable);
  const int g = *driven.symbols().Find("g");
  auto blocked = [&](const Automaton& a, ModeId m) {
    auto value = [&](const char* name) {
      return *a.modes()[m.value()].DiscreteValueOf(*a.symbols().Find(name));
    };
    return value("c3") == 1 || value("l3") == 1 ||
           (value("l1") == 1 && value("l2") == 1 && value("l3") == -1);
  };
  for (int m = 0; m < driven.num_modes(); ++m) {
    EXPECT_EQ(driven.modes()[m].name, finger.modes()[m].name);
    EXPECT_TRUE(driven.modes()[m].invariant.comparisons.empty()) << driven.modes()[m].name;
    size_t flows_without_g = 0;
    for (const auto& [slot, rhs] : finger.modes()[m].flows) flows_without_g += slot != g;
    EXPECT_EQ(driven.modes()[m].flows.size(), flows_without_g) << driven.modes()[m].name;
    for (const auto& [slot, rhs] : driven.modes()[m].flows) EXPECT_NE(slot, g);
  }
  int stalls = 0;
  for (int t = 0; t < driven.num_transitions(); ++t) {
    const Transition& d = driven.transitions()[t];
    const Transition& f = finger.transitions()[t];
    EXPECT_EQ(d.name, f.name);
    EXPECT_EQ(d.guard.comparisons.size(), f.guard.comparisons.size()) << d.name;
    const bool enters_phase4 = blocked(driven, d.target) && !blocked(driven, d.source);
    EXPECT_EQ(d.label == "stall", enters_phase4) << d.name;
    if (!enters_phase4) {
      EXPECT_EQ(d.label, f.label) << d.name;
    }
    stalls += enters_phase4;
  }
  EXPECT_EQ(stalls, 19);
}

// The state of a run at the end of each request: one request every `hold` seconds (long
// enough at 255 counts per second for the motor to settle).
struct Settled {
  std::vector<double> g, status;
  std::vector<std::array<double, 3>> theta;
};

Settled RunRequests(const System& system, const std::vector<double>& requests, double hold,
                    SimulationStatus* status = nullptr) {
  const Simulator simulator(system);
  SimulationOptions options;
  options.until = hold * static_cast<double>(requests.size());
  std::vector<std::pair<double, double>> points;
  for (size_t k = 0; k < requests.size(); ++k) {
    points.emplace_back(hold * static_cast<double>(k), requests[k]);
    options.sample_times.push_back(hold * (static_cast<double>(k) + 1) - 1e-3);
  }
  const int slot = *system.symbols().Find("request");
  const std::vector<InputSignal> signals = {InputSignal{slot, InputSignal::Shape::kStep, points}};
  const SimulationResult r = simulator.Run(options, signals);
  if (status) *status = r.status;
  EXPECT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  const auto& names = simulator.variable_names();
  auto index = [&](const std::string& name) {
    return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  Settled out;
  for (const StateSample& s : r.samples) {
    if (s.kind != StateSample::Kind::kSample) continue;
    out.g.push_back(s.x[index("g")]);
    out.theta.push_back({s.x[index("theta1")], s.x[index("theta2")], s.x[index("theta3")]});
    const Mode& mode = system.components()[1].automaton.modes()[s.modes[1]];
    const int status_slot = *system.components()[1].automaton.symbols().Find("ctl.status");
    out.status.push_back(*mode.DiscreteValueOf(status_slot));
  }
  return out;
}

System ControlledFinger() { return ParseModelFile(kSource + "/spec/controlled_finger.ha"); }

// Closing past the palm stop and reopening: the motor stays at the stop (240) while the request
// is above it, then follows the request; every settled sample is the rig's.
TEST(ControlledFingerTest, StaysAtThePalmStopUntilARequestBelowItThenFollowsTheClosedForm) {
  const std::vector<double> requests = {100, 200, 255, 250, 245, 240, 239, 200, 120, 60, 0};
  const Settled s = RunRequests(ControlledFinger(), requests, 2.0);
  ASSERT_EQ(s.g.size(), requests.size());
  const testing::RigFinger rig;
  const double stop = testing::RigStopPosition(rig, {});
  ASSERT_EQ(stop, 240.0);
  for (size_t k = 0; k < requests.size(); ++k) {
    const double motor = std::min(requests[k], stop);
    EXPECT_NEAR(s.g[k], motor, 1e-9) << "request " << requests[k];
    const auto expected = testing::RigAngles(motor, rig, {});
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(s.theta[k][j], expected[j], 1e-6) << "request " << requests[k] << " j " << j;
    }
    // Firmware status: 2 stopped while closing, 3 at the request.
    EXPECT_EQ(s.status[k], requests[k] >= stop ? 2 : 3) << "request " << requests[k];
  }
}

// An object on link 1 at g = 80: link 3 then reaches its limit where the rig says, the motor
// stops there, and reopening past it retraces the rig's contact table.
TEST(ControlledFingerTest, ObjectOnLink1StopsTheMotorWhereTheRigStops) {
  System system = ControlledFinger();
  system.SetParameter("gob1", 80.0);
  testing::RigObject object;
  object.gob1 = 80.0;
  const testing::RigFinger rig;
  const double stop = testing::RigStopPosition(rig, object);
  ASSERT_GT(stop, 200.0);
  ASSERT_LT(stop, 255.0);
  const std::vector<double> requests = {150, 255, 230, std::floor(stop) - 1, 100, 40};
  const Settled s = RunRequests(system, requests, 2.0);
  ASSERT_EQ(s.g.size(), requests.size());
  for (size_t k = 0; k < requests.size(); ++k) {
    const double motor = std::min(requests[k], stop);
    EXPECT_NEAR(s.g[k], motor, 1e-6) << "request " << requests[k];
    const auto expected = testing::RigAngles(motor, rig, object);
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(s.theta[k][j], expected[j], 1e-4) << "request " << requests[k] << " j " << j;
    }
  }
  EXPECT_EQ(s.status[1], 2);  // stopped by the object while closing
  EXPECT_EQ(s.status[2], 2);  // 230 is not below where it stopped
}

// No chattering: requests that differ from where the motor holds by less than the deadband (0.5
// count) do not move it, and a request inside the deadband below a stop does not reopen.
TEST(ControlledFingerTest, RequestsWithinTheDeadbandDoNotMoveTheMotor) {
  const System system = ControlledFinger();
  const Simulator simulator(system);
  SimulationOptions options;
  options.until = 10;
  const int slot = *system.symbols().Find("request");
  const std::vector<InputSignal> signals = {
      InputSignal{slot,
                  InputSignal::Shape::kStep,
                  {{0, 100}, {2, 100.3}, {3, 99.8}, {4, 255}, {6, 239.7}, {7, 239.4}, {8, 100}}}};
  const SimulationResult r = simulator.Run(options, signals);
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  std::vector<std::string> moves;
  for (const EventRecord& e : r.events) {
    for (const std::string& t : e.transitions) {
      if (t == "ctl.read_closes" || t == "ctl.read_opens" || t == "ctl.stopped_opens") {
        moves.push_back(t + "@" + std::to_string(static_cast<int>(e.time)));
      }
    }
  }
  // Closing to 100 at t = 0, to 255 at t = 4 (stopped at 240); 239.7 is within the deadband of
  // the stop, 239.4 is not; then opening to 100.
  EXPECT_EQ(moves, (std::vector<std::string>{"ctl.read_closes@0", "ctl.read_closes@4",
                                             "ctl.stopped_opens@7", "ctl.read_opens@8"}));
}

// The default scenario closes to 255, holds and reopens to 0.
TEST(ControlledFingerTest, DefaultScenarioClosesHoldsAndReopens) {
  const System system = ControlledFinger();
  const Simulator simulator(system);
  SimulationOptions options;
  options.sample_times = {1.5, 3.9};
  const SimulationResult r = simulator.Run(options);
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  const auto& names = simulator.variable_names();
  const int g = static_cast<int>(std::find(names.begin(), names.end(), "g") - names.begin());
  std::vector<double> at;
  for (const StateSample& s : r.samples) {
    if (s.kind == StateSample::Kind::kSample) at.push_back(s.x[g]);
  }
  ASSERT_EQ(at.size(), 2u);
  EXPECT_NEAR(at[0], 240.0, 1e-9);
  EXPECT_NEAR(at[1], 0.0, 1e-9);
}

TEST(ControlledFingerTest, EveryDeclaredInvariantIsProved) {
  const System system = ControlledFinger();
  const std::vector<Property> invariants = DeclaredProperties(system);
  ASSERT_EQ(invariants.size(), 5u);
  PropertyProver::Options options;
  options.budget = 120;  // the default (60) proves them too; headroom for sanitized builds
  const auto results = PropertyProver(options).Check(system, invariants);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kProved) << r.property << ": " << r.reason;
  }
}

// A copy of the three spec files in a fresh directory with the controller's text mutated.
System Mutated(const std::string& from, const std::string& to) {
  const fs::path dir =
      fs::temp_directory_path() / ("controlled_finger_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* name : {"driven_finger", "controlled_finger"}) {
    std::ofstream(dir / (std::string(name) + ".ha")) << SpecText(name);
  }
  std::ofstream(dir / "controller.ha") << ReplaceOnce(SpecText("controller"), from, to);
  System out = ParseModelFile(dir / "controlled_finger.ha");
  fs::remove_all(dir);
  return out;
}

// The controller's and the finger's state at one recorded sample, read directly (not through the
// property evaluator under test).
struct Reading {
  int status = 0, drive = 0;
  double g = 0.0, target = 0.0;
  bool blocked = false;  // the finger in phase 4: c3 = 1, l3 = 1, or l1 = l2 = 1 with l3 = -1
};

Reading Read(const Simulator& simulator, const StateSample& s) {
  const System& system = simulator.system();
  auto discrete = [&](int component, const std::string& name) {
    const Automaton& a = system.components()[component].automaton;
    return *a.modes()[s.modes[component]].DiscreteValueOf(*a.symbols().Find(name));
  };
  const auto& names = simulator.variable_names();
  auto value = [&](const std::string& name) {
    return s.x[std::find(names.begin(), names.end(), name) - names.begin()];
  };
  Reading r;
  r.status = discrete(1, "ctl.status");
  r.drive = discrete(1, "ctl.drive");
  r.g = value("g");
  r.target = value("ctl.target");
  r.blocked = discrete(0, "c3") == 1 || discrete(0, "l3") == 1 ||
              (discrete(0, "l1") == 1 && discrete(0, "l2") == 1 && discrete(0, "l3") == -1);
  return r;
}

struct ControllerMutant {
  const char* name;
  const char* property;
  const char* from;
  const char* to;
  bool (*breaks)(const Reading&);  // the property's violation, written out here
};

const ControllerMutant kControllerMutants[] = {
    // The controller stops without the finger being blocked (its stop no longer synchronises
    // with the finger's entry into phase 4).
    {"unsynchronised_stop", "stopped_implies_blocked",
     "transition closing_stalls: closing -> stopped { reset u := 0; label stall; }",
     "transition closing_stalls: closing -> stopped { reset u := 0; }",
     [](const Reading& r) { return r.status == 2 && !r.blocked; }},
    // The motor overshoots the request by one count before it holds.
    {"overshoot", "ctl.motor_never_passes_request", "closing -> idle { guard g >= target;",
     "closing -> idle { guard g >= target + 1;",
     [](const Reading& r) { return r.drive == 1 && r.g > r.target + 1e-6; }},
};

class ControllerMutantTest : public ::testing::TestWithParam<ControllerMutant> {};

// The prover finds the violation; the trace, simulated again on a fresh simulator (its
// parameters, initial values and inputs), reaches a state that breaks the property as read
// directly from the state.
TEST_P(ControllerMutantTest, ComesBackViolatedWithATraceTheSimulatorReplays) {
  const ControllerMutant& m = GetParam();
  const System mutant = Mutated(m.from, m.to);
  const std::vector<Property> declared = DeclaredProperties(mutant);
  const auto named = std::find_if(declared.begin(), declared.end(),
                                  [&](const Property& p) { return p.name == m.property; });
  ASSERT_NE(named, declared.end()) << m.property;
  PropertyProver::Options options;
  options.max_depth = 8;
  options.budget = 120;
  const auto results = PropertyProver(options).Check(mutant, {&*named, 1});
  ASSERT_EQ(results[0].verdict, Verdict::kViolated) << results[0].reason;
  ASSERT_TRUE(results[0].trace.has_value());
  bool broken = false;
  testing::ForEachTraceState(mutant, *results[0].trace, 100,
                             [&](const Simulator& simulator, const StateSample& s) {
                               broken = broken || m.breaks(Read(simulator, s));
                             });
  EXPECT_TRUE(broken) << m.name << ": the trace does not break " << m.property;
  // The check is not trivially true: the unmutated controller never breaks it along its
  // default scenario.
  const System original = ControlledFinger();
  const Simulator nominal(original);
  SimulationOptions every;
  every.sample_step = 0.01;
  for (const StateSample& s : nominal.Run(every).samples) {
    EXPECT_FALSE(m.breaks(Read(nominal, s))) << "t = " << s.time;
  }
}

INSTANTIATE_TEST_SUITE_P(Mutants, ControllerMutantTest, ::testing::ValuesIn(kControllerMutants),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace hybrid
