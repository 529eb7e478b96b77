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

namespace hybrid {
namespace {

namespace ht = hybrid::testing;
using ht::RandomHybridAutomaton;
using ht::RandomProperty;

constexpr std::uint64_t kDefaultSeed = 20261121;
constexpr int kDefaultModels = 300;
constexpr int kDefaultAttacks = 40;
/// A claim is contradicted only by a state that breaks it by more than this (relative to the
/// magnitude of the comparison's terms): simulation rounding never counts.
constexpr double kTolerance = 1e-6;
/// A `violated` trace must break its property by at least this (relative) margin on replay.
constexpr double kConfirmTolerance = 1e-9;

/// A non-negative integer from the environment, or `fallback` when unset.
std::uint64_t EnvNumber(const char* name, std::uint64_t fallback) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return fallback;
  char* end = nullptr;
  const unsigned long long value = std::strtoull(text, &end, 10);
  if (*end != '\0' || *text == '-') {
    ADD_FAILURE() << name << "='" << text << "' is not a non-negative integer";
    return fallback;
  }
  return value;
}

struct Settings {
  std::uint64_t seed = kDefaultSeed;
  std::uint64_t first = 0;
  int models = kDefaultModels;
  int attacks = kDefaultAttacks;
};

Settings SettingsFromEnvironment(int default_models = kDefaultModels) {
  Settings s;
  s.seed = EnvNumber("HYBRID_SOUNDNESS_SEED", kDefaultSeed);
  s.first = EnvNumber("HYBRID_SOUNDNESS_FIRST", 0);
  s.models = static_cast<int>(EnvNumber("HYBRID_SOUNDNESS_MODELS", default_models));
  s.attacks = static_cast<int>(EnvNumber("HYBRID_SOUNDNESS_ATTACKS", kDefaultAttacks));
  return s;
}

/// The seed of model `index` (SplitMix64 of seed and index): every model is reproducible alone.
std::uint64_t ModelSeed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
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

struct Summary {
  int models = 0;
  std::map<std::string, int> verdicts;  // "always proved", "reach unreachable", ...
  int claims = 0;                       // proved / unreachable verdicts attacked
  long attacks = 0;                     // simulations run against claims
  long rejected = 0;                    // simulations the model refused (initial state outside
                                        // its invariant)
  long states = 0;                      // recorded states checked against claims
  int replays = 0;                      // violated / reachable traces replayed and confirmed
  long outside = 0;                     // attacks cut at a state outside its mode's invariant
  std::map<std::string, int> refusals;  // why the model refused attacks (up to the first quote)
  std::vector<std::string> contradictions;
  double prover_seconds = 0.0;
  double attack_seconds = 0.0;
};

std::string KindName(RandomProperty::Kind k) {
  switch (k) {
    case RandomProperty::Kind::kAlways:
      return "always";
    case RandomProperty::Kind::kNever:
      return "never";
    case RandomProperty::Kind::kReach:
      return "reach";
  }
  return "?";
}

std::string VerdictText(Verdict v) {
  switch (v) {
    case Verdict::kProved:
      return "proved";
    case Verdict::kViolated:
      return "violated";
    case Verdict::kReachable:
      return "reachable";
    case Verdict::kUnreachable:
      return "unreachable";
    case Verdict::kUnknown:
      return "unknown";
  }
  return "?";
}

/// Whether a state refutes the claim `verdict` about `p` (proved invariant, unreachable target).
bool Refutes(const RandomProperty& p, Verdict verdict, const std::map<std::string, double>& values,
             const std::string& mode) {
  if (verdict == Verdict::kProved && p.kind == RandomProperty::Kind::kAlways) {
    return !ht::Holds(p.predicate, values, mode, kTolerance);
  }
  if (verdict == Verdict::kProved && p.kind == RandomProperty::Kind::kNever) {
    return ht::Holds(p.predicate, values, mode, -kTolerance);
  }
  if (verdict == Verdict::kUnreachable && p.kind == RandomProperty::Kind::kReach) {
    return ht::Holds(p.predicate, values, mode, -kTolerance);
  }
  return false;
}

/// Whether a state confirms the verdict `violated` (always, never) or `reachable` (reach).
bool Confirms(const RandomProperty& p, const std::map<std::string, double>& values,
              const std::string& mode) {
  switch (p.kind) {
    case RandomProperty::Kind::kAlways:
      return !ht::Holds(p.predicate, values, mode, kConfirmTolerance);
    case RandomProperty::Kind::kNever:
      return ht::Holds(p.predicate, values, mode, -kConfirmTolerance);
    case RandomProperty::Kind::kReach:
      return ht::Holds(p.predicate, values, mode, kTolerance);
  }
  return false;
}

/// Whether a recorded state lies in its mode's invariant (within kTolerance). The simulator
/// records the state after a jump even when it breaks the target mode's invariant (and stops
/// there, or jumps on at the same instant): such a state is no state of the model, whose states
/// all satisfy their mode's invariant, and neither is anything recorded after it. So a run is
/// cut at its first such state: it neither refutes a claim nor confirms a trace from there on.
bool InsideInvariant(const RandomHybridAutomaton& a, const std::string& mode,
                     const std::map<std::string, double>& values) {
  for (const ht::RandomMode& m : a.modes) {
    if (m.name != mode) continue;
    for (const ht::RandomComparison& c : m.invariant) {
      ht::RandomPredicate atom;
      atom.comparison = c;
      if (!ht::Holds(atom, values, mode, kTolerance)) return false;
    }
  }
  return true;
}

/// A concrete run, written as model text: the automaton with the run's parameter values and
/// initial values as its declared ones, and its inputs as its scenario.
struct ConcreteRun {
  RandomHybridAutomaton automaton;
  ht::PrintOptions print;
  std::map<std::string, double> parameters;  // every parameter's value in this run
  std::vector<double> sample_times;          // input breakpoints (recorded states)
  std::string note;                          // how it was drawn (for reports)
  std::vector<ScheduledJump> schedule;       // a trace's lazy jumps (SimulationOptions)
};

std::map<std::string, double> ParameterValues(const RandomHybridAutomaton& a) {
  std::map<std::string, double> out;
  for (const ht::RandomParameter& p : a.parameters) out[p.name] = p.nominal;
  return out;
}

/// A step signal over [0, until] of 1 to 6 pieces with values at the bounds' ends, at 0 (when
/// admitted) or uniform in the bounds.
std::vector<std::pair<double, double>> DrawSignal(std::mt19937_64& rng, double lo, double hi,
                                                  double until) {
  std::vector<double> times = {0.0};
  const int pieces = ht::UniformInt(rng, 1, 6);
  for (int i = 1; i < pieces; ++i) times.push_back(ht::UniformReal(rng, 0.0, until));
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  std::vector<std::pair<double, double>> points;
  for (double t : times) {
    const int kind = ht::UniformInt(rng, 0, 99);
    double v = kind < 30   ? lo
               : kind < 60 ? hi
               : kind < 75 ? std::clamp(0.0, lo, hi)
                           : ht::UniformReal(rng, lo, hi);
    points.emplace_back(t, std::clamp(v, lo, hi));
  }
  return points;
}

/// Pulses of 1 on a lazy transition's choice input (or none): the transition is taken at the
/// start of a pulse if its guard holds then, or as soon as it holds during the pulse.
std::vector<std::pair<double, double>> DrawChoice(std::mt19937_64& rng, double until) {
  std::vector<std::pair<double, double>> points = {{0.0, 0.0}};
  if (ht::RandomChance(rng, 40)) return points;
  std::vector<double> times;
  for (int i = ht::UniformInt(rng, 1, 3) * 2; i > 0; --i) {
    times.push_back(ht::UniformReal(rng, 0.0, until));
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (times[i] == 0.0) points.clear();
    points.emplace_back(times[i], i % 2 == 0 ? 1.0 : 0.0);
  }
  return points;
}

double DrawInRange(std::mt19937_64& rng, double lo, double hi, double nominal) {
  const int kind = ht::UniformInt(rng, 0, 99);
  if (kind < 25) return nominal;
  if (kind < 45) return lo;
  if (kind < 65) return hi;
  return std::clamp(ht::UniformReal(rng, lo, hi), lo, hi);
}

// The variables that have a rectangular rate in some mode of `a`.
std::set<std::string> RatedVariables(const ht::RandomHybridAutomaton& a) {
  std::set<std::string> out;
  for (const ht::RandomMode& m : a.modes) {
    for (const ht::RandomRate& r : m.rates) out.insert(r.variable);
  }
  return out;
}

/// A random run of `a` for an attack.
ConcreteRun DrawAttack(const RandomHybridAutomaton& a, std::mt19937_64& rng) {
  ConcreteRun run{a, {}, {}, {}, "", {}};
  RandomHybridAutomaton& c = run.automaton;
  for (ht::RandomParameter& p : c.parameters) {
    if (p.range) p.nominal = DrawInRange(rng, p.range->first, p.range->second, p.nominal);
  }
  run.parameters = ParameterValues(c);
  run.print.first_init = ht::UniformInt(rng, 0, static_cast<int>(c.inits.size()) - 1);
  for (auto& [name, range] : c.inits[run.print.first_init].values) {
    const double v = DrawInRange(rng, range.first, range.second, range.first);
    range = {v, v};
  }
  const bool has_lazy = std::any_of(c.transitions.begin(), c.transitions.end(), [](const auto& t) {
    return t.urgency == ht::RandomTransition::Urgency::kLazy;
  });
  run.print.lazy_choices = has_lazy && ht::RandomChance(rng, 60);
  ht::RandomScenario scenario;
  scenario.until = ht::UniformInt(rng, 5, 300) / 10.0;
  for (const ht::RandomInput& in : c.inputs) {
    scenario.steps.emplace_back(in.name, DrawSignal(rng, in.lo, in.hi, scenario.until));
  }
  if (run.print.lazy_choices) {
    for (int i = 0; i < static_cast<int>(c.transitions.size()); ++i) {
      if (c.transitions[i].urgency != ht::RandomTransition::Urgency::kLazy) continue;
      scenario.steps.emplace_back(ht::LazyChoiceInput(i), DrawChoice(rng, scenario.until));
    }
  }
  // Rectangular rates: a random rate in the range, segment by segment.
  run.print.explicit_rates = true;
  for (const std::string& v : RatedVariables(c)) {
    scenario.steps.emplace_back(ht::RateInput(v), DrawSignal(rng, 0.0, 1.0, scenario.until));
  }
  for (const auto& [name, points] : scenario.steps) {
    for (const auto& [t, v] : points) run.sample_times.push_back(t);
  }
  c.scenario = scenario;
  run.note = "random attack (init " + std::to_string(run.print.first_init) +
             (run.print.lazy_choices ? ", lazy transitions at random times)" : ")");
  return run;
}

/// The variables and parameters at recorded state `s` of a run of `sim`.
std::map<std::string, double> StateValues(const Simulator& sim, const StateSample& s,
                                          const std::map<std::string, double>& parameters) {
  std::map<std::string, double> values = parameters;
  for (std::size_t i = 0; i < sim.variable_names().size(); ++i) {
    values[sim.variable_names()[i]] = s.x[static_cast<int>(i)];
  }
  return values;
}

/// A simulation of a concrete run: the parsed model text, the simulator and its result.
struct Simulation {
  std::string text;
  std::optional<Simulator> simulator;
  SimulationResult result;
  double sample_step = 0.0;
  std::string error;  // the model or the simulator refused the run
};

Simulation Simulate(const ConcreteRun& run) {
  Simulation out;
  out.text = run.automaton.Text(run.print);
  try {
    const System system = ParseModel(out.text, "attack.ha");
    out.simulator.emplace(system);
    SimulationOptions options;
    out.sample_step = run.automaton.scenario->until / 256;
    options.sample_step = out.sample_step;
    std::vector<double> times;
    for (double t : run.sample_times) {
      if (t >= 0 && t <= run.automaton.scenario->until) times.push_back(t);
    }
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    options.sample_times = times;
    options.lazy_schedule = run.schedule;
    out.result = out.simulator->Run(options);
  } catch (const std::exception& e) {
    out.error = e.what();
    out.simulator.reset();
  }
  return out;
}

std::string StateText(const Simulator& sim, const StateSample& s) {
  std::ostringstream out;
  out.precision(17);
  out << "t = " << s.time << " in mode " << sim.ModeLabel(s.modes) << ":";
  for (std::size_t i = 0; i < sim.variable_names().size(); ++i) {
    out << " " << sim.variable_names()[i] << " = " << s.x[static_cast<int>(i)] << ";";
  }
  return out.str();
}

/// The events of `sim`'s run up to the state `index` and that state, for a report.
std::string RunText(const Simulation& sim, int index) {
  std::ostringstream out;
  out.precision(17);
  const SimulationResult& r = sim.result;
  out << "  simulation status: " << StatusName(r.status)
      << (r.message.empty() ? "" : " (" + r.message + ")") << "\n";
  const double until = index >= 0 ? r.samples[index].time : INFINITY;
  std::size_t shown = 0;
  while (shown < r.events.size() && r.events[shown].time <= until) ++shown;
  for (std::size_t i = 0; i < shown; ++i) {
    if (i == 20 && shown > 30) {
      out << "  ... " << shown - 25 << " more events ...\n";
      i = shown - 5;
    }
    const EventRecord& e = r.events[i];
    std::string names;
    for (const std::string& n : e.transitions) names += (names.empty() ? "" : "+") + n;
    out << "  event t = " << e.time << ": " << names << " ("
        << sim.simulator->ModeLabel(e.modes_before) << " -> "
        << sim.simulator->ModeLabel(e.modes_after) << ")\n";
  }
  if (index >= 0) out << "  state: " << StateText(*sim.simulator, r.samples[index]) << "\n";
  out << "  replay: save the text below as attack.ha and run `hybrid simulate attack.ha --sample "
      << sim.sample_step << "`\n--- attack.ha ---\n"
      << sim.text;
  return out.str();
}

std::string Header(const std::string& what, const std::string& label,
                   const RandomHybridAutomaton& a, int property, const CheckResult& result) {
  std::ostringstream out;
  out << "=== " << what << " (" << label << ") ===\n"
      << "property: " << a.PropertyText(property) << "\n"
      << "prover: " << VerdictText(result.verdict) << " (" << result.reason << ")\n"
      << "--- model (as checked) ---\n"
      << a.Text();
  return out.str();
}

/// Whether the state a simulator starts from in `run` (the first init declaration's mode and
/// values, an interval at its midpoint) is an initial state of `a`: some init declaration of
/// that mode admits every value.
bool StartsInInitialState(const RandomHybridAutomaton& a, const RandomHybridAutomaton& run) {
  const ht::RandomInit& start = run.inits[0];
  for (const ht::RandomInit& init : a.inits) {
    if (init.mode != start.mode) continue;
    bool inside = true;
    for (std::size_t v = 0; v < init.values.size(); ++v) {
      const auto [lo, hi] = init.values[v].second;
      const double x = (start.values[v].second.first + start.values[v].second.second) / 2;
      inside = inside && x >= lo - 1e-9 * (1 + std::abs(lo)) && x <= hi + 1e-9 * (1 + std::abs(hi));
    }
    if (inside) return true;
  }
  return false;
}

/// The run that a prover's trace describes, as a concrete run. `problem` collects what makes
/// the trace no run of the model: an unknown or fixed parameter, a parameter outside its range,
/// a start that is no initial state, a signal that is not a step.
ConcreteRun TraceRun(const RandomHybridAutomaton& a, const System& system, const Trace& t,
                     std::string& problem) {
  ConcreteRun run{a, {}, {}, {}, "the checker's trace, replayed", {}};
  RandomHybridAutomaton& c = run.automaton;
  for (const auto& [name, v] : t.parameters) {
    auto it = std::find_if(c.parameters.begin(), c.parameters.end(),
                           [&](const auto& p) { return p.name == name; });
    if (it == c.parameters.end() || !it->range) {
      problem += "the trace sets '" + name + "', which is no uncertain parameter; ";
      continue;
    }
    const auto [lo, hi] = *it->range;
    if (v < lo - 1e-9 * (1 + std::abs(lo)) || v > hi + 1e-9 * (1 + std::abs(hi))) {
      problem += "parameter " + name + " = " + ht::DecimalText(v) + " is outside its range; ";
    }
    it->nominal = std::clamp(v, lo, hi);
  }
  run.parameters = ParameterValues(c);
  // The init declaration the trace starts from goes first (the simulator starts from the first).
  for (const auto& [component, index] : t.initial_states) {
    if (component != 0 || index < 0 || index >= static_cast<int>(c.inits.size())) {
      problem += "the trace names initial state " + std::to_string(index) + " of component " +
                 std::to_string(component) + ", which does not exist; ";
      continue;
    }
    std::rotate(c.inits.begin(), c.inits.begin() + index, c.inits.begin() + index + 1);
  }
  for (const auto& [name, v] : t.initial_values) {
    auto& values = c.inits[0].values;
    auto it =
        std::find_if(values.begin(), values.end(), [&](const auto& x) { return x.first == name; });
    if (it == values.end()) {
      problem += "the trace sets the initial value of '" + name + "', no variable; ";
      continue;
    }
    it->second = {v, v};
  }
  if (!StartsInInitialState(a, c)) {
    problem +=
        "the trace starts from a state that no init declaration admits (see the first init of "
        "the trace text); ";
  }
  ht::RandomScenario scenario;
  scenario.until = t.inputs.until;
  run.print.explicit_rates = true;
  for (const InputSignal& signal : t.inputs.inputs) {
    if (signal.shape != InputSignal::Shape::kStep) problem += "a signal is not a step; ";
    const std::string& name = system.symbols()[signal.slot].name;
    if (!name.empty() && name.back() == '\'') {
      // The rate input x' in [-1, 1] of `x' in [lo, hi]` (rate (lo + hi)/2 + (hi - lo)/2 * w)
      // is the explicit rate input in [0, 1] at (w + 1) / 2 (rate lo + (hi - lo) * z).
      std::vector<std::pair<double, double>> points = signal.points;
      for (auto& [time, w] : points) w = (w + 1) / 2;
      scenario.steps.emplace_back(ht::RateInput(name.substr(0, name.size() - 1)), points);
    } else {
      scenario.steps.emplace_back(name, signal.points);
    }
    for (const auto& [time, value] : signal.points) run.sample_times.push_back(time);
  }
  for (const std::string& v : RatedVariables(c)) {  // an unlisted rate input is 0: the midpoint
    const bool listed =
        std::any_of(scenario.steps.begin(), scenario.steps.end(),
                    [&](const auto& step) { return step.first == ht::RateInput(v); });
    if (!listed)
      scenario.steps.emplace_back(ht::RateInput(v),
                                  std::vector<std::pair<double, double>>{{0.0, 0.5}});
  }
  c.scenario = scenario;
  run.schedule = t.schedule;  // transition indices: the text keeps the declaration order
  for (const ScheduledJump& j : t.schedule) run.sample_times.push_back(j.time);
  if (t.state_index >= 0 && t.state_index < static_cast<int>(t.run.samples.size())) {
    run.sample_times.push_back(t.run.samples[t.state_index].time);
  }
  return run;
}

/// Replays the trace of a `violated` or `reachable` verdict on property `i` from model text.
void ConfirmTrace(const RandomHybridAutomaton& a, const System& system, int i, const CheckResult& r,
                  const std::string& label, Summary& s) {
  const std::string what = VerdictText(r.verdict);
  if (!r.trace) {
    s.contradictions.push_back(Header("`" + what + "` WITHOUT A TRACE", label, a, i, r));
    return;
  }
  std::string problem;
  const ConcreteRun run = TraceRun(a, system, *r.trace, problem);
  const Simulation sim = Simulate(run);
  if (!problem.empty() || !sim.error.empty()) {
    s.contradictions.push_back(
        Header("`" + what + "` TRACE IS NO RUN OF THE MODEL", label, a, i, r) +
        "--- problem ---\n" + problem + sim.error + "\n--- trace text ---\n" + sim.text);
    return;
  }
  const RandomProperty& p = a.properties[i];
  const auto& samples = sim.result.samples;
  bool outside = false;
  for (const StateSample& state : samples) {
    if (p.within && state.time > *p.within) break;
    const std::string mode = sim.simulator->ModeLabel(state.modes);
    const auto values = StateValues(*sim.simulator, state, run.parameters);
    if (!InsideInvariant(a, mode, values)) {
      outside = true;  // the run is no run of the model from here on
      break;
    }
    if (Confirms(p, values, mode)) {
      ++s.replays;
      return;
    }
  }
  s.contradictions.push_back(
      Header("`" + what + "` TRACE DOES NOT REPLAY", label, a, i, r) +
      (outside ? "(the replay leaves its mode's invariant after a jump before it gets there)\n"
               : "") +
      "--- replay of the trace ---\n" + RunText(sim, -1));
}

/// Attacks every `proved` and `unreachable` verdict of `results` (one per property of `a`) with
/// `attacks` random simulations; each claim is reported at its first contradiction.
void AttackClaims(const RandomHybridAutomaton& a, const std::vector<CheckResult>& results,
                  const std::string& label, int attacks, std::mt19937_64& rng, Summary& s) {
  std::vector<int> open;
  for (int i = 0; i < static_cast<int>(results.size()); ++i) {
    if (results[i].verdict == Verdict::kProved || results[i].verdict == Verdict::kUnreachable) {
      open.push_back(i);
    }
  }
  s.claims += static_cast<int>(open.size());
  for (int k = 0; k < attacks && !open.empty(); ++k) {
    const ConcreteRun run = DrawAttack(a, rng);
    const Simulation sim = Simulate(run);
    ++s.attacks;
    if (!sim.error.empty()) {
      // A drawn start outside its mode's invariant is no run; anything else is a bug of the test
      // (an attack text that does not parse, a signal out of bounds) or of the simulator.
      if (sim.error.find("initial state") == std::string::npos) {
        s.contradictions.push_back("=== ATTACK REFUSED UNEXPECTEDLY (" + label + "): " + sim.error +
                                   " ===\n" + sim.text);
      }
      ++s.rejected;
      ++s.refusals[sim.error.substr(0, sim.error.find('\''))];
      continue;
    }
    const auto& samples = sim.result.samples;
    for (int j = 0; j < static_cast<int>(samples.size()) && !open.empty(); ++j) {
      const auto values = StateValues(*sim.simulator, samples[j], run.parameters);
      const std::string mode = sim.simulator->ModeLabel(samples[j].modes);
      if (!InsideInvariant(a, mode, values)) {
        ++s.outside;  // no state of the model, nor what the simulator records after it
        break;
      }
      ++s.states;
      for (auto it = open.begin(); it != open.end();) {
        const RandomProperty& p = a.properties[*it];
        const CheckResult& r = results[*it];
        if ((!p.within || samples[j].time <= *p.within) && Refutes(p, r.verdict, values, mode)) {
          s.contradictions.push_back(
              Header("CONTRADICTION: `" + VerdictText(r.verdict) + "` refuted by a simulation",
                     label, a, *it, r) +
              "--- counterexample: " + run.note + " ---\n" + RunText(sim, j));
          it = open.erase(it);
        } else {
          ++it;
        }
      }
    }
  }
}

/// Checks `a` as `hybrid check --method prove` does, confirms every trace and attacks every
/// claim.
// A checker under test: every declared property of a system, one result each.
using Checker = std::function<std::vector<CheckResult>(const System&)>;

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

void CheckAutomaton(const RandomHybridAutomaton& a, const std::string& label, int attacks,
                    std::mt19937_64& rng, Summary& s, const Checker& check = Prove) {
  ++s.models;
  const std::string text = a.Text();
  std::optional<System> system;
  try {
    system.emplace(ParseModel(text, label + ".ha"));
  } catch (const std::exception& e) {
    s.contradictions.push_back("=== GENERATED MODEL DOES NOT PARSE (" + label + ") ===\n" +
                               e.what() + "\n" + text);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<CheckResult> results;
  try {
    results = check(*system);
  } catch (const std::exception& e) {
    s.contradictions.push_back("=== PROVER THREW (" + label + "): " + e.what() + " ===\n" + text);
    return;
  }
  const auto proved = std::chrono::steady_clock::now();
  s.prover_seconds += std::chrono::duration<double>(proved - start).count();
  std::vector<CheckResult> by_property;
  for (const RandomProperty& p : a.properties) {
    auto it = std::find_if(results.begin(), results.end(),
                           [&](const CheckResult& r) { return r.property == p.name; });
    if (it == results.end()) {
      s.contradictions.push_back("=== NO RESULT FOR '" + p.name + "' (" + label + ") ===\n" + text);
      return;
    }
    by_property.push_back(*it);
    ++s.verdicts[KindName(p.kind) + " " + VerdictText(it->verdict)];
  }
  for (int i = 0; i < static_cast<int>(by_property.size()); ++i) {
    const Verdict v = by_property[i].verdict;
    if (v == Verdict::kViolated || v == Verdict::kReachable) {
      ConfirmTrace(a, *system, i, by_property[i], label, s);
    }
  }
  AttackClaims(a, by_property, label, attacks, rng, s);
  s.attack_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - proved).count();
}

std::string SummaryText(const Settings& settings, std::size_t known, const Summary& s) {
  std::ostringstream out;
  out.precision(3);
  out << "soundness: seed " << settings.seed << ", " << settings.models << " random models from "
      << settings.first << " (+" << known << " known cases), " << s.models
      << " checked\n  verdicts:";
  for (const auto& [kind, count] : s.verdicts) out << " " << kind << " " << count << ";";
  out << "\n  claims attacked " << s.claims << ", attacks " << s.attacks << " (" << s.rejected
      << " refused by the model), states checked " << s.states << ", traces replayed " << s.replays
      << "\n  runs cut at a jump outside the target mode's invariant " << s.outside << "\n";
  for (const auto& [why, count] : s.refusals) out << "  refused " << count << "x: " << why << "\n";
  out << "  contradictions " << s.contradictions.size() << "\n  prover " << s.prover_seconds
      << " s, attacks and replays " << s.attack_seconds << " s\n";
  return out.str();
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
  ConfirmTrace(tank, system, 0, r, "forged", forged);
  ASSERT_EQ(forged.contradictions.size(), 1u);
  EXPECT_NE(forged.contradictions[0].find("TRACE DOES NOT REPLAY"), std::string::npos);
  r.trace->inputs.until = 3.0;  // h reaches 6.5
  Summary genuine;
  ConfirmTrace(tank, system, 0, r, "genuine", genuine);
  EXPECT_TRUE(genuine.contradictions.empty()) << genuine.contradictions[0];
  EXPECT_EQ(genuine.replays, 1);
  r.trace->inputs.inputs[0].points = {{0.0, 0.5}};  // outside d's bounds
  Summary outside;
  ConfirmTrace(tank, system, 0, r, "outside", outside);
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
void RunDifferentialTest(const Checker& check, const std::string& what, int default_models) {
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
    const RandomHybridAutomaton a = ht::GenerateRandomAutomaton(rng);
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

// The same differential test for polyhedral reachability (--method reach): its `proved` and
// `unreachable` claims attacked, its traces (with their lazy-jump schedules) replayed. 100 models
// by default (about 40 s, several times that under the sanitizers); HYBRID_SOUNDNESS_MODELS for
// more (docs/soundness.md).
TEST(SoundnessTest, ReachabilityVerdictsSurviveSimulation) {
  RunDifferentialTest(Reach, "reach", 100);
}

}  // namespace
}  // namespace hybrid
