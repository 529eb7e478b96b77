#include "tests/test_utilities/soundness_attack.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <sstream>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"

namespace hybrid::testing {

namespace ht = ::hybrid::testing;

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

SoundnessSettings SoundnessSettingsFromEnvironment(const std::string& prefix,
                                                   std::uint64_t default_seed, int default_models,
                                                   int default_attacks) {
  SoundnessSettings s;
  s.seed = EnvNumber((prefix + "_SEED").c_str(), default_seed);
  s.first = EnvNumber((prefix + "_FIRST").c_str(), 0);
  s.models = static_cast<int>(EnvNumber((prefix + "_MODELS").c_str(), default_models));
  s.attacks = static_cast<int>(EnvNumber((prefix + "_ATTACKS").c_str(), default_attacks));
  return s;
}

std::uint64_t ModelSeed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

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

std::string VerdictText(Verdict v) { return std::string(VerdictName(v)); }

bool Refutes(const RandomProperty& p, Verdict verdict, const std::map<std::string, double>& values,
             const std::string& mode) {
  if (verdict == Verdict::kProved && p.kind == RandomProperty::Kind::kAlways) {
    return !ht::Holds(p.predicate, values, mode, kSoundnessTolerance);
  }
  if (verdict == Verdict::kProved && p.kind == RandomProperty::Kind::kNever) {
    return ht::Holds(p.predicate, values, mode, -kSoundnessTolerance);
  }
  if (verdict == Verdict::kUnreachable && p.kind == RandomProperty::Kind::kReach) {
    return ht::Holds(p.predicate, values, mode, -kSoundnessTolerance);
  }
  return false;
}

double ClaimHorizon(const RandomProperty& p, const CheckResult& result) {
  double horizon = std::numeric_limits<double>::infinity();
  if (p.within) horizon = std::min(horizon, *p.within);
  if (result.within) horizon = std::min(horizon, *result.within);
  return horizon;
}

namespace {

/// Whether a state confirms the verdict `violated` (always, never) or `reachable` (reach).
bool Confirms(const RandomProperty& p, const std::map<std::string, double>& values,
              const std::string& mode) {
  switch (p.kind) {
    case RandomProperty::Kind::kAlways:
      return !ht::Holds(p.predicate, values, mode, kConfirmTolerance);
    case RandomProperty::Kind::kNever:
      return ht::Holds(p.predicate, values, mode, -kConfirmTolerance);
    case RandomProperty::Kind::kReach:
      return ht::Holds(p.predicate, values, mode, kSoundnessTolerance);
  }
  return false;
}

/// Whether a recorded state lies in its mode's invariant (within kSoundnessTolerance). The
/// simulator records the state after a jump even when it breaks the target mode's invariant (and
/// stops there, or jumps on at the same instant): such a state is no state of the model, whose
/// states all satisfy their mode's invariant, and neither is anything recorded after it. So a run
/// is cut at its first such state: it neither refutes a claim nor confirms a trace from there on.
bool InsideInvariant(const RandomHybridAutomaton& a, const std::string& mode,
                     const std::map<std::string, double>& values) {
  for (const ht::RandomMode& m : a.modes) {
    if (m.name != mode) continue;
    for (const ht::RandomComparison& c : m.invariant) {
      ht::RandomPredicate atom;
      atom.comparison = c;
      if (!ht::Holds(atom, values, mode, kSoundnessTolerance)) return false;
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

}  // namespace

std::set<std::string> RatedVariables(const ht::RandomHybridAutomaton& a) {
  std::set<std::string> out;
  for (const ht::RandomMode& m : a.modes) {
    for (const ht::RandomRate& r : m.rates) out.insert(r.variable);
  }
  return out;
}

namespace {

/// A random run of `a` for an attack, of at most `max_until` time units (at least 0.1).
ConcreteRun DrawAttack(const RandomHybridAutomaton& a, std::mt19937_64& rng, double max_until) {
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
  if (scenario.until > max_until) scenario.until = std::max(max_until, 0.1);
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

// The status and events of a run up to the state `index`, that state (`state`), and the model
// text to replay it (saved as `file`): the report of one attack, of an automaton or a system.
template <class Sim, class StateTextOf>
std::string RunReport(const Sim& sim, int index, StateTextOf state_text, const std::string& file) {
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
  if (index >= 0) out << "  state: " << state_text(*sim.simulator, r.samples[index]) << "\n";
  out << "  replay: save the text below as " << file << " and run `hybrid simulate " << file
      << " --sample " << sim.sample_step << "`\n--- " << file << " ---\n"
      << sim.text;
  return out.str();
}

/// The events of `sim`'s run up to the state `index` and that state, for a report.
std::string RunText(const Simulation& sim, int index) {
  return RunReport(
      sim, index, [](const Simulator& s, const StateSample& x) { return StateText(s, x); },
      "attack.ha");
}

std::string Header(const std::string& what, const std::string& label,
                   const RandomHybridAutomaton& a, int property, const CheckResult& result) {
  std::ostringstream out;
  out << "=== " << what << " (" << label << ") ===\n"
      << "property: " << a.PropertyText(property) << "\n"
      << "prover: " << VerdictText(result.verdict)
      << (result.within ? " within " + ht::DecimalText(*result.within) : "") << " ("
      << result.reason << ")\n"
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

}  // namespace

void ReplayTraceBySimulation(const RandomHybridAutomaton& a, const System& system, int i,
                             const CheckResult& r, const std::string& label, SoundnessSummary& s) {
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

namespace {

// The claims of `results` under attack (their `proved` and `unreachable` verdicts), each one's
// horizon (ClaimHorizon) and the runs' longest horizon (infinity unless options.cap_horizon);
// counted into `s`.
struct OpenClaimSet {
  std::vector<int> open;
  std::vector<double> horizon;
  double max_until = std::numeric_limits<double>::infinity();
};
OpenClaimSet OpenClaims(const std::vector<RandomProperty>& properties,
                        const std::vector<CheckResult>& results, const AttackOptions& options,
                        SoundnessSummary& s) {
  OpenClaimSet c;
  c.horizon.assign(results.size(), std::numeric_limits<double>::infinity());
  double longest = 0.0;
  for (int i = 0; i < static_cast<int>(results.size()); ++i) {
    if (results[i].verdict == Verdict::kProved || results[i].verdict == Verdict::kUnreachable) {
      c.open.push_back(i);
      c.horizon[i] = ClaimHorizon(properties[i], results[i]);
      longest = std::max(longest, c.horizon[i]);
      if (std::isfinite(c.horizon[i])) ++s.bounded_claims;
    }
  }
  s.claims += static_cast<int>(c.open.size());
  if (options.cap_horizon) c.max_until = longest;
  return c;
}

}  // namespace

void AttackClaims(const RandomHybridAutomaton& a, const std::vector<CheckResult>& results,
                  const std::string& label, int attacks, std::mt19937_64& rng, SoundnessSummary& s,
                  const AttackOptions& options) {
  auto [open, horizon, max_until] = OpenClaims(a.properties, results, options, s);
  for (int k = 0; k < attacks && !open.empty(); ++k) {
    const ConcreteRun run = DrawAttack(a, rng, max_until);
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
        if (samples[j].time <= horizon[*it] && Refutes(p, r.verdict, values, mode)) {
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

void CheckAutomaton(const RandomHybridAutomaton& a, const std::string& label, int attacks,
                    std::mt19937_64& rng, SoundnessSummary& s, const Checker& check,
                    const AttackOptions& options) {
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
    s.contradictions.push_back("=== CHECKER THREW (" + label + "): " + e.what() + " ===\n" + text);
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
      ReplayTraceBySimulation(a, *system, i, by_property[i], label, s);
    }
  }
  AttackClaims(a, by_property, label, attacks, rng, s, options);
  s.attack_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - proved).count();
}

std::string SummaryText(const SoundnessSettings& settings, std::size_t known,
                        const SoundnessSummary& s) {
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

// ---- composed systems ----

namespace {

/// `s` as a concrete run: one automaton per instance (zz_run_K), with the run's parameter values
/// as nominal values and its chosen init declaration alone, its initial values as points; the
/// inputs as the scenario. `print` receives the print options of each automaton.
RandomSystem ConcreteSystem(const RandomSystem& s, const SystemRunChoices& c,
                            std::vector<ht::PrintOptions>& print) {
  RandomSystem out = s;
  out.properties.clear();
  out.automata.clear();
  print.clear();
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    ht::RandomHybridAutomaton a = s.automata[s.instances[k].automaton];
    a.name = "zz_run_" + std::to_string(k);
    for (ht::RandomParameter& p : a.parameters) {
      const auto it = c.parameters.find(s.SystemName(k, p.name));
      if (it != c.parameters.end() && p.range) p.nominal = it->second;
    }
    a.inits = {a.inits.at(c.inits.at(k))};
    for (auto& [v, range] : a.inits.front().values) {
      const auto it = c.initial_values.find(s.SystemName(k, v));
      if (it != c.initial_values.end()) range = {it->second, it->second};
    }
    out.instances[k].automaton = k;
    out.automata.push_back(a);
    ht::PrintOptions options;
    options.lazy_choices = c.lazy_choices.at(k);
    options.explicit_rates = true;
    print.push_back(options);
  }
  out.scenario = c.scenario;
  return out;
}

/// Random values for the uncertain parameters and a random start (init declaration per instance,
/// values in its boxes), each system name drawn once.
void DrawStart(const RandomSystem& s, std::mt19937_64& rng, SystemRunChoices& c) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const ht::RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    for (const ht::RandomParameter& p : a.parameters) {
      if (p.range && !c.parameters.count(s.SystemName(k, p.name))) {
        c.parameters[s.SystemName(k, p.name)] =
            DrawInRange(rng, p.range->first, p.range->second, p.nominal);
      }
    }
    c.inits.push_back(ht::UniformInt(rng, 0, static_cast<int>(a.inits.size()) - 1));
    for (const auto& [v, range] : a.inits[c.inits.back()].values) {
      if (!c.initial_values.count(s.SystemName(k, v))) {
        c.initial_values[s.SystemName(k, v)] =
            DrawInRange(rng, range.first, range.second, range.first);
      }
    }
  }
}

}  // namespace

SystemRunChoices DrawSystemAttack(const RandomSystem& s, std::mt19937_64& rng, double max_until) {
  SystemRunChoices c;
  DrawStart(s, rng, c);
  ht::RandomScenario& sc = c.scenario;
  sc.until = ht::UniformInt(rng, 5, 300) / 10.0;
  if (sc.until > max_until) sc.until = std::max(max_until, 0.1);
  std::set<std::string> driven;
  const auto drive = [&](const std::string& name, std::vector<std::pair<double, double>> points) {
    if (driven.insert(name).second) sc.steps.emplace_back(name, std::move(points));
  };
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const ht::RandomHybridAutomaton& a = s.automata[s.instances[k].automaton];
    for (const ht::RandomInput& in : a.inputs) {
      drive(s.SystemName(k, in.name), DrawSignal(rng, in.lo, in.hi, sc.until));
    }
    const bool lazy = std::any_of(a.transitions.begin(), a.transitions.end(), [](const auto& t) {
      return t.urgency == ht::RandomTransition::Urgency::kLazy;
    });
    c.lazy_choices.push_back(lazy && ht::RandomChance(rng, 60));
    for (int t = 0; c.lazy_choices.back() && t < static_cast<int>(a.transitions.size()); ++t) {
      if (a.transitions[t].urgency != ht::RandomTransition::Urgency::kLazy) continue;
      drive(s.SystemName(k, ht::LazyChoiceInput(t)), DrawChoice(rng, sc.until));
    }
    for (const std::string& v : RatedVariables(a)) {
      drive(s.SystemName(k, ht::RateInput(v)), DrawSignal(rng, 0.0, 1.0, sc.until));
    }
  }
  for (const auto& [name, points] : sc.steps) {
    for (const auto& [t, v] : points) c.sample_times.push_back(t);
  }
  c.note = "random attack";
  return c;
}

namespace {

/// Whether the simulator numbers the modes of every instance as `s` declares them.
std::string ModeNumberingProblem(const RandomSystem& s, const Simulator& sim) {
  for (int k = 0; k < static_cast<int>(s.instances.size()); ++k) {
    const auto& modes = s.automata[s.instances[k].automaton].modes;
    for (int m = 0; m < static_cast<int>(modes.size()); ++m) {
      if (sim.ModeName(k, m) != s.ModeName(k, modes[m].name)) {
        return "mode " + std::to_string(m) + " of instance " + std::to_string(k) + " is '" +
               sim.ModeName(k, m) + "', not '" + s.ModeName(k, modes[m].name) + "'";
      }
    }
  }
  return "";
}

}  // namespace

SystemSimulation SimulateSystem(const RandomSystem& s, const SystemRunChoices& c) {
  SystemSimulation out;
  std::vector<ht::PrintOptions> print;
  const RandomSystem concrete = ConcreteSystem(s, c, print);
  out.text = concrete.Text(print);
  out.parameters = ht::SystemParameterValues(s, c.parameters);
  try {
    const System system = ParseModel(out.text, "run.ha");
    out.simulator.emplace(system);
    out.error = ModeNumberingProblem(s, *out.simulator);
    if (!out.error.empty()) return out;
    SimulationOptions options;
    out.sample_step = c.scenario.until / 256;
    options.sample_step = out.sample_step;
    std::vector<double> times;
    for (double t : c.sample_times) {
      if (t >= 0 && t <= c.scenario.until) times.push_back(t);
    }
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    options.sample_times = times;
    options.lazy_schedule = c.schedule;
    out.result = out.simulator->Run(options);
  } catch (const std::exception& e) {
    out.error = e.what();
    out.simulator.reset();
  }
  return out;
}

/// The values (variables, parameters, discrete variables; system names) at recorded state `x`.
namespace {

std::map<std::string, double> SystemStateValues(const RandomSystem& s, const SystemSimulation& sim,
                                                const StateSample& x) {
  std::map<std::string, double> values = sim.parameters;
  const auto& names = sim.simulator->variable_names();
  for (std::size_t i = 0; i < names.size(); ++i) values[names[i]] = x.x[static_cast<int>(i)];
  ht::AddDiscreteValues(s, x.modes, values);
  return values;
}

std::string SystemStateText(const Simulator& sim, const StateSample& x) {
  std::ostringstream out;
  out.precision(17);
  out << "t = " << x.time << " in " << sim.ModeLabel(x.modes) << ":";
  for (std::size_t i = 0; i < sim.variable_names().size(); ++i) {
    out << " " << sim.variable_names()[i] << " = " << x.x[static_cast<int>(i)] << ";";
  }
  return out.str();
}

}  // namespace

std::string SystemRunText(const SystemSimulation& sim, int index) {
  return RunReport(
      sim, index, [](const Simulator& s, const StateSample& x) { return SystemStateText(s, x); },
      "run.ha");
}

bool RefutesInModes(const RandomProperty& p, Verdict verdict,
                    const std::map<std::string, double>& values,
                    const std::set<std::string>& modes) {
  using K = RandomProperty::Kind;
  if (verdict == Verdict::kProved && p.kind == K::kAlways) {
    return !ht::HoldsInModes(p.predicate, values, modes, kSoundnessTolerance);
  }
  if (verdict == Verdict::kProved && p.kind == K::kNever) {
    return ht::HoldsInModes(p.predicate, values, modes, -kSoundnessTolerance);
  }
  if (verdict == Verdict::kUnreachable && p.kind == K::kReach) {
    return ht::HoldsInModes(p.predicate, values, modes, -kSoundnessTolerance);
  }
  return false;
}

std::vector<SystemState> SystemStates(const RandomSystem& s, const SystemSimulation& sim,
                                      bool* outside) {
  std::vector<SystemState> out;
  const auto& samples = sim.result.samples;
  for (int j = 0; j < static_cast<int>(samples.size()); ++j) {
    SystemState x{j, samples[j].time, SystemStateValues(s, sim, samples[j]),
                  ht::ModeNames(s, samples[j].modes)};
    if (!ht::InsideInvariants(s, samples[j].modes, x.values, kSoundnessTolerance)) {
      *outside = true;
      break;
    }
    out.push_back(std::move(x));
  }
  return out;
}
void AttackSystemClaims(const RandomSystem& model, const std::vector<CheckResult>& results,
                        const std::string& label, int attacks, std::mt19937_64& rng,
                        SoundnessSummary& s, const AttackOptions& options) {
  auto [open, horizon, max_until] = OpenClaims(model.properties, results, options, s);
  for (int k = 0; k < attacks && !open.empty(); ++k) {
    const SystemRunChoices c = DrawSystemAttack(model, rng, max_until);
    const SystemSimulation sim = SimulateSystem(model, c);
    ++s.attacks;
    if (!sim.error.empty()) {
      ++s.rejected;
      ++s.refusals[sim.error.substr(0, sim.error.find('\''))];
      if (sim.error.find("initial state") != std::string::npos) continue;  // no run
      s.contradictions.push_back("=== A RUN OF THE MODEL IS REFUSED (" + label + "): " + sim.error +
                                 " ===\n--- model ---\n" + model.Text() + "--- run ---\n" +
                                 sim.text);
      break;
    }
    bool outside = false;
    const std::vector<SystemState> states = SystemStates(model, sim, &outside);
    s.outside += outside ? 1 : 0;
    for (const SystemState& x : states) {
      if (open.empty()) break;
      ++s.states;
      for (auto it = open.begin(); it != open.end();) {
        const RandomProperty& p = model.properties[*it];
        const CheckResult& r = results[*it];
        if (x.time > horizon[*it] || !RefutesInModes(p, r.verdict, x.values, x.modes)) {
          ++it;
          continue;
        }
        s.contradictions.push_back(
            "=== CONTRADICTION: `" + VerdictText(r.verdict) + "` refuted by a simulation (" +
            label + ") ===\nproperty: " + model.PropertyText(*it) + "\nchecker: " +
            VerdictText(r.verdict) + (r.within ? " within " + DecimalText(*r.within) : "") + " (" +
            r.reason + ")\n--- model (as checked) ---\n" + model.Text() +
            "--- counterexample: " + c.note + " ---\n" + SystemRunText(sim, x.index));
        it = open.erase(it);
      }
    }
  }
}

}  // namespace hybrid::testing
