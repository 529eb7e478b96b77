// Differential soundness test of the flowpipe engine (`hybrid check --method flowpipe`,
// include/hybrid/flowpipe/flowpipe_reachability.h), the counterpart of the prover's
// (tests/solvers/verification/soundness_test.cc, docs/soundness.md). Random automata whose flows
// are mostly affine in the state, sometimes polynomial (tests/test_utilities/
// random_hybrid_automata.h, RandomDynamics::kAffine: `x' = -0.4*x + 2 + u`,
// `x' = 0.3*y - 0.2*x`, `x' = y; y' = -x - 0.1*x*x*y`), with inputs, uncertain parameters,
// invariants, urgent and lazy guards, resets, several init declarations and `within T`
// properties, are generated as model-language text and checked by FlowpipeReachability on every
// declared property, with a small deterministic budget. Then every `proved` and `unreachable`
// verdict is attacked by simulations of concrete runs (tests/test_utilities/soundness_attack.h:
// random parameter values, initial states, step inputs, rates and lazy jump times), each recorded
// state up to the claim's horizon judged by the generator's own evaluator: the property's
// `within T`, and CheckResult::within for a verdict that covers the runs up to a time only (the
// budget stopped the exploration there). A state that breaks a claim by more than a relative 1e-6
// is a contradiction and fails the test with the model text, the property, the verdict and the
// simulated state (and a model text that `hybrid simulate` replays). The engine never answers
// `violated` or `reachable`; if it did, its trace would be replayed the same way. The same test
// runs on composed systems of such automata (GenerateRandomSystem, FlowpipeSystemSoundnessTest).
//
// Environment: HYBRID_FLOWPIPE_SOUNDNESS_MODELS (default 30, about 40 s of CPU in a Release
// build, nearly all of it in the engine; the long run: HYBRID_FLOWPIPE_SOUNDNESS_MODELS=10000),
// HYBRID_FLOWPIPE_SOUNDNESS_SEED (default 20261128), HYBRID_FLOWPIPE_SOUNDNESS_FIRST (index of the
// first model: rerun model i alone with FIRST=i MODELS=1), HYBRID_FLOWPIPE_SOUNDNESS_ATTACKS
// (simulations per model with a claim, default 40), HYBRID_FLOWPIPE_SOUNDNESS_STEPS (the engine's
// Taylor steps per model, default 20000: a smaller budget checks more models per hour, with more
// claims `proved within T`), HYBRID_FLOWPIPE_SOUNDNESS_VERBOSE=1 (a line per model: the engine's
// steps, entries, CPU seconds and verdicts). The engine's cost per step varies a hundredfold
// between models (a 3-variable polynomial model with uncertain parameters takes up to a minute for
// its 20000 steps), so the default run is short.
//
//   cmake --build build --target flowpipe_soundness_test
//   build/tests/flowpipe_soundness_test                                  # 30 models, as in CI
//   HYBRID_FLOWPIPE_SOUNDNESS_MODELS=10000 nice build/tests/flowpipe_soundness_test
//       --gtest_filter='*FlowpipeVerdictsSurviveSimulation'               # the long run (1 line)
//   HYBRID_FLOWPIPE_SOUNDNESS_FIRST=63 HYBRID_FLOWPIPE_SOUNDNESS_MODELS=1
//       HYBRID_FLOWPIPE_SOUNDNESS_VERBOSE=1 build/tests/flowpipe_soundness_test
//       --gtest_filter='*Survive*'                                        # one model (1 line)
//
// Systems: HYBRID_FLOWPIPE_SYSTEMS_MODELS (default 5), _SEED (default 20261129), _FIRST,
// _ATTACKS (default 24), _STEPS (default 4000: systems have up to 9 variables).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"
#include "tests/test_utilities/random_hybrid_automata.h"
#include "tests/test_utilities/soundness_attack.h"

namespace hybrid {
namespace {

namespace ht = hybrid::testing;
using ht::RandomHybridAutomaton;
using ht::RandomProperty;
using R = ht::RandomRelation;
using K = RandomProperty::Kind;

constexpr std::uint64_t kDefaultSeed = 20261128;
constexpr int kDefaultModels = 30;
constexpr int kDefaultAttacks = 40;
constexpr char kEnvironmentPrefix[] = "HYBRID_FLOWPIPE_SOUNDNESS";

constexpr std::int64_t kDefaultSteps = 20000;

/// A small deterministic budget: `steps` Taylor steps (or the environment's PREFIX_STEPS; the
/// command's `--budget 1` is kFlowpipeStepsPerBudgetSecond of them) and 500 mode entries per
/// model.
FlowpipeReachability::Options FlowpipeOptions(const std::string& prefix, std::int64_t steps) {
  FlowpipeReachability::Options o;
  o.max_steps = static_cast<std::int64_t>(
      ht::EnvNumber((prefix + "_STEPS").c_str(), static_cast<std::uint64_t>(steps)));
  o.max_entries = 500;
  return o;
}

/// What the engine said, beyond the verdicts the oracle counts.
struct EngineCounts {
  int handled = 0;
  int not_handled = 0;
  std::map<std::string, int> why_not;  // Handles' reason, up to the first quote or colon
  int complete = 0;                    // explorations that ended (results for all time)
  int stopped = 0;                     // explorations the budget stopped
  std::int64_t steps = 0;
  int proved = 0;
  int unreachable = 0;
  int unknown = 0;
  int within_property = 0;   // claims about a `within T` property
  int within_verdict = 0;    // claims with CheckResult::within (proved up to the frontier only)
  double cpu_seconds = 0.0;  // the engine's, by the process clock
  bool verbose = false;      // a line per model
};

/// FlowpipeReachability on `properties` (counted in `counts`); a model outside its class
/// (Handles) gets `unknown` for every property.
std::vector<CheckResult> RunFlowpipe(const System& system, std::span<const Property> properties,
                                     EngineCounts& counts,
                                     const FlowpipeReachability::Options& options) {
  std::vector<CheckResult> results;
  std::string why;
  if (!FlowpipeReachability::Handles(system, properties, &why)) {
    ++counts.not_handled;
    ++counts.why_not[why.substr(0, why.find_first_of("':"))];
    for (const Property& p : properties) {
      CheckResult r;
      r.property = p.name;
      r.kind = p.kind;
      r.method = "flowpipe";
      r.reason = "not handled: " + why;
      results.push_back(r);
    }
  } else {
    ++counts.handled;
    FlowpipeReachability::Usage usage;
    const std::clock_t start = std::clock();
    results = FlowpipeReachability(options).Check(system, properties, &usage);
    const double cpu = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    counts.cpu_seconds += cpu;
    ++(usage.complete ? counts.complete : counts.stopped);
    counts.steps += usage.steps;
    if (counts.verbose) {
      std::cout << "    flowpipe: " << usage.steps << " steps, " << usage.entries << " entries, "
                << (usage.complete ? "complete" : "stopped") << ", " << cpu << " s CPU:";
      for (const CheckResult& r : results) {
        std::cout << " " << r.property << " " << VerdictName(r.verdict)
                  << (r.within ? " within " + std::to_string(*r.within) : "");
      }
      std::cout << std::endl;
    }
  }
  for (std::size_t i = 0; i < results.size() && i < properties.size(); ++i) {
    const CheckResult& r = results[i];
    if (r.verdict == Verdict::kUnknown) ++counts.unknown;
    if (r.verdict != Verdict::kProved && r.verdict != Verdict::kUnreachable) continue;
    ++(r.verdict == Verdict::kProved ? counts.proved : counts.unreachable);
    if (properties[i].horizon) ++counts.within_property;
    if (r.within) ++counts.within_verdict;
  }
  return results;
}

/// The checker under test: the flowpipe on every property the model declares.
ht::Checker Flowpipe(EngineCounts& counts) {
  return [&counts,
          options = FlowpipeOptions(kEnvironmentPrefix, kDefaultSteps)](const System& system) {
    return RunFlowpipe(system, system.properties(), counts, options);
  };
}

// ---- known cases: small models of each shape, checked first whatever the seed ----

ht::RandomSum Sum(std::vector<ht::RandomTerm> terms) { return {std::move(terms)}; }
ht::RandomSum Var(const std::string& name) { return {{{1.0, {name}}}}; }
ht::RandomComparison Compare(const std::string& name, R r, double rhs) {
  return {Var(name), r, rhs};
}
ht::RandomPredicate Atom(const ht::RandomComparison& c) {
  ht::RandomPredicate p;
  p.comparison = c;
  return p;
}
ht::RandomPredicate Both(ht::RandomPredicate a, ht::RandomPredicate b) {
  ht::RandomPredicate p;
  p.kind = ht::RandomPredicate::Kind::kAnd;
  p.operands = {std::move(a), std::move(b)};
  return p;
}

/// x' = -0.4*x + 2 from x in [0, 0.5]: x rises towards 5 and never gets there.
RandomHybridAutomaton Relaxation() {
  RandomHybridAutomaton a;
  a.name = "relax";
  a.variables = {{"x", std::nullopt}};
  a.declaration_order = {{0, 0}};
  a.modes = {{"m", {{"x", Sum({{-0.4, {"x"}}, {2.0, {}}})}}, {}, {}}};
  a.inits = {{"m", {{"x", {0.0, 0.5}}}}};
  a.properties = {{"below_5", K::kAlways, Atom(Compare("x", R::kLessEqual, 5.0)), std::nullopt},
                  {"below_4", K::kAlways, Atom(Compare("x", R::kLessEqual, 4.0)), 3.0},
                  {"over_5", K::kReach, Atom(Compare("x", R::kGreaterEqual, 5.1)), std::nullopt},
                  {"negative", K::kNever, Atom(Compare("x", R::kLess, -0.1)), std::nullopt}};
  return a;
}

/// x' = y; y' = -x - 0.1*x*x*y from x in [1, 1.1], y = 0: the energy (x^2 + y^2) / 2 never
/// grows, so |x| and |y| stay below 1.1.
RandomHybridAutomaton Oscillator() {
  RandomHybridAutomaton a;
  a.name = "osc";
  a.variables = {{"x", std::nullopt}, {"y", std::nullopt}};
  a.declaration_order = {{0, 0}, {0, 1}};
  a.modes = {
      {"m", {{"x", Var("y")}, {"y", Sum({{-1.0, {"x"}}, {-0.1, {"x", "x", "y"}}})}}, {}, {}}};
  a.inits = {{"m", {{"x", {1.0, 1.1}}, {"y", {0.0, 0.0}}}}};
  a.properties = {
      {"bounded", K::kAlways,
       Both(Atom(Compare("x", R::kLessEqual, 1.2)), Atom(Compare("x", R::kGreaterEqual, -1.2))),
       std::nullopt},
      {"fast", K::kReach, Atom(Compare("y", R::kGreaterEqual, 1.2)), std::nullopt},
      {"early", K::kAlways, Atom(Compare("x", R::kGreaterEqual, 0.0)), 1.0}};
  return a;
}

/// A thermostat with affine flows: heats towards 30 until x >= 21 (urgent), cools towards 0
/// and may switch back on once x <= 19 (lazy), at the latest at 18 (the invariant).
RandomHybridAutomaton Thermostat() {
  RandomHybridAutomaton a;
  a.name = "thermo";
  a.variables = {{"x", std::nullopt}};
  a.inputs = {{"u", -0.2, 0.2}};
  a.declaration_order = {{0, 0}, {1, 0}};
  a.modes = {{"on",
              {{"x", Sum({{-0.1, {"x"}}, {3.0, {}}, {1.0, {"u"}}})}},
              {Compare("x", R::kLessEqual, 22.0)},
              {}},
             {"off", {{"x", Sum({{-0.1, {"x"}}})}}, {Compare("x", R::kGreaterEqual, 18.0)}, {}}};
  a.transitions = {{"stop", "on", "off", {Compare("x", R::kGreaterEqual, 21.0)}, {}, {}},
                   {"start",
                    "off",
                    "on",
                    {Compare("x", R::kLessEqual, 19.0)},
                    {},
                    ht::RandomTransition::Urgency::kLazy}};
  a.inits = {{"on", {{"x", {19.5, 20.0}}}}};
  ht::RandomPredicate in_on;
  in_on.kind = ht::RandomPredicate::Kind::kInMode;
  in_on.mode = "on";
  ht::RandomPredicate on_or_warm;
  on_or_warm.kind = ht::RandomPredicate::Kind::kOr;
  on_or_warm.operands = {in_on, Atom(Compare("x", R::kGreaterEqual, 17.9))};
  a.properties = {
      {"range", K::kAlways,
       Both(Atom(Compare("x", R::kGreaterEqual, 17.9)), Atom(Compare("x", R::kLessEqual, 22.1))),
       std::nullopt},
      {"too_hot", K::kReach, Atom(Compare("x", R::kGreaterEqual, 22.5)), std::nullopt},
      {"warm", K::kAlways, on_or_warm, 20.0}};
  return a;
}

/// x' = 0.2*x + u, u in [-0.1, 0.1], from 0: |x| <= 0.5 (e^{0.2 t} - 1), below 1 until t = 5.49;
/// `always x <= 1` holds within 5 and fails later.
RandomHybridAutomaton Unstable() {
  RandomHybridAutomaton a;
  a.name = "grow";
  a.variables = {{"x", std::nullopt}};
  a.inputs = {{"u", -0.1, 0.1}};
  a.declaration_order = {{0, 0}, {1, 0}};
  a.modes = {{"m", {{"x", Sum({{0.2, {"x"}}, {1.0, {"u"}}})}}, {}, {}}};
  a.inits = {{"m", {{"x", {0.0, 0.0}}}}};
  a.properties = {
      {"small", K::kAlways, Atom(Compare("x", R::kLessEqual, 1.0)), 5.0},
      {"small_forever", K::kAlways, Atom(Compare("x", R::kLessEqual, 1.0)), std::nullopt}};
  return a;
}

/// A ball with an impulse counter: x' = v, v' = -1 from x0 in [1, 1.2] at rest; at the floor
/// v := -0.8 v, w := w - 1.8 v. Within 5 it hits twice (at sqrt(2 x0) and about 2.3 later), so
/// w reaches 1.8 * 1.8 * sqrt(2 x0) <= 5.0195: `always w <= 5.03 within 5` is tight, and its
/// proof rests on the set at each impact keeping v's relation to x0 (the crossing forms).
RandomHybridAutomaton Impacts() {
  RandomHybridAutomaton a;
  a.name = "impacts";
  a.variables = {{"x", std::nullopt}, {"v", std::nullopt}, {"w", std::nullopt}};
  a.declaration_order = {{0, 0}, {0, 1}, {0, 2}};
  a.modes = {{"move",
              {{"x", Sum({{1.0, {"v"}}})}, {"v", Sum({{-1.0, {}}})}},
              {Compare("x", R::kGreaterEqual, 0.0)},
              {}}};
  a.transitions = {{"bounce",
                    "move",
                    "move",
                    {Compare("x", R::kLessEqual, 0.0), Compare("v", R::kLessEqual, 0.0)},
                    {{"v", Sum({{-0.8, {"v"}}})}, {"w", Sum({{1.0, {"w"}}, {-1.8, {"v"}}})}},
                    {}}};
  a.inits = {{"move", {{"x", {1.0, 1.2}}, {"v", {0.0, 0.0}}, {"w", {0.0, 0.0}}}}};
  a.properties = {{"tight", K::kAlways, Atom(Compare("w", R::kLessEqual, 5.03)), 5.0},
                  {"loose", K::kAlways, Atom(Compare("w", R::kLessEqual, 5.2)), 5.0}};
  return a;
}

std::vector<std::pair<std::string, RandomHybridAutomaton>> KnownCases() {
  return {{"relaxation", Relaxation()},
          {"oscillator", Oscillator()},
          {"thermostat", Thermostat()},
          {"unstable", Unstable()},
          {"impacts", Impacts()}};
}

CheckResult Claim(const std::string& name, Verdict verdict, std::optional<double> within = {}) {
  CheckResult r;
  r.property = name;
  r.verdict = verdict;
  r.reason = "claimed by the test";
  r.within = within;
  return r;
}

std::string EngineText(const EngineCounts& c) {
  std::ostringstream out;
  out << "  flowpipe: models handled " << c.handled << ", not handled " << c.not_handled;
  for (const auto& [why, n] : c.why_not) out << " (" << n << "x " << why << ")";
  out << "; explorations complete " << c.complete << ", stopped by the budget " << c.stopped
      << "; Taylor steps " << c.steps << "\n  claims: proved " << c.proved << ", unreachable "
      << c.unreachable << "; bounded: by the property's `within` " << c.within_property
      << ", by CheckResult::within " << c.within_verdict << "; unknown verdicts " << c.unknown
      << "\n  engine CPU " << c.cpu_seconds << " s\n";
  return out.str();
}

// ---- tests of the test ----

/// Whether some flow of `a` has a term with two or more variable factors.
bool HasPolynomialFlow(const RandomHybridAutomaton& a) {
  for (const ht::RandomMode& m : a.modes) {
    for (const auto& [v, rhs] : m.flows) {
      for (const ht::RandomTerm& t : rhs.terms) {
        const auto variables =
            std::count_if(t.factors.begin(), t.factors.end(), [&](const auto& f) {
              return std::any_of(a.variables.begin(), a.variables.end(),
                                 [&](const auto& x) { return x.name == f; });
            });
        if (variables >= 2) return true;
      }
    }
  }
  return false;
}

// The attacks refute false claims, and read a claim's horizon: `always x <= 4` fails at
// t = 4.02 (from x = 0), so it is refuted when claimed for all time, spared when claimed up to
// t = 3 by CheckResult::within or by the property's own `within 3`.
TEST(FlowpipeSoundnessTest, AttacksRefuteFalseClaimsAndReadHorizons) {
  RandomHybridAutomaton a = Relaxation();
  a.inits = {{"m", {{"x", {0.0, 0.0}}}}};
  a.properties[1].within.reset();  // below_4 for all time
  ht::AttackOptions capped;
  capped.cap_horizon = true;
  {
    std::mt19937_64 rng(1);
    ht::SoundnessSummary s;
    ht::AttackClaims(a,
                     {Claim("below_5", Verdict::kProved), Claim("below_4", Verdict::kProved),
                      Claim("over_5", Verdict::kUnknown), Claim("negative", Verdict::kProved)},
                     "false claim", kDefaultAttacks, rng, s);
    ASSERT_EQ(s.contradictions.size(), 1u);
    EXPECT_NE(s.contradictions[0].find("always x <= 4;"), std::string::npos) << s.contradictions[0];
    EXPECT_EQ(s.claims, 3);
    EXPECT_EQ(s.bounded_claims, 0);
  }
  for (const bool cap : {false, true}) {
    std::mt19937_64 rng(2);
    ht::SoundnessSummary s;
    ht::AttackClaims(a,
                     {Claim("below_5", Verdict::kProved), Claim("below_4", Verdict::kProved, 3.0),
                      Claim("over_5", Verdict::kUnreachable), Claim("negative", Verdict::kProved)},
                     "bounded claim", kDefaultAttacks, rng, s, cap ? capped : ht::AttackOptions{});
    EXPECT_TRUE(s.contradictions.empty()) << s.contradictions[0];
    EXPECT_EQ(s.claims, 4);
    EXPECT_EQ(s.bounded_claims, 1);
    EXPECT_EQ(s.attacks, kDefaultAttacks);
  }
  a.properties[1].within = 3.0;  // `always x <= 4 within 3`
  {
    std::mt19937_64 rng(3);
    ht::SoundnessSummary s;
    ht::AttackClaims(a, {Claim("below_5", Verdict::kUnknown), Claim("below_4", Verdict::kProved)},
                     "within 3", kDefaultAttacks, rng, s, capped);
    EXPECT_TRUE(s.contradictions.empty()) << s.contradictions[0];
    EXPECT_EQ(s.bounded_claims, 1);
  }
  a.properties[1].within = 4.5;  // fails at 4.02
  {
    std::mt19937_64 rng(4);
    ht::SoundnessSummary s;
    ht::AttackClaims(a, {Claim("below_5", Verdict::kUnknown), Claim("below_4", Verdict::kProved)},
                     "within 4.5", kDefaultAttacks, rng, s, capped);
    EXPECT_EQ(s.contradictions.size(), 1u);
  }
}

// Polynomial flows are simulated as written: the oscillator's `always x >= 0 within 1` holds
// (x = cos t roughly, 0 at t = 1.57), `within 2` does not.
TEST(FlowpipeSoundnessTest, AttacksFollowPolynomialFlows) {
  RandomHybridAutomaton a = Oscillator();
  std::mt19937_64 rng(5);
  ht::SoundnessSummary holds;
  ht::AttackClaims(a,
                   {Claim("bounded", Verdict::kProved), Claim("fast", Verdict::kUnreachable),
                    Claim("early", Verdict::kProved)},
                   "oscillator", kDefaultAttacks, rng, holds);
  EXPECT_TRUE(holds.contradictions.empty()) << holds.contradictions[0];
  a.properties[2].within = 2.0;
  ht::SoundnessSummary fails;
  ht::AttackClaims(a,
                   {Claim("bounded", Verdict::kUnknown), Claim("fast", Verdict::kUnknown),
                    Claim("early", Verdict::kProved)},
                   "oscillator", kDefaultAttacks, rng, fails);
  EXPECT_EQ(fails.contradictions.size(), 1u);
}

// The generator's affine models: small (1 to 3 variables and modes, initial boxes at most 0.5
// wide), parsed, in the engine's class, and of every shape the test needs.
TEST(FlowpipeSoundnessTest, GeneratedAffineModelsCoverTheShapes) {
  std::mt19937_64 rng(kDefaultSeed);
  ht::RandomAutomatonOptions options;
  options.dynamics = ht::RandomDynamics::kAffine;
  std::map<std::string, int> seen;
  int handled = 0;
  constexpr int kModels = 600;
  for (int i = 0; i < kModels; ++i) {
    const RandomHybridAutomaton a = ht::GenerateRandomAutomaton(rng, options);
    std::optional<System> system;
    ASSERT_NO_THROW(system.emplace(ParseModel(a.Text(), "random.ha"))) << a.Text();
    std::string why;
    if (FlowpipeReachability::Handles(*system, system->properties(), &why)) {
      ++handled;
    } else {
      ADD_FAILURE() << why << "\n" << a.Text();
    }
    EXPECT_GE(a.variables.size(), 1u);
    EXPECT_LE(a.variables.size(), 3u);
    EXPECT_GE(a.modes.size(), 1u);
    EXPECT_LE(a.modes.size(), 3u);
    for (const ht::RandomInit& init : a.inits) {
      for (const auto& [v, range] : init.values) {
        EXPECT_LE(range.second - range.first, 0.5 + 1e-9) << a.Text();
        if (range.first < range.second) seen["interval init"]++;
      }
    }
    if (a.inits.size() > 1) seen["two inits"]++;
    if (!a.inputs.empty()) seen["inputs"]++;
    for (const ht::RandomParameter& p : a.parameters) {
      if (p.range && p.range->first < p.range->second) seen["uncertain parameter"]++;
    }
    for (const ht::RandomMode& m : a.modes) {
      if (!m.rates.empty()) seen["rectangular rate"]++;
      if (!m.invariant.empty()) seen["invariant"]++;
      for (const auto& [v, rhs] : m.flows) {
        bool linear = false, cross = false, nonlinear = false, input = false, parameter = false;
        for (const ht::RandomTerm& t : rhs.terms) {
          int variables = 0;
          for (const std::string& f : t.factors) {
            const bool is_variable = std::any_of(a.variables.begin(), a.variables.end(),
                                                 [&](const auto& x) { return x.name == f; });
            variables += is_variable ? 1 : 0;
            input = input || std::any_of(a.inputs.begin(), a.inputs.end(),
                                         [&](const auto& u) { return u.name == f; });
            parameter = parameter || std::any_of(a.parameters.begin(), a.parameters.end(),
                                                 [&](const auto& p) { return p.name == f; });
          }
          if (variables >= 2) nonlinear = true;
          if (variables == 1 && t.factors.size() == 1) {
            (t.factors[0] == v ? linear : cross) = true;
            if (t.factors[0] == v) seen[t.coef < 0 ? "stable diagonal" : "unstable diagonal"]++;
          }
          if (variables == 1 && t.factors.size() == 2 && parameter) seen["parameter * state"]++;
        }
        if (linear && !nonlinear) seen["affine in the state"]++;
        if (cross) seen["cross term"]++;
        if (nonlinear) seen["polynomial"]++;
        if ((linear || cross) && input) seen["state and input"]++;
      }
    }
    for (const ht::RandomTransition& t : a.transitions) {
      seen[t.urgency == ht::RandomTransition::Urgency::kLazy ? "lazy" : "urgent"]++;
      if (!t.resets.empty()) seen["reset"]++;
    }
    for (const RandomProperty& p : a.properties) {
      seen[ht::KindName(p.kind)]++;
      if (p.within) seen["within"]++;
    }
  }
  EXPECT_EQ(handled, kModels);
  for (const char* shape : {"interval init",
                            "two inits",
                            "inputs",
                            "uncertain parameter",
                            "rectangular rate",
                            "invariant",
                            "stable diagonal",
                            "unstable diagonal",
                            "parameter * state",
                            "affine in the state",
                            "cross term",
                            "polynomial",
                            "state and input",
                            "lazy",
                            "urgent",
                            "reset",
                            "always",
                            "never",
                            "reach",
                            "within"}) {
    EXPECT_GT(seen[shape], 0) << shape;
  }
  // Most flows are affine in the state; some are polynomial.
  EXPECT_GT(seen["affine in the state"], seen["polynomial"]);
  EXPECT_GT(seen["polynomial"], kModels / 10);
}

// The default options draw what the generator always drew (the prover's test sees its models).
TEST(FlowpipeSoundnessTest, DefaultOptionsKeepTheModelsOfEverySeed) {
  for (std::uint64_t seed : {1ull, 20261121ull}) {
    std::mt19937_64 a(seed), b(seed);
    for (int i = 0; i < 50; ++i) {
      ASSERT_EQ(ht::GenerateRandomAutomaton(a).Text(),
                ht::GenerateRandomAutomaton(b, ht::RandomAutomatonOptions{}).Text());
    }
    EXPECT_EQ(a(), b());
  }
}

// ---- the differential test ----

TEST(FlowpipeSoundnessTest, FlowpipeVerdictsSurviveSimulation) {
  const ht::SoundnessSettings settings = ht::SoundnessSettingsFromEnvironment(
      kEnvironmentPrefix, kDefaultSeed, kDefaultModels, kDefaultAttacks);
  std::cout << "flowpipe soundness: seed " << settings.seed << " (" << kEnvironmentPrefix
            << "_SEED), models " << settings.models << " (" << kEnvironmentPrefix
            << "_MODELS) from " << settings.first << " (" << kEnvironmentPrefix
            << "_FIRST), attacks " << settings.attacks << " (" << kEnvironmentPrefix << "_ATTACKS)"
            << std::endl;
  EngineCounts counts;
  counts.verbose = ht::EnvNumber("HYBRID_FLOWPIPE_SOUNDNESS_VERBOSE", 0) != 0;
  const ht::Checker check = Flowpipe(counts);
  ht::AttackOptions attack;
  attack.cap_horizon = true;  // claims `proved within T` are attacked by runs up to T
  ht::SoundnessSummary s;
  const auto known = KnownCases();
  for (const auto& [label, a] : known) {
    std::mt19937_64 rng(settings.seed);
    ht::CheckAutomaton(a, label, settings.attacks, rng, s, check, attack);
  }
  ht::RandomAutomatonOptions options;
  options.dynamics = ht::RandomDynamics::kAffine;
  for (int i = 0; i < settings.models; ++i) {
    const std::uint64_t index = settings.first + static_cast<std::uint64_t>(i);
    std::mt19937_64 rng(ht::ModelSeed(settings.seed, index));
    const RandomHybridAutomaton a = ht::GenerateRandomAutomaton(rng, options);
    const std::string label = "seed " + std::to_string(settings.seed) + ", model " +
                              std::to_string(index) + ": " + kEnvironmentPrefix +
                              "_FIRST=" + std::to_string(index) + " " + kEnvironmentPrefix +
                              "_MODELS=1";
    if (counts.verbose) std::cout << "  model " << index << std::endl;
    ht::CheckAutomaton(a, label, settings.attacks, rng, s, check, attack);
    if ((i + 1) % 1000 == 0) {  // progress of long runs
      std::cout << "  ... " << i + 1 << " models, " << s.contradictions.size()
                << " contradictions so far" << std::endl;
    }
  }
  std::cout << "flowpipe " << ht::SummaryText(settings, known.size(), s) << EngineText(counts)
            << std::flush;
  ::testing::Test::RecordProperty("models", s.models);
  ::testing::Test::RecordProperty("claims", s.claims);
  ::testing::Test::RecordProperty("claims_proved", counts.proved);
  ::testing::Test::RecordProperty("claims_unreachable", counts.unreachable);
  ::testing::Test::RecordProperty("claims_bounded", s.bounded_claims);
  ::testing::Test::RecordProperty("claims_within_verdict", counts.within_verdict);
  ::testing::Test::RecordProperty("attacks", static_cast<int>(s.attacks));
  ::testing::Test::RecordProperty("contradictions", static_cast<int>(s.contradictions.size()));
  ::testing::Test::RecordProperty("unknown", counts.unknown);
  EXPECT_GT(s.claims, 0) << "the engine proved nothing: the test attacked no claim";
  for (const std::string& c : s.contradictions) ADD_FAILURE() << c;
}

// ---- the composed-system variant ----

constexpr std::uint64_t kDefaultSystemSeed = 20261129;
constexpr int kDefaultSystems = 5;
/// Systems have up to 9 variables, and a step costs up to some milliseconds.
constexpr std::int64_t kDefaultSystemSteps = 4000;
constexpr int kDefaultSystemAttacks = 24;
constexpr char kSystemEnvironmentPrefix[] = "HYBRID_FLOWPIPE_SYSTEMS";

/// Checks system `model` with the flowpipe (its properties in the model's order) and attacks
/// every claim; a verdict `violated` or `reachable`, which this engine never gives, is a failure.
void CheckSystem(const ht::RandomSystem& model, const std::string& label, int attacks,
                 std::mt19937_64& rng, ht::SoundnessSummary& s, EngineCounts& counts) {
  ++s.models;
  const std::string text = model.Text();
  std::optional<System> system;
  std::vector<Property> properties;
  try {
    system.emplace(ParseModel(text, "system.ha"));
    for (const RandomProperty& p : model.properties) {
      const auto it = std::find_if(system->properties().begin(), system->properties().end(),
                                   [&](const Property& q) { return q.name == p.name; });
      if (it == system->properties().end()) throw std::runtime_error("no property " + p.name);
      properties.push_back(*it);
    }
  } catch (const std::exception& e) {
    s.contradictions.push_back("=== GENERATED SYSTEM DOES NOT PARSE (" + label + "): " + e.what() +
                               " ===\n" + text);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<CheckResult> results;
  try {
    results = RunFlowpipe(*system, properties, counts,
                          FlowpipeOptions(kSystemEnvironmentPrefix, kDefaultSystemSteps));
  } catch (const std::exception& e) {
    s.contradictions.push_back("=== CHECKER THREW (" + label + "): " + e.what() + " ===\n" + text);
    return;
  }
  const auto checked = std::chrono::steady_clock::now();
  s.prover_seconds += std::chrono::duration<double>(checked - start).count();
  if (results.size() != properties.size()) {
    s.contradictions.push_back("=== NOT ONE RESULT PER PROPERTY (" + label + ") ===\n" + text);
    return;
  }
  for (std::size_t i = 0; i < results.size(); ++i) {
    ++s.verdicts[ht::KindName(model.properties[i].kind) + " " +
                 ht::VerdictText(results[i].verdict)];
    if (results[i].verdict == Verdict::kViolated || results[i].verdict == Verdict::kReachable) {
      s.contradictions.push_back(
          "=== THE FLOWPIPE ANSWERED `" + ht::VerdictText(results[i].verdict) + "` (" + label +
          ") ===\nproperty: " + model.PropertyText(static_cast<int>(i)) + "\n" + text);
    }
  }
  ht::AttackOptions options;
  options.cap_horizon = true;
  ht::AttackSystemClaims(model, results, label, attacks, rng, s, options);
  s.attack_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - checked).count();
}

// The generator's systems of affine automata parse, and the flowpipe handles them.
TEST(FlowpipeSystemSoundnessTest, GeneratedAffineSystemsAreHandled) {
  ht::RandomSystemOptions options;
  options.automata.dynamics = ht::RandomDynamics::kAffine;
  std::mt19937_64 rng(kDefaultSystemSeed);
  int polynomial = 0;
  for (int i = 0; i < 200; ++i) {
    const ht::RandomSystem model = ht::GenerateRandomSystem(rng, options);
    ASSERT_EQ(model.conflict, ht::RandomConflict::kNone);
    std::optional<System> system;
    ASSERT_NO_THROW(system.emplace(ParseModel(model.Text(), "system.ha"))) << model.Text();
    std::string why;
    EXPECT_TRUE(FlowpipeReachability::Handles(*system, system->properties(), &why)) << why << "\n"
                                                                                    << model.Text();
    polynomial += std::count_if(model.automata.begin(), model.automata.end(), HasPolynomialFlow);
    if (i < 50) {  // the texts of concrete runs parse too (an initial state may be refused)
      const ht::SystemSimulation sim = ht::SimulateSystem(model, ht::DrawSystemAttack(model, rng));
      EXPECT_TRUE(sim.error.empty() || sim.error.find("initial state") != std::string::npos)
          << sim.error << "\n"
          << sim.text;
    }
  }
  EXPECT_GT(polynomial, 0);
}

// The same differential test on composed systems (GenerateRandomSystem of affine automata: 1 to
// 3 instances, shared and bound variables, inputs, labels, parameters and discrete variables):
// 5 systems by default, 4000 Taylor steps each (HYBRID_FLOWPIPE_SYSTEMS_MODELS, _SEED, _FIRST,
// _ATTACKS, _STEPS).
TEST(FlowpipeSystemSoundnessTest, FlowpipeVerdictsOnSystemsSurviveSimulation) {
  const ht::SoundnessSettings settings = ht::SoundnessSettingsFromEnvironment(
      kSystemEnvironmentPrefix, kDefaultSystemSeed, kDefaultSystems, kDefaultSystemAttacks);
  std::cout << "flowpipe soundness on systems: seed " << settings.seed << " ("
            << kSystemEnvironmentPrefix << "_SEED), systems " << settings.models << " ("
            << kSystemEnvironmentPrefix << "_MODELS) from " << settings.first << " ("
            << kSystemEnvironmentPrefix << "_FIRST), attacks " << settings.attacks << " ("
            << kSystemEnvironmentPrefix << "_ATTACKS)" << std::endl;
  EngineCounts counts;
  counts.verbose = ht::EnvNumber("HYBRID_FLOWPIPE_SOUNDNESS_VERBOSE", 0) != 0;
  ht::RandomSystemOptions options;
  options.automata.dynamics = ht::RandomDynamics::kAffine;
  ht::SoundnessSummary s;
  for (int i = 0; i < settings.models; ++i) {
    const std::uint64_t index = settings.first + static_cast<std::uint64_t>(i);
    std::mt19937_64 rng(ht::ModelSeed(settings.seed, index));
    const ht::RandomSystem model = ht::GenerateRandomSystem(rng, options);
    const std::string label = "seed " + std::to_string(settings.seed) + ", system " +
                              std::to_string(index) + ": " + kSystemEnvironmentPrefix +
                              "_FIRST=" + std::to_string(index) + " " + kSystemEnvironmentPrefix +
                              "_MODELS=1";
    if (counts.verbose) std::cout << "  system " << index << std::endl;
    CheckSystem(model, label, settings.attacks, rng, s, counts);
    if ((i + 1) % 100 == 0) {
      std::cout << "  ... " << i + 1 << " systems, " << s.contradictions.size()
                << " contradictions so far" << std::endl;
    }
  }
  std::cout << "flowpipe (systems) " << ht::SummaryText(settings, 0, s) << EngineText(counts)
            << std::flush;
  for (const std::string& c : s.contradictions) ADD_FAILURE() << c;
}

}  // namespace
}  // namespace hybrid
