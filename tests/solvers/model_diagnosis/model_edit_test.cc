#include "hybrid/model_diagnosis/model_edit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/spaceex/spaceex_import.h"
#include "tests/test_utilities/models.h"

namespace hybrid {
namespace {

System Spec(const std::string& name) { return ParseModel(testing::SpecText(name), name + ".ha"); }

TraceData Trace(const System& model) {
  std::string text = "run,time,u,x\n";
  for (int k = 0; k < 20; ++k)
    text += "a," + std::to_string(k) + ",10," + std::to_string(18 + 0.2 * k) + "\n";
  std::istringstream in(text);
  return ReadTraceData(in, "t.csv", model);
}

std::vector<std::string> Names(const CandidateSet& set) {
  std::vector<std::string> names;
  for (const ModelEdit& e : set.edits) names.push_back(e.name);
  return names;
}

const ModelEdit& Find(const CandidateSet& set, const std::string& name) {
  for (const ModelEdit& e : set.edits) {
    if (e.name == name) return e;
  }
  throw std::invalid_argument("no edit " + name);
}

// x at every 0.5 time units of the model's scenario, with `parameters` set per run.
std::vector<double> Samples(const System& s,
                            std::vector<std::pair<std::string, double>> parameters = {},
                            const std::string& variable = "x", double until = 0.0) {
  const Simulator sim(s);
  SimulationOptions o;
  if (until > 0) o.until = until;
  o.sample_step = 0.5;
  o.parameters = std::move(parameters);
  const SimulationResult r = sim.Run(o);
  EXPECT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  const auto& names = sim.variable_names();
  const size_t i = std::find(names.begin(), names.end(), variable) - names.begin();
  std::vector<double> xs;
  for (const StateSample& sample : r.samples) {
    if (sample.kind == StateSample::Kind::kSample) xs.push_back(sample.x[i]);
  }
  return xs;
}

void ExpectNear(const std::vector<double>& a, const std::vector<double>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], tol) << "sample " << k;
}

TEST(CandidateEdits, ThermostatVocabulary) {
  const System s = Spec("thermostat");
  const CandidateSet set = CandidateEdits(s.components()[0].automaton, Trace(s));
  EXPECT_EQ(Names(set),
            (std::vector<std::string>{"a", "p", "x_bias", "x_gain", "off.x_gain", "on.x_gain",
                                      "off.invariant", "on.invariant", "u_offset"}));
  // Both guards are lazy: left out, with a note each.
  ASSERT_EQ(set.notes.size(), 2u);
  EXPECT_NE(set.notes[0].find("lazy transition 'switch_on'"), std::string::npos);
  const ModelEdit& inv = Find(set, "off.invariant");
  EXPECT_EQ(inv.identifier, "off_invariant");
  EXPECT_EQ(inv.neutral, 18.0);
  // A quarter of the measured range of x (18 to 21.8) either side.
  EXPECT_NEAR(inv.hi - inv.lo, 0.5 * 3.8, 1e-9);
  EXPECT_NEAR(Find(set, "x_bias").hi, 1.9, 1e-9);
  EXPECT_NEAR(Find(set, "p").lo, 1.5, 1e-12);  // no declared range: +-50%
}

TEST(CandidateEdits, UrgentGuardsAreThresholds) {
  const System s = Spec("thermostat_urgent");
  const CandidateSet set = CandidateEdits(s.components()[0].automaton, Trace(s));
  const ModelEdit& on = Find(set, "switch_on.threshold");
  EXPECT_EQ(on.kind, EditKind::kGuardThreshold);
  EXPECT_EQ(on.owner, "switch_on");
  EXPECT_EQ(on.neutral, 18.0);
  EXPECT_TRUE(set.notes.empty());
}

// Oracle 1: every dynamic edit at its neutral value leaves the model's runs as they were.
TEST(ApplyEdits, NeutralEditsSimulateAsTheModel) {
  for (const char* name : {"thermostat", "thermostat_urgent"}) {
    const System s = Spec(name);
    const Automaton& a = s.components()[0].automaton;
    std::vector<std::pair<ModelEdit, double>> neutral;
    for (const ModelEdit& e : CandidateEdits(a, Trace(s)).edits) {
      if (!e.cheap && e.kind != EditKind::kParameter) neutral.emplace_back(e, e.neutral);
    }
    ASSERT_GE(neutral.size(), 4u);
    // The delays' clocks are further state variables: the integrator's error control differs.
    ExpectNear(Samples(System::Of(ApplyEdits(a, neutral))), Samples(s), 1e-7);
  }
}

// Oracle 2: the extended model, printed and parsed back, simulates as the instrumented model with
// the values set per run; and the measured variable is gain * x + bias.
TEST(ApplyEdits, ExtendedModelRoundTripsAndEqualsPerRunValues) {
  const System s = Spec("thermostat_urgent");
  const Automaton& a = s.components()[0].automaton;
  const CandidateSet set = CandidateEdits(a, Trace(s));
  const std::vector<std::pair<ModelEdit, double>> edits = {{Find(set, "switch_on.threshold"), 18.5},
                                                           {Find(set, "on.x_gain"), 0.9},
                                                           {Find(set, "u_offset"), -1.0},
                                                           {Find(set, "x_bias"), 0.4},
                                                           {Find(set, "x_gain"), 1.01}};
  const std::string text = PrintSystem(System::Of(ApplyEdits(a, edits)));
  const System extended = ParseModel(text, "extended.ha");
  std::vector<std::pair<ModelEdit, double>> neutral;
  for (const auto& [e, v] : edits) {
    if (!e.cheap) neutral.emplace_back(e, e.neutral);
  }
  const System instrumented = System::Of(ApplyEdits(a, neutral));
  const std::vector<double> x = Samples(
      instrumented, {{"switch_on_threshold", 18.5}, {"on_x_gain", 0.9}, {"u_offset", -1.0}});
  // The extended model integrates one more variable (x_measured): the error control differs.
  ExpectNear(Samples(extended), x, 1e-7);
  const std::vector<double> measured = Samples(extended, {}, "x_measured");
  ASSERT_EQ(measured.size(), x.size());
  for (size_t k = 0; k < x.size(); ++k) EXPECT_NEAR(measured[k], 1.01 * x[k] + 0.4, 1e-6);
  // And the edits change the run (the comparison can fail).
  EXPECT_GT(std::abs(Samples(s).back() - x.back()), 0.1);
}

// Oracle 3: the printed edits, written by hand.
TEST(ApplyEdits, PrintedEdits) {
  const System s = Spec("thermostat_urgent");
  const Automaton& a = s.components()[0].automaton;
  const CandidateSet set = CandidateEdits(a, Trace(s));
  const std::vector<std::pair<ModelEdit, double>> edits = {{Find(set, "switch_on.threshold"), 18.5},
                                                           {Find(set, "x_bias"), 0.4}};
  const std::string text = PrintSystem(System::Of(ApplyEdits(a, edits)));
  for (const char* line :
       {"param switch_on_threshold = 18.5;", "param x_bias = 0.4;", "var x_measured [degC];",
        "guard x <= switch_on_threshold;", "x_measured' = a * (u - x);",
        "x_measured' = a * (u - x) + p;", "init off { x = 20; x_measured = 20 + x_bias; }"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
}

// A threshold that reads a parameter (`inv y <= high`, `guard y == high` in the SpaceEx water tank)
// follows it at its neutral value: the instrumented model with `high` set per run simulates as the
// model with `high` changed (found diagnosing a trace of the tank: every value of `high` failed).
TEST(ApplyEdits, NeutralThresholdsFollowTheParametersTheyRead) {
  System s =
      spaceex::ReadModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/spaceex/water_tank.xml");
  const Automaton& a = s.components()[0].automaton;
  std::vector<std::pair<ModelEdit, double>> neutral;
  std::string text = "run,time,y\n";
  for (int k = 0; k < 20; ++k)
    text += "a," + std::to_string(k) + "," + std::to_string(5 + 0.3 * k) + "\n";
  std::istringstream in(text);
  for (const ModelEdit& e : CandidateEdits(a, ReadTraceData(in, "t.csv", s)).edits) {
    if (e.kind == EditKind::kInvariantThreshold) neutral.emplace_back(e, e.neutral);
  }
  ASSERT_EQ(neutral.size(), 4u);
  const System instrumented = System::Of(ApplyEdits(a, neutral));
  const std::vector<double> per_run = Samples(instrumented, {{"high", 11.0}}, "y", 30.0);
  s.SetParameter("high", 11.0);
  ExpectNear(per_run, Samples(s, {}, "y", 30.0), 1e-9);
  // And `high` matters (the comparison can fail).
  const std::vector<double> neutral_run = Samples(instrumented, {}, "y", 30.0);
  double most = 0.0;
  for (size_t k = 0; k < per_run.size() && k < neutral_run.size(); ++k) {
    most = std::max(most, std::abs(per_run[k] - neutral_run[k]));
  }
  EXPECT_GT(most, 0.5);
}

// A delay: the pending mode keeps the source's flow until the clock reaches the delay. Oracle:
// the closed form of the off mode, x = u + (x0 - u) e^{-a t}, past the level 18 for 0.5 min.
TEST(ApplyEdits, DelayedTransitionWaitsInItsPendingMode) {
  const System s = Spec("thermostat_urgent");
  const Automaton& a = s.components()[0].automaton;
  const std::vector<std::pair<ModelEdit, double>> edits = {
      {Find(CandidateEdits(a, Trace(s)), "switch_on.delay"), 0.5}};
  const Automaton delayed = ApplyEdits(a, edits);
  const std::string text = PrintAutomaton(delayed);
  for (const char* line : {"param switch_on_delay = 0.5;", "mode switch_on_pending {",
                           "inv switch_on_clock <= switch_on_delay;",
                           "transition switch_on_done: switch_on_pending -> on {"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
  // The scenario's u = 10 from x = 20: x reaches 18 at t* = 10 ln(10 / 8); heating starts 0.5
  // later, at x = 10 + 10 e^{-0.1 (t* + 0.5)}.
  const System system = System::Of(delayed);  // the simulator keeps a reference
  const Simulator sim(system);
  const SimulationResult r = sim.Run(SimulationOptions{});
  ASSERT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  ASSERT_GE(r.events.size(), 2u);
  const double t_star = 10.0 * std::log(10.0 / 8.0);
  EXPECT_NEAR(r.events[0].time, t_star, 1e-6);
  EXPECT_NEAR(r.events[1].time, t_star + 0.5, 1e-6);
  EXPECT_NEAR(r.events[1].before[0], 10.0 + 10.0 * std::exp(-0.1 * (t_star + 0.5)), 1e-6);
}

TEST(ApplyEdits, RefusesAnEditThatDoesNotFit) {
  const System s = Spec("thermostat_urgent");
  const Automaton& a = s.components()[0].automaton;
  ModelEdit e = Find(CandidateEdits(a, Trace(s)), "switch_on.threshold");
  e.atom = 3;
  const std::vector<std::pair<ModelEdit, double>> edits = {{e, 18.5}};
  EXPECT_THROW(ApplyEdits(a, edits), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
