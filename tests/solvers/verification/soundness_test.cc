// Differential soundness test of `hybrid check --method prove`
// (include/hybrid/verification/property_prover.h), see docs/soundness.md. Random automata are
// generated as model-language text (tests/test_utilities/random_hybrid_automata.h) and checked by
// PropertyProver exactly as the command does (every declared property). Then every verdict is put
// to the simulator:
// - every `proved` invariant and every `unreachable` target is attacked by many simulations with
//   random piecewise-constant inputs within their bounds, random values of the uncertain
//   parameters, random initial values and initial modes, and random times for lazy transitions;
//   one recorded state that breaks the claim beyond a small tolerance is a contradiction;
// - every `violated` trace and every `reachable` witness is turned back into model text (its
//   parameter and initial values as declared values, its inputs as the scenario) and simulated:
//   it must reach the violation or the target.
// The attacks and replays are tests/test_utilities/soundness_attack.h (shared with the flowpipe
// engine's test, tests/solvers/flowpipe/flowpipe_soundness_test.cc).
// The oracle shares no code with the SMT encoding: the model is text, the simulator (CVODE with
// event location, exact on constant-rate segments) produces the states, and the properties are
// evaluated by the generator's own evaluator. One contradiction fails the test and prints the
// model, the property and the simulated counterexample (with a model text that `hybrid simulate`
// replays).
//
// Environment: HYBRID_SOUNDNESS_MODELS (default 300), HYBRID_SOUNDNESS_SEED (default 20261121),
// HYBRID_SOUNDNESS_FIRST (index of the first model, default 0: rerun one model with FIRST=i
// MODELS=1), HYBRID_SOUNDNESS_ATTACKS (simulations per model with a claim, default 40).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "tests/test_utilities/random_hybrid_automata.h"
#include "tests/test_utilities/soundness_attack.h"

namespace hybrid {
namespace {

namespace ht = hybrid::testing;
using ht::RandomHybridAutomaton;
using ht::RandomProperty;
using Summary = ht::SoundnessSummary;
using Settings = ht::SoundnessSettings;
using ht::AttackClaims;
using ht::CheckAutomaton;
using ht::Checker;
using ht::KindName;
using ht::ModelSeed;
using ht::RatedVariables;
using ht::SummaryText;

constexpr std::uint64_t kDefaultSeed = 20261121;
constexpr int kDefaultModels = 300;
constexpr int kDefaultAttacks = 40;

Settings SettingsFromEnvironment(int default_models = kDefaultModels) {
  return ht::SoundnessSettingsFromEnvironment("HYBRID_SOUNDNESS", kDefaultSeed, default_models,
                                              kDefaultAttacks);
}

/// What `hybrid check --method prove --depth 6 --induction 2 --budget 30` does: Z3 resource
/// units per query, and a budget for the whole check (`search_seconds`, the name both the
/// wall-clock budget of old and the solver-resource budget understand). Small models never use
/// it up.
PropertyProver::Options ProverOptions() {
  PropertyProver::Options o;
  o.max_depth = 6;
  o.max_induction = 2;
  o.resource_limit = 5'000'000;
  o.search_seconds = 30.0;
  return o;
}

// A checker under test: every declared property of a system, one result each.
std::vector<CheckResult> Prove(const System& system) {
  return PropertyProver(ProverOptions()).Check(system, DeclaredProperties(system));
}

// The engine of --method reach, on every model: those outside its class give `unknown`.
// Bounded to 2000 symbolic states (random models with clocks that are never reset have no
// fixpoint), so that the test's time does not depend on the CPU-time net.
std::vector<CheckResult> Reach(const System& system) {
  PolyhedralReachability::Options options;
  options.max_states = 2000;
  return PolyhedralReachability(options).Check(system, DeclaredProperties(system));
}

/// The model of issue 12: the tank rises at 0.3 to 0.5 per second, yet an input named `d`
/// (the SMT encoding's name for a flow's duration) made the prover claim both properties.
RandomHybridAutomaton IssueTank() {
  RandomHybridAutomaton a;
  a.name = "tank";
  a.variables = {{"h", std::make_pair(0.0, 10.0)}};
  a.inputs = {{"d", -0.2, 0.0}};
  a.declaration_order = {{0, 0}, {1, 0}};
  const ht::RandomSum h{{{1.0, {"h"}}}};
  a.modes = {{"fill",
              {{"h", ht::RandomSum{{{0.5, {}}, {1.0, {"d"}}}}}},
              {{h, ht::RandomRelation::kLessEqual, 8.0}},
              {}}};
  a.inits = {{"fill", {{"h", {5.0, 5.0}}}}};
  ht::RandomPredicate below_6, above_7;
  below_6.comparison = {h, ht::RandomRelation::kLessEqual, 6.0};
  above_7.comparison = {h, ht::RandomRelation::kGreaterEqual, 7.0};
  a.properties = {{"stays_below_6", RandomProperty::Kind::kAlways, below_6, std::nullopt},
                  {"reaches_7", RandomProperty::Kind::kReach, above_7, std::nullopt}};
  return a;
}

ht::RandomSum Term(double coef, const std::string& name) { return {{{coef, {name}}}}; }
ht::RandomSum Rate(double c) { return {{{c, {}}}}; }
ht::RandomComparison Compare(const std::string& name, ht::RandomRelation r, double rhs) {
  return {Term(1.0, name), r, rhs};
}
ht::RandomPredicate Atom(const ht::RandomComparison& c) {
  ht::RandomPredicate p;
  p.comparison = c;
  return p;
}
ht::RandomPredicate InMode(const std::string& mode) {
  ht::RandomPredicate p;
  p.kind = ht::RandomPredicate::Kind::kInMode;
  p.mode = mode;
  return p;
}
ht::RandomPredicate Both(ht::RandomPredicate::Kind kind, ht::RandomPredicate a,
                         ht::RandomPredicate b) {
  ht::RandomPredicate p;
  p.kind = kind;
  p.operands = {std::move(a), std::move(b)};
  return p;
}

/// Known unsound answers of the prover before issue 12, each checked (and attacked) first in the
/// differential test, whatever the random models draw.
std::vector<std::pair<std::string, RandomHybridAutomaton>> KnownCases() {
  using R = ht::RandomRelation;
  using K = RandomProperty::Kind;
  std::vector<std::pair<std::string, RandomHybridAutomaton>> cases;
  cases.emplace_back("issue 12 tank: input d", IssueTank());
  // A variable named d (the encoding's duration): x was "never" to reach 2.
  RandomHybridAutomaton vard;
  vard.name = "a";
  vard.variables = {{"x", std::nullopt}, {"d", std::nullopt}};
  vard.declaration_order = {{0, 0}, {0, 1}};
  vard.modes = {{"m", {{"x", Rate(1.0)}}, {}, {}}};
  vard.inits = {{"m", {{"x", {0.0, 0.0}}, {"d", {-1.0, -1.0}}}}};
  vard.properties = {{"p", K::kNever,
                      Both(ht::RandomPredicate::Kind::kAnd, Atom(Compare("x", R::kGreaterEqual, 2)),
                           Atom(Compare("d", R::kLessEqual, 0))),
                      std::nullopt}};
  cases.emplace_back("variable d", vard);
  // An urgent strict guard fires on its boundary (in its closure): x reaches 1, then `stop`.
  RandomHybridAutomaton strict;
  strict.name = "a";
  strict.variables = {{"x", std::nullopt}};
  strict.declaration_order = {{0, 0}};
  strict.modes = {{"run", {{"x", Rate(1.0)}}, {}, {}}, {"stop", {}, {}, {}}};
  strict.transitions = {{"go", "run", "stop", {Compare("x", R::kGreater, 1)}, {}, {}}};
  strict.inits = {{"run", {{"x", {0.0, 0.0}}}}};
  strict.properties = {{"p", K::kAlways, InMode("run"), std::nullopt},
                       {"q", K::kReach, InMode("stop"), std::nullopt}};
  cases.emplace_back("strict urgent guard", strict);
  // The target holds in the initial state; the input's bounds exclude 0.
  RandomHybridAutomaton start;
  start.name = "a";
  start.variables = {{"x", std::nullopt}};
  start.inputs = {{"u", 1.0, 2.0}};
  start.declaration_order = {{0, 0}, {1, 0}};
  start.modes = {{"m", {}, {}, {}}};
  start.inits = {{"m", {{"x", {0.0, 0.0}}}}};
  start.properties = {{"f", K::kAlways, Atom(Compare("x", R::kGreaterEqual, 100)), std::nullopt},
                      {"r", K::kReach, Atom(Compare("x", R::kLessEqual, 8.5)), std::nullopt}};
  cases.emplace_back("target at the start, input bounds without 0", start);
  // Two initial states; a trace from the second must not start from a mix of both.
  RandomHybridAutomaton mix;
  mix.name = "mix";
  mix.variables = {{"x", std::nullopt}, {"y", std::nullopt}};
  mix.declaration_order = {{0, 0}, {0, 1}};
  mix.modes = {{"a", {}, {}, {}}, {"b", {{"x", Term(-0.5, "x")}}, {}, {}}};
  mix.inits = {{"a", {{"x", {0.0, 1.0}}, {"y", {0.0, 0.0}}}},
               {"b", {{"x", {5.0, 6.0}}, {"y", {10.0, 10.0}}}}};
  mix.properties = {
      {"p", K::kAlways,
       Both(ht::RandomPredicate::Kind::kAnd,
            Both(ht::RandomPredicate::Kind::kOr, Atom(Compare("y", R::kGreaterEqual, 10)),
                 Atom(Compare("x", R::kLessEqual, 1))),
            Atom(Compare("x", R::kLessEqual, 6.5))),
       std::nullopt}};
  cases.emplace_back("two initial states", mix);
  return cases;
}

/// A prover result claiming `verdict` (to test the attacks and replays themselves).
CheckResult Claim(const std::string& name, Verdict verdict) {
  CheckResult r;
  r.property = name;
  r.verdict = verdict;
  r.reason = "claimed by the test";
  return r;
}

TEST(SoundnessTest, IssueTankTextIsTheIssueModel) {
  const std::string text = IssueTank().Text();
  const System system = ParseModel(text, "tank.ha");
  EXPECT_NE(text.find("input d in [-0.2, 0];"), std::string::npos) << text;
  EXPECT_NE(text.find("mode fill { h' = 0.5 + d; inv h <= 8; }"), std::string::npos) << text;
  EXPECT_NE(text.find("property stays_below_6: always h <= 6;"), std::string::npos) << text;
  EXPECT_NE(text.find("property reaches_7: reach h >= 7;"), std::string::npos) << text;
  EXPECT_EQ(system.properties().size(), 2u);
}

// The attacks find the issue's false claims: the oracle catches the `d` capture whatever the
// prover says today.
TEST(SoundnessTest, AttacksRefuteTheIssueFalseClaims) {
  const RandomHybridAutomaton tank = IssueTank();
  std::mt19937_64 rng(1);
  Summary s;
  AttackClaims(
      tank, {Claim("stays_below_6", Verdict::kProved), Claim("reaches_7", Verdict::kUnreachable)},
      "issue tank", kDefaultAttacks, rng, s);
  ASSERT_EQ(s.contradictions.size(), 2u);
  EXPECT_NE(s.contradictions[0].find("always h <= 6"), std::string::npos) << s.contradictions[0];
  EXPECT_NE(s.contradictions[1].find("reach h >= 7"), std::string::npos) << s.contradictions[1];
}

// True claims survive: h stops at the invariant's boundary 8 (the run ends there), so
// `always h <= 8` holds and `reach h >= 8.5` is unreachable.
TEST(SoundnessTest, AttacksLeaveTrueClaimsAlone) {
  RandomHybridAutomaton tank = IssueTank();
  tank.properties[0].predicate.comparison.rhs = 8.0;
  tank.properties[1].predicate.comparison.rhs = 8.5;
  std::mt19937_64 rng(2);
  Summary s;
  AttackClaims(
      tank, {Claim("stays_below_6", Verdict::kProved), Claim("reaches_7", Verdict::kUnreachable)},
      "true tank", kDefaultAttacks, rng, s);
  EXPECT_TRUE(s.contradictions.empty()) << s.contradictions[0];
  EXPECT_EQ(s.attacks, kDefaultAttacks);
  EXPECT_EQ(s.rejected, 0);
  EXPECT_GT(s.states, 10 * kDefaultAttacks);
}

// A lazy transition may fire at any time its guard holds; the simulator alone fires it as late
// as possible. Reaching `down` with x < 4.5 needs an early choice: the attacks' choice inputs
// make it.
TEST(SoundnessTest, LazyChoicesFireEarly) {
  RandomHybridAutomaton a;
  a.name = "choice";
  a.variables = {{"x", std::nullopt}};
  a.declaration_order = {{0, 0}};
  const ht::RandomSum x{{{1.0, {"x"}}}};
  a.modes = {
      {"up", {{"x", ht::RandomSum{{{1.0, {}}}}}}, {{x, ht::RandomRelation::kLessEqual, 5.0}}, {}},
      {"down", {}, {}, {}}};
  ht::RandomTransition t;
  t.name = "fall";
  t.source = "up";
  t.target = "down";
  t.guard = {{x, ht::RandomRelation::kGreaterEqual, 1.0}};
  t.urgency = ht::RandomTransition::Urgency::kLazy;
  a.transitions = {t};
  a.inits = {{"up", {{"x", {0.0, 0.0}}}}};
  ht::RandomPredicate in_down, early;
  in_down.kind = ht::RandomPredicate::Kind::kInMode;
  in_down.mode = "down";
  early.comparison = {x, ht::RandomRelation::kLess, 4.5};
  ht::RandomPredicate both;
  both.kind = ht::RandomPredicate::Kind::kAnd;
  both.operands = {in_down, early};
  a.properties = {{"early", RandomProperty::Kind::kReach, both, std::nullopt}};
  std::mt19937_64 rng(3);
  Summary s;
  AttackClaims(a, {Claim("early", Verdict::kUnreachable)}, "lazy", kDefaultAttacks, rng, s);
  ASSERT_EQ(s.contradictions.size(), 1u);
  EXPECT_NE(s.contradictions[0].find("zz_lazy_choice_0"), std::string::npos) << s.contradictions[0];
}

// A trace that does not reach the violation it claims is reported; one that does is counted.
TEST(SoundnessTest, ReplaysCheckTraces) {
  const RandomHybridAutomaton tank = IssueTank();
  const System system = ParseModel(tank.Text(), "tank.ha");
  const auto input = system.symbols().Find("d");
  ASSERT_TRUE(input.has_value());
  CheckResult r = Claim("stays_below_6", Verdict::kViolated);
  r.trace.emplace();
  r.trace->inputs.until = 1.0;  // h reaches at most 5.5
  r.trace->inputs.inputs = {{*input, InputSignal::Shape::kStep, {{0.0, 0.0}}}};
  Summary forged;
  ht::ReplayTraceBySimulation(tank, system, 0, r, "forged", forged);
  ASSERT_EQ(forged.contradictions.size(), 1u);
  EXPECT_NE(forged.contradictions[0].find("TRACE DOES NOT REPLAY"), std::string::npos);
  r.trace->inputs.until = 3.0;  // h reaches 6.5
  Summary genuine;
  ht::ReplayTraceBySimulation(tank, system, 0, r, "genuine", genuine);
  EXPECT_TRUE(genuine.contradictions.empty()) << genuine.contradictions[0];
  EXPECT_EQ(genuine.replays, 1);
  r.trace->inputs.inputs[0].points = {{0.0, 0.5}};  // outside d's bounds
  Summary outside;
  ht::ReplayTraceBySimulation(tank, system, 0, r, "outside", outside);
  ASSERT_EQ(outside.contradictions.size(), 1u);
  EXPECT_NE(outside.contradictions[0].find("IS NO RUN OF THE MODEL"), std::string::npos);
}

// The generator's models parse (also with lazy choices and every init first), use every name of
// the pool, and cover the shapes the issue asks for.
TEST(SoundnessTest, GeneratedModelsParseAndCoverTheIssueShapes) {
  std::mt19937_64 rng(kDefaultSeed);
  std::map<std::string, int> seen;
  std::set<std::string> names;
  for (int i = 0; i < 2000; ++i) {
    const RandomHybridAutomaton a = ht::GenerateRandomAutomaton(rng);
    ASSERT_NO_THROW(ParseModel(a.Text(), "random.ha")) << a.Text();
    for (int init = 0; init < static_cast<int>(a.inits.size()); ++init) {
      ASSERT_NO_THROW(ParseModel(a.Text({init, true}), "random.ha")) << a.Text({init, true});
    }
    const std::string text = a.Text();
    for (const ht::RandomInput& in : a.inputs) {
      seen[in.lo < 0 && in.hi == 0    ? "[-a, 0]"
           : in.lo == 0 && in.hi > 0  ? "[0, a]"
           : in.lo == 0 && in.hi == 0 ? "[0, 0]"
           : in.lo < 0 && in.hi > 0   ? "[-a, b]"
           : in.lo > 0                ? "[a, b]"
                                      : "[-b, -a]"]++;
      if (in.name == "d" && in.hi <= 0 && text.find("+ d;") != std::string::npos)
        seen["flow + d"]++;
    }
    for (const ht::RandomTransition& t : a.transitions) {
      seen["urgency " + std::to_string(static_cast<int>(t.urgency))]++;
      if (!t.resets.empty()) seen["reset"]++;
    }
    for (const ht::RandomParameter& p : a.parameters) seen[p.range ? "uncertain" : "fixed"]++;
    for (const RandomProperty& p : a.properties) {
      seen[KindName(p.kind)]++;
      if (p.within) seen["within"]++;
    }
    if (a.inits.size() > 1) seen["two inits"]++;
    for (const ht::RandomMode& m : a.modes) {
      for (const ht::RandomRate& r : m.rates) seen[r.lo < r.hi ? "rate range" : "rate point"]++;
    }
    if (!RatedVariables(a).empty()) {
      ht::PrintOptions explicit_rates;
      explicit_rates.explicit_rates = true;
      ASSERT_NO_THROW(ParseModel(a.Text(explicit_rates), "random.ha")) << a.Text(explicit_rates);
    }
    for (const ht::RandomInit& init : a.inits) {
      for (const auto& [v, range] : init.values) {
        if (range.first < range.second) seen["interval init"]++;
      }
    }
    for (const char* shape : {" > ", " < ", "*", "' = 0;", " := -", " in "}) {
      if (text.find(shape) != std::string::npos) seen[shape]++;
    }
    names.insert(a.name);
    for (const auto& v : a.variables) names.insert(v.name);
    for (const auto& in : a.inputs) names.insert(in.name);
    for (const auto& p : a.parameters) names.insert(p.name);
    for (const auto& m : a.modes) names.insert(m.name);
    for (const auto& t : a.transitions) names.insert(t.name);
    for (const auto& p : a.properties) names.insert(p.name);
  }
  for (const char* shape :
       {"[-a, 0]",       "[0, a]",     "[0, 0]",    "[-a, b]",   "[a, b]", "[-b, -a]",
        "flow + d",      "urgency 0",  "urgency 1", "urgency 2", "reset",  "uncertain",
        "fixed",         "always",     "never",     "reach",     "within", "two inits",
        "interval init", " > ",        " < ",       "*",         "' = 0;", " := -",
        " in ",          "rate range", "rate point"}) {
    EXPECT_GT(seen[shape], 0) << shape;
  }
  for (const std::string& n : ht::ShortNamePool()) EXPECT_TRUE(names.count(n)) << n;
}

// The differential test: the issue's model, then random models; see the file comment.
// The differential test itself: 300 models (and the known cases) in CI, about 10 s; more with
// HYBRID_SOUNDNESS_MODELS (docs/soundness.md).
// Runs the differential test of `check` (see the file comment) on the known cases and the
// random models the environment asks for; `what` names the engine in the summary.
void RunDifferentialTest(const Checker& check, const std::string& what, int default_models,
                         const ht::RandomAutomatonOptions& options = {}) {
  const Settings settings = SettingsFromEnvironment(default_models);
  std::cout << what << " soundness: seed " << settings.seed << " (HYBRID_SOUNDNESS_SEED), models "
            << settings.models << " (HYBRID_SOUNDNESS_MODELS) from " << settings.first
            << " (HYBRID_SOUNDNESS_FIRST), attacks " << settings.attacks
            << " (HYBRID_SOUNDNESS_ATTACKS)" << std::endl;
  Summary s;
  for (const auto& [label, a] : KnownCases()) {
    std::mt19937_64 rng(settings.seed);
    CheckAutomaton(a, label, settings.attacks, rng, s, check);
  }
  for (int i = 0; i < settings.models; ++i) {
    const std::uint64_t index = settings.first + static_cast<std::uint64_t>(i);
    std::mt19937_64 rng(ModelSeed(settings.seed, index));
    const RandomHybridAutomaton a = ht::GenerateRandomAutomaton(rng, options);
    const std::string label =
        "seed " + std::to_string(settings.seed) + ", model " + std::to_string(index) +
        ": HYBRID_SOUNDNESS_FIRST=" + std::to_string(index) + " HYBRID_SOUNDNESS_MODELS=1";
    CheckAutomaton(a, label, settings.attacks, rng, s, check);
    if ((i + 1) % 1000 == 0) {  // progress of long runs
      std::cout << "  ... " << i + 1 << " models, " << s.contradictions.size()
                << " contradictions so far" << std::endl;
    }
  }
  std::cout << what << " " << SummaryText(settings, KnownCases().size(), s) << std::flush;
  for (const std::string& c : s.contradictions) ADD_FAILURE() << c;
}

TEST(SoundnessTest, ProverVerdictsSurviveSimulation) {
  RunDifferentialTest(Prove, "prove", kDefaultModels);
}

// The same differential test on models whose modes are mostly separable (RandomDynamics::
// kSeparable: a driver w' = c u and polynomial laws K phi(w) u, the finger's phase-3 shape),
// where the prover asks the step from such a mode one move at a time and nlsat decides the
// law: 100 models by default.
TEST(SoundnessTest, ProverVerdictsSurviveSimulationOnSeparableFlows) {
  RunDifferentialTest(Prove, "prove (separable flows)", 100, {ht::RandomDynamics::kSeparable});
}

// The same differential test for polyhedral reachability (--method reach): its `proved` and
// `unreachable` claims attacked, its traces (with their lazy-jump schedules) replayed. 100 models
// by default (about 40 s, several times that under the sanitizers); HYBRID_SOUNDNESS_MODELS for
// more (docs/soundness.md).
TEST(SoundnessTest, ReachabilityVerdictsSurviveSimulation) {
  RunDifferentialTest(Reach, "reach", 100);
}

}  // namespace
}  // namespace hybrid
