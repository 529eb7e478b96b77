// Differential test across engines and compositions (docs/soundness.md, "Engine agreement"):
// one meaning of a model for every engine. Random systems of 1 to 3 instances with shared and
// bound variables, inputs, labels, parameters and discrete variables, derived and uncertain
// parameters, strict and non-strict invariants and guards, urgent and lazy transitions and several
// init declarations are generated as model-language text (tests/test_utilities/
// random_hybrid_automata.h, GenerateRandomSystem) and every property is checked by every engine:
// polyhedral reachability (`check --method reach`), flowpipes (`flowpipe`), the SMT prover
// (`prove`) and the sampler (`sample`), each with a small deterministic budget. Then:
// - every `proved` and `unreachable` verdict is attacked by simulations of concrete runs written
//   back as model text (random values of the uncertain parameters, a random init declaration per
//   instance with random values in its boxes, random step inputs, lazy transitions at random
//   times), the properties judged by the generator's own evaluator: a state that breaks a claim
//   beyond a relative 1e-6 is a contradiction;
// - every `violated` and `reachable` verdict must carry a trace that ReplayTrace confirms and
//   that, written back as model text and simulated, reaches the violation (or the target) by the
//   generator's evaluator;
// - two definite verdicts of different engines that disagree (proved vs violated, unreachable vs
//   reachable) are a disagreement;
// - a few systems are given a conflict on purpose (a shared variable started at two values, an
//   input with two bounds, a discrete variable given values by two instances, a variable reset by
//   two synchronised transitions): the parser must refuse them with the conflict's message.
// Every failure prints the model text and the verdicts of every engine.
//
// Environment: HYBRID_AGREEMENT_SYSTEMS (default 200), HYBRID_AGREEMENT_SEED (default 20261127),
// HYBRID_AGREEMENT_FIRST (index of the first system: rerun system i alone with FIRST=i
// SYSTEMS=1), HYBRID_AGREEMENT_ATTACKS (simulations per system with a claim, default 24).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "hybrid/verification/property_sampler.h"
#include "tests/test_utilities/random_hybrid_automata.h"
#include "tests/test_utilities/soundness_attack.h"

namespace hybrid {
namespace {

namespace ht = hybrid::testing;
using ht::RandomProperty;
using ht::RandomSystem;
using Rng = std::mt19937_64;

constexpr std::uint64_t kDefaultSeed = 20261127;
constexpr int kDefaultSystems = 200;
constexpr int kDefaultAttacks = 24;
/// Percent of the systems given a conflict on purpose.
constexpr int kConflictPercent = 6;
/// A claim is contradicted only by a state that breaks it by more than this (relative).
constexpr double kTolerance = 1e-6;
/// A `violated` trace must break its property by at least this (relative) on replay.
constexpr double kConfirmTolerance = 1e-9;

using ht::EnvNumber;  // a non-negative integer from the environment, or a fallback

struct Settings {
  std::uint64_t seed = kDefaultSeed;
  std::uint64_t first = 0;
  int systems = kDefaultSystems;
  int attacks = kDefaultAttacks;
};

Settings SettingsFromEnvironment(int default_systems = kDefaultSystems) {
  Settings s;
  s.seed = EnvNumber("HYBRID_AGREEMENT_SEED", kDefaultSeed);
  s.first = EnvNumber("HYBRID_AGREEMENT_FIRST", 0);
  s.systems = static_cast<int>(EnvNumber("HYBRID_AGREEMENT_SYSTEMS", default_systems));
  s.attacks = static_cast<int>(EnvNumber("HYBRID_AGREEMENT_ATTACKS", kDefaultAttacks));
  return s;
}

/// The seed of system `index` (SplitMix64 of seed and index): every system is reproducible alone.
std::uint64_t SystemSeed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// System `index` of `seed`, its automata's flows drawn as `dynamics` says, its instances
/// independent (RandomSystemOptions::independent_instances) if asked.
RandomSystem SystemAt(std::uint64_t seed, std::uint64_t index,
                      ht::RandomDynamics dynamics = ht::RandomDynamics::kMixed,
                      bool independent = false) {
  Rng rng(SystemSeed(seed, index));
  ht::RandomSystemOptions options;
  options.conflict_percent = kConflictPercent;
  options.automata.dynamics = dynamics;
  options.independent_instances = independent;
  return ht::GenerateRandomSystem(rng, options);
}

std::string VerdictText(Verdict v) { return std::string(VerdictName(v)); }

bool Positive(Verdict v) { return v == Verdict::kViolated || v == Verdict::kReachable; }
bool Negative(Verdict v) { return v == Verdict::kProved || v == Verdict::kUnreachable; }

// ---- the engines, with small deterministic budgets ----

/// One engine's results on one system, one per property (in the order of the properties).
struct EngineRun {
  std::string engine;
  std::vector<CheckResult> results;
  std::vector<std::string> errors;  // per property: what the engine threw ("" if nothing)
  double seconds = 0.0;
};

using Engine = std::function<std::vector<CheckResult>(const System&, const std::vector<Property>&)>;

/// The options of every reachability engine here: a small deterministic budget (and a bound on
/// symbolic states, as random clocks that are never reset have no fixpoint), no hulls (each
/// engine below says what it adds).
PolyhedralReachability::Options SmallReach() {
  PolyhedralReachability::Options o;
  o.budget = 0.02;  // 2 million reach units
  o.max_states = 400;
  o.cpu_seconds = 30;
  o.hull_units = 0;
  return o;
}

/// `check --method reach` with the exact exploration alone (the hulls are "reach-hull").
std::vector<CheckResult> Reach(const System& system, const std::vector<Property>& properties) {
  const PolyhedralReachability::Options o = SmallReach();
  return PolyhedralReachability(o).Check(system, properties);
}

/// Reachability with its hulls' first turn (Options::hull_units; at most a quarter of the
/// budget), so that what the hulls prove (HullExploration) is attacked and compared like every
/// other engine's verdicts.
std::vector<CheckResult> ReachHull(const System& system, const std::vector<Property>& properties) {
  PolyhedralReachability::Options o = SmallReach();
  o.hull_units = PolyhedralReachability::Options().hull_units;
  return PolyhedralReachability(o).Check(system, properties);
}

/// The same with the interaction groups' turn first (Options::group_turn_units = 0), so that on
/// systems of several groups the product of the groups decides what it can before the exact
/// exploration (by default the small random systems would be decided before the groups' first
/// turn).
std::vector<CheckResult> ReachGroupsFirst(const System& system,
                                          const std::vector<Property>& properties) {
  PolyhedralReachability::Options o = SmallReach();
  o.group_turn_units = 0;
  return PolyhedralReachability(o).Check(system, properties);
}

/// Reachability pausing at once for the quick proof of `auto` (PolyhedralReachability::Options::
/// pause: the prover at depth 1 with 1-induction answers the properties still open, and its
/// definite answers decide them), so that the answers the pause passes back are attacked and
/// compared like every other engine's.
std::vector<CheckResult> ReachPaused(const System& system,
                                     const std::vector<Property>& properties) {
  PolyhedralReachability::Options o = SmallReach();
  o.pause_units = 1;
  o.pause = [](const System& s, const std::vector<Property>& open) {
    PropertyProver::Options quick;
    quick.max_depth = 1;
    quick.max_induction = 1;
    quick.budget = 0.4;
    quick.resource_limit = 400'000;
    return PropertyProver(quick).Check(s, open);
  };
  return PolyhedralReachability(o).Check(system, properties);
}

/// `check --method prove --depth 4 --induction 2` with a small deterministic budget.
std::vector<CheckResult> Prove(const System& system, const std::vector<Property>& properties) {
  PropertyProver::Options o;
  o.max_depth = 4;
  o.max_induction = 2;
  o.budget = 0.4;  // one million Z3 resource units for the whole check
  o.resource_limit = 400'000;
  return PropertyProver(o).Check(system, properties);
}

/// The reason of a sampler's `unknown` for a model that rejected every drawn run.
constexpr char kSampleRefused[] = "the sampler refused the model: ";

/// `check --method sample` with 24 runs per property (horizon 12 unless `within T`).
std::vector<CheckResult> Sample(const System& system, const std::vector<Property>& properties) {
  std::vector<CheckResult> out;
  for (const Property& p : properties) {
    PropertySampler::Options o;
    o.runs = 24;
    o.max_segments = 4;
    if (!p.horizon) o.horizon = 12.0;
    o.max_shrink_replays = 64;
    try {
      out.push_back(PropertySampler(o).Check(system, p));
    } catch (const std::invalid_argument& e) {
      // Documented: a model that rejects every drawn run (its initial states all violate their
      // invariants: a model without runs) is refused. No verdict.
      if (std::string(e.what()).find("rejected every") == std::string::npos) throw;
      CheckResult r;
      r.property = p.name;
      r.kind = p.kind;
      r.reason = std::string(kSampleRefused) + e.what();
      out.push_back(r);
    }
  }
  return out;
}

/// `check --method flowpipe` with a small deterministic budget (400 Taylor steps, 20 mode
/// entries, no splitting of the initial set).
std::vector<CheckResult> Flowpipe(const System& system, const std::vector<Property>& properties) {
  FlowpipeReachability::Options o;
  o.max_steps = 400;
  o.max_entries = 20;
  o.max_pieces = 1;
  return FlowpipeReachability(o).Check(system, properties);
}

const std::vector<std::pair<std::string, Engine>>& Engines() {
  static const std::vector<std::pair<std::string, Engine>> engines = {
      {"reach", Reach},
      {"reach-hull", ReachHull},
      {"reach-groups-first", ReachGroupsFirst},
      {"reach-paused", ReachPaused},
      {"flowpipe", Flowpipe},
      {"prove", Prove},
      {"sample", Sample}};
  return engines;
}

/// Runs `engine` on every property at once; if it throws, on each property alone, so that a
/// throw is charged to the properties that cause it (their results are `unknown`).
EngineRun RunEngine(const std::string& name, const Engine& engine, const System& system,
                    const std::vector<Property>& properties) {
  EngineRun run{name, {}, std::vector<std::string>(properties.size()), 0.0};
  const auto start = std::chrono::steady_clock::now();
  try {
    run.results = engine(system, properties);
  } catch (const std::exception&) {
    run.results.clear();
    for (std::size_t i = 0; i < properties.size(); ++i) {
      try {
        run.results.push_back(engine(system, {properties[i]}).at(0));
      } catch (const std::exception& e) {
        run.errors[i] = e.what();
        run.results.emplace_back();
        run.results.back().reason = std::string("threw: ") + e.what();
      }
    }
  }
  if (run.results.size() != properties.size()) {
    run.results.assign(properties.size(), CheckResult{});
    run.errors.assign(properties.size(), "not one result per property");
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

// ---- summary ----

struct Summary {
  int systems = 0;
  int properties = 0;
  std::map<std::string, int> refused;  // conflicting systems refused, by kind
  std::map<std::string, std::map<std::string, int>> verdicts;  // engine -> verdict -> count
  std::map<std::string, double> seconds;                       // engine -> seconds
  int reach_outside_class = 0;  // properties reach left unknown as not linear
  int group_product = 0;   // reach's verdicts on the product of interaction groups (GroupProduct)
  int paused = 0;          // definite verdicts of reach-paused that its pause (the prover) gave
  int hull = 0;            // verdicts of reach-hull from its hulls (HullExploration)
  int sample_refused = 0;  // properties of models whose every sampled run was rejected
  int claims = 0;          // proved / unreachable verdicts (per property) attacked
  long attacks = 0;        // simulations run against claims
  long rejected = 0;       // attacks the model refused (initial state outside its invariant)
  long states = 0;         // recorded states checked against claims
  long outside = 0;        // attacks cut at a state outside its modes' invariants
  int replays = 0;         // traces confirmed by ReplayTrace
  int text_replays = 0;    // traces confirmed from model text by the test's evaluator
  int boundary_witnesses = 0;      // of which `reach` witnesses only within the tolerance
  int off_tie = 0;                 // prove's traces replayed with parameters moved off a tie
  int joint_unreachable = 0;       // prove's `unreachable` together with other targets only
  int boundary_disagreements = 0;  // disagreements whose witnesses are all such
  int agreements = 0;              // properties with definite verdicts of two engines that agree
  std::vector<std::string> contradictions;
  std::vector<std::string> disagreements;
  std::vector<std::string> trace_failures;
  std::vector<std::string> other_failures;  // parse failures, engine errors, accepted conflicts
  double attack_seconds = 0.0;
};

std::string SummaryText(const Settings& settings, const Summary& s) {
  std::ostringstream out;
  out.precision(3);
  out << "engine agreement: seed " << settings.seed << ", systems " << settings.first << ".."
      << settings.first + settings.systems - 1 << ": " << s.systems << " checked, " << s.properties
      << " properties\n  conflicting systems refused:";
  int refused = 0;
  for (const auto& [kind, n] : s.refused) {
    out << " " << kind << " " << n << ";";
    refused += n;
  }
  out << " (" << refused << ")\n";
  for (const auto& [engine, counts] : s.verdicts) {
    int definite = 0;
    out << "  " << engine << ":";
    for (const auto& [verdict, n] : counts) {
      out << " " << verdict << " " << n << ";";
      if (verdict != "unknown") definite += n;
    }
    out << " definite " << definite << "; " << s.seconds.at(engine) << " s\n";
  }
  out << "  reach outside its class (not linear): " << s.reach_outside_class
      << "; sample refused models without runs: " << s.sample_refused
      << "; reach verdicts on the product of interaction groups: " << s.group_product
      << "; reach-paused verdicts from its pause: " << s.paused
      << "; reach-hull verdicts from its hulls: " << s.hull << "\n"
      << "  claims attacked " << s.claims << ", attacks " << s.attacks << " (" << s.rejected
      << " refused by the model, " << s.outside
      << " cut at a state outside the invariants), states checked " << s.states << "\n"
      << "  traces replayed: ReplayTrace " << s.replays << ", from model text " << s.text_replays
      << " (" << s.boundary_witnesses << " of them reach witnesses within the tolerance only)"
      << "\n  prove: traces with parameters moved off a tie " << s.off_tie
      << ", unreachable only together with other targets " << s.joint_unreachable
      << "\n  properties with agreeing definite verdicts of two engines " << s.agreements
      << "\n  contradictions " << s.contradictions.size() << ", disagreements "
      << s.disagreements.size() << " (" << s.boundary_disagreements
      << " with witnesses within the tolerance only)"
      << ", trace failures " << s.trace_failures.size() << ", other failures "
      << s.other_failures.size() << "\n  attacks and replays " << s.attack_seconds << " s\n";
  return out.str();
}

// ---- concrete runs, written back as model text (tests/test_utilities/soundness_attack.h) ----

using RunChoices = ht::SystemRunChoices;
using Simulation = ht::SystemSimulation;
using ModelState = ht::SystemState;
using ht::RatedVariables;

/// A random run of `s` for an attack.
RunChoices DrawAttack(const RandomSystem& s, Rng& rng) { return ht::DrawSystemAttack(s, rng); }

Simulation Simulate(const RandomSystem& s, const RunChoices& c) { return ht::SimulateSystem(s, c); }

/// The events of a run up to state `index` (all if negative), that state, and the run's text.
std::string RunText(const Simulation& sim, int index) { return ht::SystemRunText(sim, index); }

// ---- judging states ----

/// Whether a state refutes the claim `verdict` about `p` (proved invariant, unreachable target).
bool Refutes(const RandomProperty& p, Verdict verdict, const std::map<std::string, double>& values,
             const std::set<std::string>& modes) {
  return ht::RefutesInModes(p, verdict, values, modes);
}

/// Whether a state confirms `violated` (always, never) or `reachable` (reach): a `reach` target
/// within the tolerance, as the engines' replays read it.
bool Confirms(const RandomProperty& p, const std::map<std::string, double>& values,
              const std::set<std::string>& modes) {
  switch (p.kind) {
    case RandomProperty::Kind::kAlways:
      return !ht::HoldsInModes(p.predicate, values, modes, kConfirmTolerance);
    case RandomProperty::Kind::kNever:
      return ht::HoldsInModes(p.predicate, values, modes, -kConfirmTolerance);
    case RandomProperty::Kind::kReach:
      return ht::HoldsInModes(p.predicate, values, modes, kTolerance);
  }
  return false;
}

/// Whether a state confirms `violated` or `reachable` with margin (a `reach` target included).
bool ClearlyConfirms(const RandomProperty& p, const std::map<std::string, double>& values,
                     const std::set<std::string>& modes) {
  if (p.kind != RandomProperty::Kind::kReach) return Confirms(p, values, modes);
  return ht::HoldsInModes(p.predicate, values, modes, -kConfirmTolerance);
}

/// The recorded states of `sim` up to the first one outside its modes' invariants (`*outside`
/// then).
std::vector<ModelState> ModelStates(const RandomSystem& s, const Simulation& sim, bool* outside) {
  return ht::SystemStates(s, sim, outside);
}

// ---- one system ----

/// What every engine said about one system.
struct Verdicts {
  const RandomSystem* model = nullptr;
  std::string label;
  std::vector<EngineRun> runs;
};

std::string VerdictsText(const Verdicts& v, int property) {
  std::ostringstream out;
  out << "property: " << v.model->PropertyText(property) << "\n";
  for (const EngineRun& run : v.runs) {
    if (!run.errors[property].empty()) {
      out << "  " << run.engine << ": threw: " << run.errors[property] << "\n";
      continue;
    }
    const CheckResult& r = run.results[property];
    out << "  " << run.engine << ": " << VerdictText(r.verdict) << " (" << r.reason << ")\n";
  }
  return out.str();
}

std::string Header(const std::string& what, const Verdicts& v, int property) {
  return "=== " + what + " (" + v.label + ") ===\n" + VerdictsText(v, property) +
         "--- model ---\n" + v.model->Text();
}

// ---- traces ----

/// Whether `x` lies in [lo, hi] up to a relative 1e-9.
bool Within(double x, double lo, double hi) {
  return x >= lo - 1e-9 * (1 + std::abs(lo)) && x <= hi + 1e-9 * (1 + std::abs(hi));
}

/// The system name of the explicit rate input (PrintOptions::explicit_rates) that stands for
/// the rate input `name` (`A.x'`) of a trace, or "" if `name` is none.
std::string ExplicitRateInput(const RandomSystem& s, const std::string& name) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    for (const std::string& v : RatedVariables(s.automata[s.instances[k].automaton])) {
      if (s.SystemName(k, v + "'") == name || s.SystemName(k, v) + "'" == name) {
        return s.SystemName(k, ht::RateInput(v));
      }
    }
  }
  return "";
}

/// The trace's inputs as the choices' scenario: a rate input w in [-1, 1] (rate
/// (lo + hi)/2 + (hi - lo)/2 w) becomes the explicit rate input at (w + 1) / 2 (rate
/// lo + (hi - lo) z); rate inputs the trace does not drive are 0, the midpoint.
void TraceInputs(const RandomSystem& s, const System& system, const Trace& t, RunChoices& c,
                 std::string& problem) {
  c.scenario.until = t.inputs.until;
  std::set<std::string> driven;
  for (const InputSignal& signal : t.inputs.inputs) {
    if (signal.shape != InputSignal::Shape::kStep) problem += "a signal is not a step; ";
    const std::string& name = system.symbols()[signal.slot].name;
    std::vector<std::pair<double, double>> points = signal.points;
    std::string input = name;
    if (!name.empty() && name.back() == '\'') {
      input = ExplicitRateInput(s, name);
      if (input.empty()) problem += "unknown rate input '" + name + "'; ";
      for (auto& [time, w] : points) w = (w + 1) / 2;
    }
    driven.insert(input);
    c.scenario.steps.emplace_back(input, points);
    for (const auto& [time, value] : points) c.sample_times.push_back(time);
  }
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    for (const std::string& v : RatedVariables(s.automata[s.instances[k].automaton])) {
      const std::string input = s.SystemName(k, ht::RateInput(v));
      if (driven.insert(input).second) {
        c.scenario.steps.emplace_back(input, std::vector<std::pair<double, double>>{{0.0, 0.5}});
      }
    }
  }
  c.schedule = t.schedule;  // the concrete text keeps every transition's index
  for (const ScheduledJump& j : t.schedule) c.sample_times.push_back(j.time);
  if (t.state_index >= 0 && t.state_index < static_cast<int>(t.run.samples.size())) {
    c.sample_times.push_back(t.run.samples[t.state_index].time);
  }
}

/// Checks that the trace's parameter values and initial values are admitted by the model.
void CheckTraceStart(const RandomSystem& s, const RunChoices& c, std::string& problem) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const ht::RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    for (const ht::RandomParameter& p : a.parameters) {
      const auto it = c.parameters.find(s.SystemName(k, p.name));
      if (it == c.parameters.end()) continue;
      if (!p.range || !Within(it->second, p.range->first, p.range->second)) {
        problem += "parameter " + it->first + " = " + ht::DecimalText(it->second) +
                   " is no value of an uncertain parameter; ";
      }
    }
    for (const auto& [v, range] : a.inits.at(c.inits.at(k)).values) {
      const auto it = c.initial_values.find(s.SystemName(k, v));
      if (it != c.initial_values.end() && !Within(it->second, range.first, range.second)) {
        problem += "initial value " + it->first + " = " + ht::DecimalText(it->second) +
                   " lies outside init " + std::to_string(c.inits[k]) + " of instance " +
                   std::to_string(k) + "; ";
      }
    }
  }
}

/// The run a trace describes, as choices over system names. `problem` collects what makes the
/// trace no run of the model.
RunChoices TraceChoices(const RandomSystem& s, const System& system, const Trace& t,
                        std::string& problem) {
  RunChoices c;
  c.note = "the engine's trace";
  c.inits.assign(s.instances.size(), 0);
  c.lazy_choices.assign(s.instances.size(), false);
  for (const auto& [component, index] : t.initial_states) {
    if (component < 0 || component >= static_cast<int>(s.instances.size()) || index < 0 ||
        index >= static_cast<int>(s.automata[s.instances[component].automaton].inits.size())) {
      problem += "init " + std::to_string(index) + " of component " + std::to_string(component) +
                 " does not exist; ";
      continue;
    }
    c.inits[component] = index;
  }
  for (const auto& [name, v] : t.parameters) c.parameters[name] = v;
  for (const auto& [name, v] : t.initial_values) c.initial_values[name] = v;
  CheckTraceStart(s, c, problem);
  TraceInputs(s, system, t, c, problem);
  return c;
}

/// Checks the trace of a `violated` or `reachable` verdict of `engine` on property `i`: present,
/// confirmed by ReplayTrace, and, replayed from model text, reaching the violation (target) by
/// the generator's evaluator. Returns true for a `reach` witness that meets its target only
/// within the tolerance (a state on the boundary of a strict comparison, say), false otherwise.
bool CheckTrace(const Verdicts& v, const System& system, const Property& property, int i,
                const EngineRun& run, Summary& s) {
  const RandomSystem& model = *v.model;
  const CheckResult& r = run.results[i];
  const std::string what = "`" + VerdictText(r.verdict) + "` of " + run.engine;
  if (!r.trace) {
    s.trace_failures.push_back(Header(what + " WITHOUT A TRACE", v, i));
    return false;
  }
  Trace copy = *r.trace;
  std::string replay_error;
  bool replayed = false;
  try {
    replayed = ReplayTrace(system, property, copy);
  } catch (const std::exception& e) {
    replay_error = e.what();
  }
  if (!replayed) {
    s.trace_failures.push_back(Header(what + ": ReplayTrace DOES NOT CONFIRM THE TRACE", v, i) +
                               replay_error + "\n");
    return false;
  }
  ++s.replays;
  std::string problem;
  const RunChoices c = TraceChoices(model, system, *r.trace, problem);
  const Simulation sim = Simulate(model, c);
  if (!problem.empty() || !sim.error.empty()) {
    s.trace_failures.push_back(Header(what + ": THE TRACE IS NO RUN OF THE MODEL", v, i) +
                               "--- problem ---\n" + problem + sim.error + "\n--- run ---\n" +
                               sim.text);
    return false;
  }
  bool outside = false, confirmed = false;
  const RandomProperty& p = model.properties[i];
  for (const ModelState& x : ModelStates(model, sim, &outside)) {
    if (p.within && x.time > *p.within) break;
    confirmed = confirmed || Confirms(p, x.values, x.modes);
    if (ClearlyConfirms(p, x.values, x.modes)) {
      ++s.text_replays;
      return false;
    }
  }
  if (confirmed) {  // a witness within the tolerance of the target only: noted, not a failure
    ++s.text_replays;
    ++s.boundary_witnesses;
    return true;
  }
  s.trace_failures.push_back(
      Header(what + ": THE TRACE DOES NOT REPLAY FROM MODEL TEXT", v, i) +
      (outside ? "(the replay leaves its modes' invariants before it gets there)\n" : "") +
      "--- replay ---\n" + RunText(sim, -1));
  return false;
}

// ---- attacks on claims ----

/// A `proved` or `unreachable` claim about property `property` up to time `until`
/// (ht::ClaimHorizon: the property's `within T`, a bounded proof's CheckResult::within, or
/// infinity), and the engines that made it.
struct Claim {
  int property = 0;
  Verdict verdict = Verdict::kUnknown;
  double until = std::numeric_limits<double>::infinity();
  std::vector<std::string> engines;
};

/// The claims of every engine, one per property and horizon.
std::vector<Claim> ClaimsOf(const Verdicts& v) {
  std::vector<Claim> claims;
  for (int i = 0; i < static_cast<int>(v.model->properties.size()); ++i) {
    std::map<double, Claim> by_horizon;
    for (const EngineRun& run : v.runs) {
      if (!run.errors[i].empty() || !Negative(run.results[i].verdict)) continue;
      const double until = ht::ClaimHorizon(v.model->properties[i], run.results[i]);
      Claim& c = by_horizon[until];
      c.property = i;
      c.verdict = run.results[i].verdict;
      c.until = until;
      c.engines.push_back(run.engine);
    }
    for (auto& [until, c] : by_horizon) claims.push_back(std::move(c));
  }
  return claims;
}

/// Attacks every claim with `attacks` random simulations; each claim is reported at its first
/// contradiction.
void AttackClaims(const Verdicts& v, std::vector<Claim> open, int attacks, Rng& rng, Summary& s) {
  const RandomSystem& model = *v.model;
  s.claims += static_cast<int>(open.size());
  for (int k = 0; k < attacks && !open.empty(); ++k) {
    const RunChoices c = DrawAttack(model, rng);
    const Simulation sim = Simulate(model, c);
    ++s.attacks;
    if (!sim.error.empty()) {
      ++s.rejected;
      if (sim.error.find("initial state") != std::string::npos) continue;  // no run
      // A run of the model that its own text refuses (reported once per system): a bug of the
      // test, or a model the IR accepts although one of its runs gives a symbol two meanings.
      const bool shared_parameter = sim.error.find("shared parameter") != std::string::npos;
      s.other_failures.push_back(
          "=== A RUN OF THE MODEL IS REFUSED (" + v.label + "): " + sim.error + " ===\n" +
          (shared_parameter ? "(the model shares a parameter whose definition reads parameters "
                              "of each instance: its instances give it different values)\n"
                            : "") +
          "--- model ---\n" + model.Text() + "--- run ---\n" + sim.text);
      break;
    }
    bool outside = false;
    const std::vector<ModelState> states = ModelStates(model, sim, &outside);
    s.outside += outside ? 1 : 0;
    for (const ModelState& x : states) {
      ++s.states;
      for (auto it = open.begin(); it != open.end();) {
        const RandomProperty& p = model.properties[it->property];
        if (x.time > it->until || !Refutes(p, it->verdict, x.values, x.modes)) {
          ++it;
          continue;
        }
        std::string engines;
        for (const std::string& e : it->engines) engines += (engines.empty() ? "" : ", ") + e;
        s.contradictions.push_back(Header("CONTRADICTION: `" + VerdictText(it->verdict) + "` of " +
                                              engines + " refuted by a simulation",
                                          v, it->property) +
                                   "--- counterexample: " + c.note + " ---\n" +
                                   RunText(sim, x.index));
        it = open.erase(it);
      }
    }
  }
}

// ---- comparing engines ----

/// Counts every verdict, checks that each fits its property's kind and engine, and reports
/// properties on which two engines give opposite definite verdicts.
void CompareVerdicts(const Verdicts& v, const std::set<std::pair<std::string, int>>& boundary,
                     Summary& s) {
  for (int i = 0; i < static_cast<int>(v.model->properties.size()); ++i) {
    const bool reach = v.model->properties[i].kind == RandomProperty::Kind::kReach;
    std::vector<std::string> positive, negative;
    // A bounded proof (`proved within T`) contradicts only a witness that meets the property's
    // states by T.
    double earliest_witness = std::numeric_limits<double>::infinity();
    for (const EngineRun& run : v.runs) {
      const CheckResult& r = run.results[i];
      if (run.errors[i].empty() && Positive(r.verdict) && r.trace && r.trace->state_index >= 0) {
        const auto k = static_cast<std::size_t>(r.trace->state_index);
        if (k < r.trace->run.samples.size())
          earliest_witness = std::min(earliest_witness, r.trace->run.samples[k].time);
      } else if (run.errors[i].empty() && Positive(r.verdict)) {
        earliest_witness = 0.0;  // no time known: compared with every claim
      }
    }
    for (const EngineRun& run : v.runs) {
      if (!run.errors[i].empty()) {
        ++s.verdicts[run.engine]["threw"];
        s.other_failures.push_back(Header(run.engine + " THREW", v, i));
        continue;
      }
      const CheckResult& r = run.results[i];
      if (r.reason.rfind(kSampleRefused, 0) == 0) ++s.sample_refused;
      if (run.engine == "prove") {  // the prover's verdict paths, to see them attacked
        if (r.reason.find("moved off a tie") != std::string::npos) ++s.off_tie;
        if (r.reason.find("together with the negations of") != std::string::npos &&
            r.reason.find("of 0 other") == std::string::npos) {
          ++s.joint_unreachable;
        }
      }
      ++s.verdicts[run.engine][VerdictText(r.verdict)];
      if (run.engine == "reach" && r.verdict == Verdict::kUnknown &&
          r.reason.find("not a linear") != std::string::npos) {
        ++s.reach_outside_class;
      }
      if (run.engine == "reach-paused" && r.method == "prove" && r.verdict != Verdict::kUnknown) {
        ++s.paused;
      }
      if (run.engine == "reach-hull" && r.reason.find("on convex hulls") != std::string::npos) {
        ++s.hull;
      }
      if (run.engine.starts_with("reach") &&
          r.reason.find("interaction groups alone") != std::string::npos) {
        ++s.group_product;
      }
      const bool fits = r.verdict == Verdict::kUnknown ||
                        (reach ? (r.verdict == Verdict::kReachable ||
                                  (r.verdict == Verdict::kUnreachable && run.engine != "sample"))
                               : (r.verdict == Verdict::kViolated ||
                                  (r.verdict == Verdict::kProved && run.engine != "sample")));
      if (!fits) s.other_failures.push_back(Header("VERDICT OF THE WRONG KIND", v, i));
      if (Positive(r.verdict)) positive.push_back(run.engine);
      if (Negative(r.verdict) && earliest_witness <= ht::ClaimHorizon(v.model->properties[i], r))
        negative.push_back(run.engine);
    }
    if (!positive.empty() && !negative.empty()) {
      const bool at_boundary = std::all_of(positive.begin(), positive.end(), [&](const auto& e) {
        return boundary.count({e, i}) > 0;
      });
      s.disagreements.push_back(Header(
          "DISAGREEMENT: " + negative.front() + " vs " + positive.front() +
              (at_boundary ? " (the witnesses meet the target within the tolerance only)" : ""),
          v, i));
      s.boundary_disagreements += at_boundary ? 1 : 0;
    } else if (positive.size() + negative.size() >= 2) {
      ++s.agreements;
    }
  }
}

/// The system's properties as the engines see them, in the order of model.properties.
std::optional<std::vector<Property>> PropertiesOf(const RandomSystem& model, const System& system,
                                                  std::string& problem) {
  std::vector<Property> out;
  for (const RandomProperty& p : model.properties) {
    const auto it = std::find_if(system.properties().begin(), system.properties().end(),
                                 [&](const Property& q) { return q.name == p.name; });
    if (it == system.properties().end()) {
      problem = "no property '" + p.name + "' in the parsed system";
      return std::nullopt;
    }
    out.push_back(*it);
  }
  return out;
}

/// Parses a conflicting system, which must be refused with its conflict's message.
void CheckRefused(const RandomSystem& model, const std::string& label, Summary& s) {
  const std::string text = model.Text();
  std::string message;
  try {
    ParseModel(text, "conflict.ha");
  } catch (const ParseError& e) {
    message = e.what();
  }
  const std::string kind = ht::ConflictName(model.conflict) + " (" + model.conflict_via + ")";
  if (message.find(model.conflict_message) == std::string::npos) {
    s.other_failures.push_back("=== CONFLICTING SYSTEM NOT REFUSED AS EXPECTED (" + label + ", " +
                               kind + ": expected a message with '" + model.conflict_message +
                               "', got '" + message + "') ===\n" + text);
    return;
  }
  ++s.refused[kind];
}

/// Checks one system with every engine, then confirms every trace, attacks every claim and
/// compares the engines' verdicts.
void CheckSystem(const RandomSystem& model, const std::string& label, int attacks, Rng& rng,
                 Summary& s) {
  ++s.systems;
  if (model.conflict != ht::RandomConflict::kNone) {
    CheckRefused(model, label, s);
    return;
  }
  const std::string text = model.Text();
  std::optional<System> system;
  std::string problem;
  std::optional<std::vector<Property>> properties;
  try {
    system.emplace(ParseModel(text, "system.ha"));
    properties = PropertiesOf(model, *system, problem);
  } catch (const std::exception& e) {
    problem = e.what();
  }
  if (!properties) {
    s.other_failures.push_back("=== GENERATED SYSTEM DOES NOT PARSE (" + label + "): " + problem +
                               " ===\n" + text);
    return;
  }
  s.properties += static_cast<int>(properties->size());
  Verdicts v{&model, label, {}};
  for (const auto& [name, engine] : Engines()) {
    v.runs.push_back(RunEngine(name, engine, *system, *properties));
    s.seconds[name] += v.runs.back().seconds;
  }
  const auto start = std::chrono::steady_clock::now();
  std::set<std::pair<std::string, int>> boundary;  // (engine, property): boundary witnesses
  for (const EngineRun& run : v.runs) {
    for (int i = 0; i < static_cast<int>(properties->size()); ++i) {
      if (Positive(run.results[i].verdict) && CheckTrace(v, *system, (*properties)[i], i, run, s))
        boundary.emplace(run.engine, i);
    }
  }
  CompareVerdicts(v, boundary, s);
  AttackClaims(v, ClaimsOf(v), attacks, rng, s);
  s.attack_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Reports every failure of `s` (each printed in full).
void ReportFailures(const Summary& s) {
  for (const auto* list :
       {&s.contradictions, &s.disagreements, &s.trace_failures, &s.other_failures}) {
    for (const std::string& f : *list) ADD_FAILURE() << f;
  }
}

// ---- tests of the test ----

/// What `name` is in automaton `a`: "variable", "input", "parameter", "discrete" or "label".
std::string KindOf(const ht::RandomHybridAutomaton& a, const std::string& name) {
  for (const auto& v : a.variables) {
    if (v.name == name) return "variable";
  }
  for (const auto& in : a.inputs) {
    if (in.name == name) return "input";
  }
  for (const auto& p : a.parameters) {
    if (p.name == name) return "parameter";
  }
  for (const auto& d : a.discretes) {
    if (d == name) return "discrete";
  }
  return "label";
}

/// Counts the features of automaton `a` (instance k of `model`) in `seen`.
void CountAutomatonFeatures(const ht::RandomHybridAutomaton& a, std::map<std::string, int>& seen) {
  using R = ht::RandomRelation;
  const auto strict = [](const ht::RandomComparison& c) {
    return c.relation == R::kLess || c.relation == R::kGreater;
  };
  for (const ht::RandomParameter& p : a.parameters) {
    if (p.range) ++seen["uncertain parameter"];
    if (p.definition) ++seen["derived parameter"];
  }
  if (!a.discretes.empty()) ++seen["discrete variable"];
  if (a.inits.size() > 1) ++seen["two init declarations"];
  for (const ht::RandomMode& m : a.modes) {
    if (std::any_of(m.invariant.begin(), m.invariant.end(), strict)) ++seen["strict invariant"];
    if (!m.rates.empty()) ++seen["rectangular rate"];
  }
  for (const ht::RandomTransition& t : a.transitions) {
    if (std::any_of(t.guard.begin(), t.guard.end(), strict)) ++seen["strict guard"];
    ++seen[t.urgency == ht::RandomTransition::Urgency::kLazy ? "lazy" : "urgent"];
  }
}

/// The instances (system names' prefixes) whose modes `p` reads, and whether it compares with ==.
void CountPredicateFeatures(const ht::RandomPredicate& p, std::set<std::string>& instances,
                            std::map<std::string, int>& seen) {
  if (p.kind == ht::RandomPredicate::Kind::kInMode) {
    instances.insert(p.mode.substr(0, p.mode.find('.')));
  } else if (p.kind == ht::RandomPredicate::Kind::kComparison &&
             p.comparison.relation == ht::RandomRelation::kEqual) {
    ++seen["discrete == in a property"];
  }
  for (const ht::RandomPredicate& q : p.operands) CountPredicateFeatures(q, instances, seen);
}

/// Counts the features of `model` in `seen`: how its instances connect and what they use.
void CountFeatures(const RandomSystem& model, std::map<std::string, int>& seen) {
  const int n = static_cast<int>(model.instances.size());
  ++seen[std::to_string(n) + " instances"];
  std::map<std::string, std::set<int>> symbol_users, label_users;  // system name -> instances
  std::map<std::string, std::string> kinds;
  for (int k = 0; k < n; ++k) {
    const ht::RandomInstance& in = model.instances[k];
    const ht::RandomHybridAutomaton& a = model.automata[in.automaton];
    if (in.name.empty()) ++seen["unqualified instance"];
    for (int e = 0; e < k; ++e) {
      if (model.instances[e].automaton == in.automaton) ++seen["one automaton twice"];
    }
    for (const auto& [from, to] : in.binds) ++seen["bound " + KindOf(a, from)];
    CountAutomatonFeatures(a, seen);
    for (const ht::RandomTransition& t : a.transitions) {
      if (!t.label.empty()) label_users[model.SystemName(k, t.label)].insert(k);
    }
    for (const std::string& sh : model.shared) {
      const std::string kind = KindOf(a, sh);
      if (kind == "label") continue;
      symbol_users[sh].insert(k);
      kinds[sh] = kind;
    }
  }
  for (const auto& [name, users] : symbol_users) {
    if (users.size() > 1) ++seen["shared " + kinds[name]];
  }
  for (const auto& [name, users] : label_users) {
    if (users.size() > 1) ++seen["synchronising label"];
    if (users.size() > 1 && std::count(model.shared.begin(), model.shared.end(), name) > 0) {
      ++seen["shared label"];
    }
  }
  for (const RandomProperty& p : model.properties) {
    ++seen[p.kind == RandomProperty::Kind::kAlways  ? "always"
           : p.kind == RandomProperty::Kind::kNever ? "never"
                                                    : "reach"];
    if (p.within) ++seen["within"];
    std::set<std::string> instances;
    CountPredicateFeatures(p.predicate, instances, seen);
    if (instances.size() > 1) ++seen["modes of two instances in a property"];
  }
}

/// Every name of `model` (automata, instances, symbols, labels, modes, transitions, properties).
void CollectNames(const RandomSystem& model, std::set<std::string>& names) {
  names.insert(model.name);
  for (const ht::RandomInstance& in : model.instances) names.insert(in.name);
  for (const ht::RandomHybridAutomaton& a : model.automata) {
    names.insert(a.name);
    for (const auto& v : a.variables) names.insert(v.name);
    for (const auto& in : a.inputs) names.insert(in.name);
    for (const auto& p : a.parameters) names.insert(p.name);
    names.insert(a.discretes.begin(), a.discretes.end());
    for (const auto& m : a.modes) names.insert(m.name);
    for (const auto& t : a.transitions) {
      names.insert(t.name);
      names.insert(t.label);
    }
  }
  for (const RandomProperty& p : model.properties) names.insert(p.name);
}

/// What the generator's systems must cover (CountFeatures).
const char* const kFeatures[] = {"1 instances",
                                 "2 instances",
                                 "3 instances",
                                 "unqualified instance",
                                 "one automaton twice",
                                 "shared variable",
                                 "bound variable",
                                 "shared input",
                                 "bound input",
                                 "shared label",
                                 "bound label",
                                 "shared parameter",
                                 "shared discrete",
                                 "synchronising label",
                                 "uncertain parameter",
                                 "derived parameter",
                                 "discrete variable",
                                 "two init declarations",
                                 "strict invariant",
                                 "strict guard",
                                 "lazy",
                                 "urgent",
                                 "rectangular rate",
                                 "always",
                                 "never",
                                 "reach",
                                 "within",
                                 "discrete == in a property",
                                 "modes of two instances in a property"};

// The generator's systems parse (and their attack texts too), the conflicting ones are refused
// with their conflict's message, and they cover what the issue asks for.
TEST(EngineAgreementTest, GeneratedSystemsParseAndCoverTheFeatures) {
  std::map<std::string, int> seen;
  std::set<std::string> names;
  Summary s;
  for (int i = 0; i < 1500; ++i) {
    const RandomSystem model = SystemAt(kDefaultSeed, i);
    const std::string label = "system " + std::to_string(i);
    if (model.conflict != ht::RandomConflict::kNone) {
      CheckRefused(model, label, s);
      continue;
    }
    ASSERT_NO_THROW(ParseModel(model.Text(), "system.ha")) << label << "\n" << model.Text();
    CountFeatures(model, seen);
    CollectNames(model, names);
    if (i < 300) {  // the texts of concrete runs parse too (an initial state may be refused)
      Rng rng(i);
      const Simulation sim = Simulate(model, DrawAttack(model, rng));
      EXPECT_TRUE(sim.error.empty() || sim.error.find("initial state") != std::string::npos)
          << sim.error << "\n"
          << sim.text;
    }
  }
  for (const std::string& f : s.other_failures) ADD_FAILURE() << f;
  std::cout << "features of 1500 systems:";
  for (const auto& [feature, count] : seen) std::cout << " " << feature << " " << count << ";";
  std::cout << std::endl;
  for (const char* feature : kFeatures) EXPECT_GT(seen[feature], 0) << feature;
  for (const std::string& n : ht::ShortNamePool()) EXPECT_TRUE(names.count(n)) << n;
  int refused = 0;
  for (const auto& [kind, count] : s.refused) refused += count;
  EXPECT_GT(refused, 0);
}

// Systems given a conflict on purpose are refused at parse, for every kind of conflict, whether
// the conflicting names are shared or bound.
TEST(EngineAgreementTest, ConflictingSystemsAreRefused) {
  Summary s;
  for (int i = 0; i < 150; ++i) {
    Rng rng(SystemSeed(kDefaultSeed, i));
    ht::RandomSystemOptions options;
    options.conflict_percent = 100;
    const RandomSystem model = ht::GenerateRandomSystem(rng, options);
    if (model.conflict != ht::RandomConflict::kNone) {
      CheckRefused(model, "system " + std::to_string(i), s);
    }
  }
  for (const std::string& f : s.other_failures) ADD_FAILURE() << f;
  for (auto kind : {ht::RandomConflict::kInitialValue, ht::RandomConflict::kInputBounds,
                    ht::RandomConflict::kDiscrete, ht::RandomConflict::kResets}) {
    for (const char* via : {"share", "bind"}) {
      EXPECT_GT(s.refused[ht::ConflictName(kind) + " (" + via + ")"], 0)
          << ht::ConflictName(kind) << " " << via;
    }
  }
}

ht::RandomSum Sum(double coef, const std::string& name) { return {{{coef, {name}}}}; }

ht::RandomPredicate Atom(const std::string& name, ht::RandomRelation r, double rhs) {
  ht::RandomPredicate p;
  p.comparison = {Sum(1.0, name), r, rhs};
  return p;
}

ht::RandomPredicate InMode(const std::string& mode) {
  ht::RandomPredicate p;
  p.kind = ht::RandomPredicate::Kind::kInMode;
  p.mode = mode;
  return p;
}

ht::RandomPredicate Both(ht::RandomPredicate a, ht::RandomPredicate b) {
  ht::RandomPredicate p;
  p.kind = ht::RandomPredicate::Kind::kAnd;
  p.operands = {std::move(a), std::move(b)};
  return p;
}

/// A handshake: A's clock x runs at q = 2 p (p uncertain in [0.5, 2]); B's urgent transition,
/// bound to A's lazy one (label A.l), fires with it at t = 2 (y = 2), where x = 4 p, and sets B's
/// discrete c to 1.
RandomSystem Handshake() {
  using R = ht::RandomRelation;
  ht::RandomHybridAutomaton a;
  a.name = "ta";
  a.variables = {{"x", std::nullopt}};
  a.parameters = {{"p", 1.0, std::make_pair(0.5, 2.0)}, {"q", 2.0, std::nullopt, Sum(2.0, "p")}};
  a.declaration_order = {{0, 0}, {2, 0}, {2, 1}};
  a.modes = {{"run", {{"x", Sum(1.0, "q")}}, {{Sum(1.0, "x"), R::kLessEqual, 10.0}}, {}},
             {"done", {}, {}, {}}};
  a.transitions = {{"go",
                    "run",
                    "done",
                    {{Sum(1.0, "x"), R::kGreaterEqual, 1.0}},
                    {},
                    ht::RandomTransition::Urgency::kLazy,
                    "l"}};
  a.inits = {{"run", {{"x", {0.0, 0.0}}}}};
  ht::RandomHybridAutomaton b;
  b.name = "tb";
  b.variables = {{"y", std::nullopt}};
  b.declaration_order = {{0, 0}};
  b.discretes = {"c"};
  b.modes = {{"wait",
              {{"y", ht::RandomSum{{{1.0, {}}}}}},
              {{Sum(1.0, "y"), R::kLessEqual, 3.0}},
              {},
              {{"c", 0}}},
             {"fired", {}, {}, {}, {{"c", 1}}}};
  b.transitions = {{"t", "wait", "fired", {{Sum(1.0, "y"), R::kGreaterEqual, 2.0}}, {}, {}, "k"}};
  b.inits = {{"wait", {{"y", {0.0, 0.0}}}}};
  RandomSystem s;
  s.name = "hs";
  s.automata = {a, b};
  s.instances = {{"A", 0, {}}, {"B", 1, {{"k", "A.l"}}}};
  using K = RandomProperty::Kind;
  s.properties = {
      {"fires", K::kNever, Atom("B.c", R::kEqual, 1.0), std::nullopt},
      {"below7", K::kAlways, Atom("A.x", R::kLessEqual, 7.0), std::nullopt},
      {"below8", K::kAlways, Atom("A.x", R::kLessEqual, 8.0), std::nullopt},
      {"early", K::kReach, Both(InMode("A.done"), Atom("B.y", R::kLess, 1.9)), std::nullopt},
      {"apart", K::kNever, Both(InMode("A.run"), Atom("B.c", R::kEqual, 1.0)), std::nullopt}};
  return s;
}

/// A run of one pretend engine that claims `verdicts` (one per property).
EngineRun Claimed(const std::vector<Verdict>& verdicts) {
  EngineRun run{"claimed", {}, std::vector<std::string>(verdicts.size()), 0.0};
  for (Verdict v : verdicts) {
    CheckResult r;
    r.verdict = v;
    r.reason = "claimed by the test";
    run.results.push_back(r);
  }
  return run;
}

TEST(EngineAgreementTest, HandshakeTextAndEvaluator) {
  const RandomSystem hs = Handshake();
  const std::string text = hs.Text();
  EXPECT_NE(text.find("param q = 2*p;"), std::string::npos) << text;
  EXPECT_NE(text.find("mode wait (c = 0) {"), std::string::npos) << text;
  EXPECT_NE(text.find("label l;"), std::string::npos) << text;
  EXPECT_NE(text.find("instance B = tb { k = A.l; }"), std::string::npos) << text;
  EXPECT_NE(text.find("property fires: never B.c == 1;"), std::string::npos) << text;
  EXPECT_EQ(ParseModel(text, "hs.ha").properties().size(), 5u);
  EXPECT_EQ(ht::SystemParameterValues(hs, {{"A.p", 1.5}}).at("A.q"), 3.0);
  std::map<std::string, double> values = {{"A.x", 6.0}, {"B.y", 2.0}};
  ht::AddDiscreteValues(hs, {1, 1}, values);
  EXPECT_EQ(values.at("B.c"), 1.0);
  EXPECT_TRUE(
      ht::HoldsInModes(hs.properties[0].predicate, values, ht::ModeNames(hs, {1, 1}), -kTolerance));
  EXPECT_FALSE(
      ht::HoldsInModes(hs.properties[4].predicate, values, ht::ModeNames(hs, {1, 1}), kTolerance));
}

// The attacks find the handshake's false claims (B fires; x passes 7 when p > 1.75) and leave
// its true ones alone.
TEST(EngineAgreementTest, AttacksRefuteFalseClaimsAndSpareTrueOnes) {
  const RandomSystem hs = Handshake();
  const Verdicts v{&hs,
                   "handshake",
                   {Claimed({Verdict::kProved, Verdict::kProved, Verdict::kProved,
                             Verdict::kUnreachable, Verdict::kProved})}};
  Rng rng(5);
  Summary s;
  AttackClaims(v, ClaimsOf(v), 40, rng, s);
  ASSERT_EQ(s.contradictions.size(), 2u) << (s.contradictions.empty() ? "" : s.contradictions[0]);
  EXPECT_NE(s.contradictions[0].find("never B.c == 1"), std::string::npos) << s.contradictions[0];
  EXPECT_NE(s.contradictions[1].find("always A.x <= 7"), std::string::npos) << s.contradictions[1];
  EXPECT_TRUE(s.other_failures.empty()) << s.other_failures[0];
  EXPECT_GT(s.states, 100);
}

// A trace must replay, through ReplayTrace and from model text; one that does not is reported.
TEST(EngineAgreementTest, TracesAreReplayedTwice) {
  const RandomSystem hs = Handshake();
  const System system = ParseModel(hs.Text(), "hs.ha");
  const Property& fires = system.properties()[0];
  EngineRun run = Claimed({Verdict::kViolated, Verdict::kUnknown, Verdict::kUnknown,
                           Verdict::kUnknown, Verdict::kUnknown});
  const Verdicts v{&hs, "handshake", {}};
  Summary missing;
  CheckTrace(v, system, fires, 0, run, missing);
  ASSERT_EQ(missing.trace_failures.size(), 1u);
  EXPECT_NE(missing.trace_failures[0].find("WITHOUT A TRACE"), std::string::npos);
  run.results[0].trace.emplace();
  run.results[0].trace->parameters = {{"A.p", 2.0}};
  run.results[0].trace->inputs.until = 1.0;  // B fires at t = 2
  Summary early;
  CheckTrace(v, system, fires, 0, run, early);
  ASSERT_EQ(early.trace_failures.size(), 1u);
  EXPECT_NE(early.trace_failures[0].find("DOES NOT CONFIRM"), std::string::npos);
  run.results[0].trace->inputs.until = 3.0;
  Summary genuine;
  CheckTrace(v, system, fires, 0, run, genuine);
  EXPECT_TRUE(genuine.trace_failures.empty()) << genuine.trace_failures[0];
  EXPECT_EQ(genuine.replays, 1);
  EXPECT_EQ(genuine.text_replays, 1);
  run.results[0].trace->parameters = {{"A.p", 3.0}};  // outside its range
  Summary outside;
  CheckTrace(v, system, fires, 0, run, outside);
  EXPECT_EQ(outside.trace_failures.size(), 1u);
}

// The differential test itself (see the file comment) on `default_systems` systems (or
// HYBRID_AGREEMENT_SYSTEMS) whose automata's flows are drawn as `dynamics` says.
Summary RunAgreement(const std::string& what, int default_systems, ht::RandomDynamics dynamics,
                     bool independent = false) {
  const Settings settings = SettingsFromEnvironment(default_systems);
  std::cout << what << ": seed " << settings.seed << " (HYBRID_AGREEMENT_SEED), systems "
            << settings.systems << " (HYBRID_AGREEMENT_SYSTEMS) from " << settings.first
            << " (HYBRID_AGREEMENT_FIRST), attacks " << settings.attacks
            << " (HYBRID_AGREEMENT_ATTACKS)" << std::endl;
  Summary s;
  for (int i = 0; i < settings.systems; ++i) {
    const std::uint64_t index = settings.first + static_cast<std::uint64_t>(i);
    const RandomSystem model = SystemAt(settings.seed, index, dynamics, independent);
    Rng rng(SystemSeed(settings.seed, index) ^ 0x5DEECE66Dull);
    const std::string label =
        "seed " + std::to_string(settings.seed) + ", system " + std::to_string(index) +
        ": HYBRID_AGREEMENT_FIRST=" + std::to_string(index) + " HYBRID_AGREEMENT_SYSTEMS=1";
    CheckSystem(model, label, settings.attacks, rng, s);
    if ((i + 1) % 500 == 0) {
      std::cout << "  ... " << i + 1 << " systems, "
                << s.contradictions.size() + s.disagreements.size() + s.trace_failures.size() +
                       s.other_failures.size()
                << " failures so far" << std::endl;
    }
  }
  std::cout << SummaryText(settings, s) << std::flush;
  ReportFailures(s);
  return s;
}

// 200 systems in CI; more with HYBRID_AGREEMENT_SYSTEMS (docs/soundness.md, "Engine agreement").
TEST(EngineAgreementTest, EnginesAgreeOnRandomSystems) {
  const Summary s = RunAgreement("engine agreement", kDefaultSystems, ht::RandomDynamics::kMixed);
  EXPECT_GT(s.paused, 0) << "no verdict came from reachability's pause";
  EXPECT_GT(s.hull, 0) << "no verdict came from reachability's hulls";
}

// The same on systems whose modes are mostly separable (RandomDynamics::kSeparable, the
// finger's phase-3 shape: a driver w' = c u and polynomial laws K phi(w) u), which the prover
// checks one move at a time and by their closed form: 100 systems in CI.
TEST(EngineAgreementTest, EnginesAgreeOnSeparableSystems) {
  RunAgreement("engine agreement (separable flows)", 100, ht::RandomDynamics::kSeparable);
}

// The same on systems of 2 or 3 instances that meet only through inputs and parameters, most
// of them independent interaction groups, whose properties `reach` first tries on the product of
// the groups explored alone (GroupProduct): 100 systems in CI.
TEST(EngineAgreementTest, EnginesAgreeOnIndependentInstances) {
  const Summary s = RunAgreement("engine agreement (independent instances)", 100,
                                 ht::RandomDynamics::kMixed, true);
  EXPECT_GT(s.group_product, 0) << "no verdict came from the product of interaction groups";
}

// ---- reproducers of what the differential test found (disabled until the engines are fixed) ----

/// The results of every engine on every property `text` declares.
std::map<std::string, std::vector<CheckResult>> CheckEveryEngine(const std::string& text) {
  const System system = ParseModel(text, "reproducer.ha");
  const std::vector<Property> properties = DeclaredProperties(system);
  std::map<std::string, std::vector<CheckResult>> out;
  for (const auto& [name, engine] : Engines()) {
    const EngineRun run = RunEngine(name, engine, system, properties);
    for (const std::string& e : run.errors) EXPECT_EQ(e, "") << name << " threw";
    out[name] = run.results;
  }
  return out;
}

// prove throws "name 'A.p' has no slot" on a property that reads a variable of one instance and
// a parameter of another (found as "name 'hi.g' has no slot" on a derived parameter, systems 30,
// 62, 78, 85, 157, 166 of the default seed). reach proves it; sample finds no counterexample.
TEST(EngineAgreementTest, ProveReadsAParameterOfAnotherInstance) {
  const auto r = CheckEveryEngine(R"(
automaton v {
  param p = 1;
  var c;
  mode k { }
  init k { c = 0; }
}
automaton w {
  var y;
  mode m { }
  init m { y = 0; }
}
system sys {
  instance A = v;
  instance B = w;
  property q: always B.y <= A.p;
}
)");
  EXPECT_EQ(VerdictText(r.at("reach")[0].verdict), "proved") << r.at("reach")[0].reason;
  EXPECT_EQ(VerdictText(r.at("prove")[0].verdict), "proved") << r.at("prove")[0].reason;
}

// sample reports `reachable` for a target that holds only on the boundary of its strict
// comparison: x is 1 forever, `reach x < 1` is unreachable (so say prove and reach), yet the
// sampler's witness is the start x = 1, which ReplayTrace confirms because a `reach` target is
// read leniently (Predicate::Lenient with +tolerance, trace.cc IsTarget), while ReplayOptions
// documents that it must hold with margin. Found as 4 disagreements (sample vs reach / prove) on
// 200 systems of the default seed (systems 17, 18, 40, 194: `reach not c >= 1` with a discrete c
// equal to 1, or a variable that starts on a strict target's boundary and moves away).
TEST(EngineAgreementTest, SampleWitnessOnTheBoundaryOfAStrictTarget) {
  const std::string text = R"(
automaton a {
  var x;
  mode m { }
  init m { x = 1; }
  property r: reach x < 1;
}
)";
  const auto r = CheckEveryEngine(text);
  EXPECT_EQ(VerdictText(r.at("reach")[0].verdict), "unreachable") << r.at("reach")[0].reason;
  EXPECT_EQ(VerdictText(r.at("prove")[0].verdict), "unreachable") << r.at("prove")[0].reason;
  EXPECT_NE(VerdictText(r.at("sample")[0].verdict), "reachable") << r.at("sample")[0].reason;
  const System system = ParseModel(text, "reproducer.ha");
  Trace t;
  t.inputs.until = 1.0;
  EXPECT_FALSE(ReplayTrace(system, system.properties()[0], t)) << "x = 1 is no witness of x < 1";
}

// The IR accepts `share q;` for a derived parameter `q = 2 * p` of two instances of one automaton
// whose uncertain `p` is not shared: one system symbol q with two definitions, 2 * A.p and 2 * B.p,
// equal at the nominal values (which is all System::AddComponent compares), different in the runs
// with A.p != B.p, which are runs of the model. The text of such a run (the model with A.p = 0.5
// and B.p = 1.5 as nominal values) is refused ("shared parameter 'q' is 1 in ... but 3 in ..."),
// and which q an engine reads there (the first instance's definition? each its own?) is not
// defined. Found by the attacks on systems 764 and 1419 of the default seed (`share time;` with
// `param time = -0.8*bool;`). Refusing the model at load, as for the other conflicts, is one fix.
TEST(EngineAgreementTest, SharedDerivedParameterOfUnsharedUncertainOnes) {
  const std::string text = R"(
automaton a {
  param p = 1 in [0, 2];
  param q = 2 * p;
  var x;
  mode m { x' = q; inv x <= 10; }
  init m { x = 0; }
}
system s {
  share q;
  instance A = a;
  instance B = a;
  property same: never A.x - B.x > 0.5;
}
)";
  EXPECT_THROW(ParseModel(text, "reproducer.ha"), ParseError)
      << "q would be both 2 * A.p and 2 * B.p";
}

}  // namespace
}  // namespace hybrid
