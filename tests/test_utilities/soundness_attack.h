#pragma once

// The oracle of the differential soundness tests (docs/soundness.md): a checker's verdicts on a
// random automaton (tests/test_utilities/random_hybrid_automata.h) put to the simulator.
// - every `proved` invariant and every `unreachable` target is attacked by simulations of
//   concrete runs written back as model text (random values of the uncertain parameters, a random
//   init declaration with random values in its boxes, random step inputs within their bounds,
//   random rates in rectangular ones, lazy transitions at random times); every recorded state up
//   to the claim's horizon (`within T` of the property, CheckResult::within of the verdict) is
//   judged by the generator's own evaluator, and one that breaks the claim beyond a relative
//   kSoundnessTolerance is a contradiction;
// - every `violated` trace and `reachable` witness is written back as model text (its parameter
//   and initial values as declared values, its inputs as the scenario, its lazy jumps as the
//   simulator's schedule) and simulated: it must reach the violation or the target.
// Users: tests/solvers/verification/soundness_test.cc (the SMT prover, polyhedral reachability)
// and tests/solvers/flowpipe/flowpipe_soundness_test.cc (the flowpipe engine). The oracle shares
// no code with the engines: the model is text, the simulator produces the states, the generator
// judges the properties.

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/random_hybrid_automata.h"

namespace hybrid::testing {

/// A claim is contradicted only by a state that breaks it by more than this (relative to the
/// magnitude of the comparison's terms): simulation rounding never counts.
inline constexpr double kSoundnessTolerance = 1e-6;
/// A `violated` trace must break its property by at least this (relative) margin on replay.
inline constexpr double kConfirmTolerance = 1e-9;

/// A non-negative integer from the environment, or `fallback` when unset (a malformed value is a
/// test failure, and gives `fallback`).
std::uint64_t EnvNumber(const char* name, std::uint64_t fallback);

/// Which models a differential test runs, from the environment variables PREFIX_SEED,
/// PREFIX_FIRST (index of the first model), PREFIX_MODELS and PREFIX_ATTACKS (simulations per
/// model with a claim).
struct SoundnessSettings {
  std::uint64_t seed = 0;
  std::uint64_t first = 0;
  int models = 0;
  int attacks = 0;
};
SoundnessSettings SoundnessSettingsFromEnvironment(const std::string& prefix,
                                                   std::uint64_t default_seed, int default_models,
                                                   int default_attacks);

/// The seed of model `index` (SplitMix64 of seed and index): every model is reproducible alone.
std::uint64_t ModelSeed(std::uint64_t seed, std::uint64_t index);

/// What a differential test saw.
struct SoundnessSummary {
  int models = 0;
  std::map<std::string, int> verdicts;  // "always proved", "reach unreachable", ...
  int claims = 0;                       // proved / unreachable verdicts attacked
  int bounded_claims = 0;               // of those, claims up to a time only (`within`)
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

/// "always", "never", "reach".
std::string KindName(RandomProperty::Kind k);
/// "proved", "violated", ...
std::string VerdictText(Verdict v);

/// Whether a state refutes the claim `verdict` about `p` (proved invariant, unreachable target)
/// by more than kSoundnessTolerance.
bool Refutes(const RandomProperty& p, Verdict verdict, const std::map<std::string, double>& values,
             const std::string& mode);

/// The variables that have a rectangular rate in some mode of `a`.
std::set<std::string> RatedVariables(const RandomHybridAutomaton& a);

/// The time up to which a claim about `p` holds (`within T` of the property, `within` of the
/// verdict, the smaller of the two); infinity for a claim about every time.
double ClaimHorizon(const RandomProperty& p, const CheckResult& result);

/// How AttackClaims draws its runs.
struct AttackOptions {
  /// Every attack's horizon is drawn in [0.5, 30]; with this set, it is cut to the longest
  /// horizon of the claims under attack (ClaimHorizon, at least 0.1), so that a claim `proved
  /// within 2` is attacked by runs of 2 time units, recorded in 256 steps. Off by default (the
  /// runs of the prover's test).
  bool cap_horizon = false;
};

/// Replays the trace of a `violated` or `reachable` verdict `r` on property `i` of `a` (`system`
/// is `a` parsed) from model text; a missing trace, or one that is no run of the model or does
/// not reach the violation (target), is a contradiction; a confirmed one counts as a replay.
void ReplayTraceBySimulation(const RandomHybridAutomaton& a, const System& system, int i,
                             const CheckResult& r, const std::string& label, SoundnessSummary& s);

/// Attacks every `proved` and `unreachable` verdict of `results` (one per property of `a`, in
/// order) with `attacks` random simulations; each claim is reported at its first contradiction.
void AttackClaims(const RandomHybridAutomaton& a, const std::vector<CheckResult>& results,
                  const std::string& label, int attacks, std::mt19937_64& rng, SoundnessSummary& s,
                  const AttackOptions& options = {});

/// A checker under test: every declared property of a system, one result each.
using Checker = std::function<std::vector<CheckResult>(const System&)>;

/// Parses `a`'s text, checks it with `check`, counts the verdicts, replays every trace and
/// attacks every claim (the model refused, a throwing checker or a missing result is a
/// contradiction too).
void CheckAutomaton(const RandomHybridAutomaton& a, const std::string& label, int attacks,
                    std::mt19937_64& rng, SoundnessSummary& s, const Checker& check,
                    const AttackOptions& options = {});

/// The summary of a run of `settings.models` random models and `known` known cases.
std::string SummaryText(const SoundnessSettings& settings, std::size_t known,
                        const SoundnessSummary& s);

// ---- composed systems (GenerateRandomSystem) ----

/// The choices that make a run of a system concrete.
struct SystemRunChoices {
  std::map<std::string, double> parameters;      // uncertain parameters, by system name
  std::vector<int> inits;                        // the init declaration of each instance
  std::map<std::string, double> initial_values;  // by system variable name
  RandomScenario scenario;                       // inputs by system name
  std::vector<bool> lazy_choices;                // per instance: urgent copies of lazy jumps
  std::vector<ScheduledJump> schedule;           // a trace's lazy jumps
  std::vector<double> sample_times;              // input breakpoints and other times to record
  std::string note;
};

/// A random run of `s` for an attack: values of the uncertain parameters, an init declaration
/// per instance and values in its boxes (each system name drawn once), step signals on every
/// input, random lazy-jump times and rates; a horizon in [0.5, 30], cut to `max_until` (at
/// least 0.1).
SystemRunChoices DrawSystemAttack(const RandomSystem& s, std::mt19937_64& rng,
                                  double max_until = std::numeric_limits<double>::infinity());

/// A simulation of a concrete run of a system.
struct SystemSimulation {
  std::string text;
  std::optional<Simulator> simulator;
  SimulationResult result;
  double sample_step = 0.0;
  std::map<std::string, double> parameters;  // every parameter's value, by system name
  std::string error;                         // the model or the simulator refused the run
};

/// Simulates `c` written as model text: one automaton per instance (zz_run_K) with the run's
/// parameter values and initial values as declared ones, its inputs as the scenario; the state
/// recorded every 1/256 of the horizon and at every input breakpoint.
SystemSimulation SimulateSystem(const RandomSystem& s, const SystemRunChoices& c);

/// The events of a run up to state `index` (all if negative), that state, and the run's text.
std::string SystemRunText(const SystemSimulation& sim, int index);

/// A recorded state of a system's run, as the generator's evaluator reads it.
struct SystemState {
  int index = 0;  // into the run's samples
  double time = 0.0;
  std::map<std::string, double> values;  // variables, parameters, discrete variables
  std::set<std::string> modes;           // system names of the instances' modes
};

/// The recorded states of `sim` up to the first one outside its modes' invariants (`*outside`
/// then): the simulator records the state a jump leads to even when it breaks the target mode's
/// invariant, and such a state is no state of the model, nor what it records after it.
std::vector<SystemState> SystemStates(const RandomSystem& s, const SystemSimulation& sim,
                                      bool* outside);

/// Refutes for a system state (`in M` holds when M is one of `modes`).
bool RefutesInModes(const RandomProperty& p, Verdict verdict,
                    const std::map<std::string, double>& values,
                    const std::set<std::string>& modes);

/// AttackClaims for a system: every `proved` and `unreachable` verdict of `results` (one per
/// property of `s`, in order) attacked by `attacks` random simulations up to its horizon
/// (ClaimHorizon); a run the model's own text refuses for another reason than its start is a
/// failure too.
void AttackSystemClaims(const RandomSystem& s, const std::vector<CheckResult>& results,
                        const std::string& label, int attacks, std::mt19937_64& rng,
                        SoundnessSummary& summary, const AttackOptions& options = {});

}  // namespace hybrid::testing
