#pragma once

// Random hybrid automata and composed systems written as model-language TEXT, for the differential
// soundness test (tests/solvers/verification/soundness_test.cc: automata) and the engine agreement
// test (tests/solvers/verification/engine_agreement_test.cc: systems of automata,
// GenerateRandomSystem). The generator never touches the IR builders of the code under test: it
// keeps its own small description of the automaton (flows, guards, resets, properties as sums of
// products of names), prints that as a `.ha` text for the parser, and evaluates the properties'
// predicates itself, so that a test can judge a simulated state without the checker's code.
// Randomness comes from a caller-owned std::mt19937_64 only (no distribution objects, whose output
// the C++ standard leaves to the library): one seed gives the same models everywhere.

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hybrid::testing {

/// Short common names that an encoder, a solver or a code generator might use for its own
/// objects (a duration `d`, a time `t`, a flag `flow`, an integral `int`, Z3's `div` ...). Every
/// name of a random automaton (the automaton, its variables, inputs, parameters, modes,
/// transitions and properties) is drawn from this pool, so model names meet internal names often.
/// None is a keyword of the model language.
const std::vector<std::string>& ShortNamePool();

/// c * f1 * f2 * ...; no factors: the constant c.
struct RandomTerm {
  double coef = 0.0;
  std::vector<std::string> factors;
};

/// A sum of terms (empty: 0).
struct RandomSum {
  std::vector<RandomTerm> terms;
};

/// kEqual (`==`) is drawn only for discrete variables (integers), in properties: a continuous
/// value never clearly equals a constant, so Holds reads it exactly when asked for a clear answer.
enum class RandomRelation { kLess, kLessEqual, kGreater, kGreaterEqual, kEqual };

/// `lhs REL rhs`.
struct RandomComparison {
  RandomSum lhs;
  RandomRelation relation = RandomRelation::kLessEqual;
  double rhs = 0.0;
};

/// A property's predicate.
struct RandomPredicate {
  enum class Kind { kComparison, kInMode, kNot, kAnd, kOr };
  Kind kind = Kind::kComparison;
  RandomComparison comparison;            ///< kComparison
  std::string mode;                       ///< kInMode
  std::vector<RandomPredicate> operands;  ///< kNot: one; kAnd, kOr: two
};

struct RandomVariable {
  std::string name;
  std::optional<std::pair<double, double>> domain;  ///< `var x in [lo, hi];` (metadata)
};

struct RandomInput {
  std::string name;
  double lo = 0.0;
  double hi = 0.0;
};

struct RandomParameter {
  std::string name;
  double nominal = 0.0;
  std::optional<std::pair<double, double>> range;  ///< uncertain: `param p = v in [lo, hi];`
  /// A derived parameter `param q = 2 * p + 0.5;` over earlier parameters (no range); `nominal`
  /// is then its value at the nominal values (EvaluateParameters gives it for others).
  std::optional<RandomSum> definition = {};
};

/// A rectangular rate `x' in [lo, hi];` of one variable in one mode.
struct RandomRate {
  std::string variable;
  double lo = 0.0;
  double hi = 0.0;
};

struct RandomMode {
  std::string name;
  std::vector<std::pair<std::string, RandomSum>> flows;  ///< variable, right-hand side
  std::vector<RandomComparison> invariant;               ///< conjunction (empty: none)
  std::vector<RandomRate> rates;  ///< variables with a rectangular rate (no flow)
  /// The value of every discrete variable in this mode: `mode m (c = 1, e = -1) { ... }`.
  std::vector<std::pair<std::string, int>> discrete_values = {};
};

struct RandomTransition {
  enum class Urgency { kDefault, kUrgent, kLazy };
  std::string name;
  std::string source;
  std::string target;
  std::vector<RandomComparison> guard;                    ///< conjunction (empty: true)
  std::vector<std::pair<std::string, RandomSum>> resets;  ///< variable := sum
  Urgency urgency = Urgency::kDefault;
  std::string label = {};  ///< synchronisation label (empty: none)
};

struct RandomInit {
  std::string mode;
  /// Every variable: [lo, hi] (lo == hi is printed as a point `x = v`).
  std::vector<std::pair<std::string, std::pair<double, double>>> values;
};

struct RandomProperty {
  enum class Kind { kAlways, kNever, kReach };
  std::string name;
  Kind kind = Kind::kAlways;
  RandomPredicate predicate;
  std::optional<double> within;
};

/// A default run: `scenario { until T; u = step(t0: v0, t1: v1, ...); }`.
struct RandomScenario {
  double until = 0.0;
  /// Input name and its step signal's (time, value) points.
  std::vector<std::pair<std::string, std::vector<std::pair<double, double>>>> steps;
};

/// How to print a RandomHybridAutomaton.
struct PrintOptions {
  /// This init declaration is printed first (a simulator starts from the first one).
  int first_init = 0;
  /// Every lazy transition i also gets an urgent copy `zz_lazy_copy_<i>` whose guard is the lazy
  /// one's and `zz_lazy_choice_<i> >= 0.5`, with a new input `zz_lazy_choice_<i> in [0, 1]` (the
  /// `zz_` names are not in the pool): a step signal on that input makes a simulator take the lazy
  /// transition at a chosen time. Every run of that text is a run of the automaton, since a lazy
  /// transition may fire at any time its guard holds (with the input at 0 nothing changes). The
  /// copy's strict comparisons are tightened to non-strict ones 0.001 inside (`x > 1` becomes
  /// `x >= 1.001`), because an urgent transition fires where its guard holds in its closure.
  bool lazy_choices = false;
  /// Every rectangular rate `x' in [lo, hi]` is printed as the flow
  /// `x' = lo + (hi - lo) * zz_rate_x` over an input `zz_rate_x in [0, 1]` (RateInput), declared
  /// once per variable that has a rate somewhere: a step signal on it picks the rate segment by
  /// segment, and every run of that text is a run of the automaton.
  bool explicit_rates = false;
};

/// A random automaton in a form the test understands without the code under test.
struct RandomHybridAutomaton {
  std::string name;
  std::vector<RandomVariable> variables;
  std::vector<RandomInput> inputs;
  std::vector<RandomParameter> parameters;
  std::vector<RandomMode> modes;
  std::vector<RandomTransition> transitions;
  std::vector<RandomInit> inits;
  std::vector<RandomProperty> properties;
  std::optional<RandomScenario> scenario;  ///< none from the generator
  /// Declaration order of variables (0), inputs (1) and parameters (2) as printed.
  std::vector<std::pair<int, int>> declaration_order;
  /// Discrete variables (`discrete c, e;`, printed after the other declarations); every mode
  /// gives each a value (RandomMode::discrete_values).
  std::vector<std::string> discretes = {};

  /// The model-language text.
  std::string Text(const PrintOptions& options = {}) const;
  /// The text of property `i` as declared (`property NAME: always ...;`).
  std::string PropertyText(int i) const;
};

/// Name of the choice input of lazy transition `transition` (PrintOptions::lazy_choices).
std::string LazyChoiceInput(int transition);
/// Name of the input that picks the rate of `variable` (PrintOptions::explicit_rates).
std::string RateInput(const std::string& variable);

/// Which flows GenerateRandomAutomaton draws.
enum class RandomDynamics {
  /// Constant rates, affine in the inputs (also with parameter coefficients), zero, absent,
  /// rectangular rates, or occasionally affine in the state (relaxation towards a constant).
  /// The default: every seed keeps the models it has always given.
  kMixed,
  /// Mostly affine in the state with small coefficients, stable and unstable, with cross terms
  /// (`x' = -0.4*x + 2 + u`, `x' = 0.3*y - 0.2*x + 0.1*p*x`), sometimes polynomial (a cubic
  /// damping `x' = -0.5*x - 0.2*x*x*x`, `x' = -0.3*x - 0.1*x*y*y + 0.2*y*y`, and, with two or more
  /// variables, oscillators `x' = y; y' = -x - 0.1*x*x*y` (damped or Van der Pol: bounded
  /// runs)), besides the other shapes of kMixed (constant, input-affine, rectangular rates, zero,
  /// absent), and small initial sets: models the flowpipe engine (`check --method flowpipe`)
  /// can prove things about (tests/solvers/flowpipe/flowpipe_soundness_test.cc). Inputs,
  /// uncertain parameters, invariants, guards (urgent and lazy), resets, several init
  /// declarations and `within T` properties are drawn as for kMixed, and besides: 4 in 10
  /// transitions also leave their source mode through the boundary of one of its invariant atoms
  /// (guard `x >= 3` for an invariant `x <= 3`), and a third of the resets mix two variables
  /// (`v := -0.7*v + 0.2*w + 1.1`).
  kAffine,
  /// Seven modes in ten (with an input and two variables or more) separable as the finger's
  /// phase 3 is: one input u drives one variable (`w' = 0.7*u`), and each other variable stands
  /// still or follows a polynomial of the driver times u (`x' = 0.4*w*u`, `x' = 0.2*w*w*u`,
  /// `x' = 0.3*p*w*u` with a parameter p), whose closed form the prover encodes as a polynomial
  /// law; the other modes, and everything else, are drawn as for kMixed.
  kSeparable,
};

/// How to draw a RandomHybridAutomaton (GenerateRandomAutomaton).
struct RandomAutomatonOptions {
  RandomDynamics dynamics = RandomDynamics::kMixed;
};

/// A random automaton: 1 to 3 variables (some with a domain), 0 to 3 inputs whose bounds take
/// every sign ([-a, 0], [0, a], [0, 0], [-a, b], [a, b], [-b, -a]), 0 to 2 parameters (most with a
/// range, some degenerate), 1 to 3 modes whose flows are constant rates, affine in the inputs
/// (also with parameter coefficients), zero, rectangular rates `x' in [lo, hi]` (some with
/// lo == hi), or occasionally affine in the state, conjunctive
/// invariants, 0 to 5 transitions (urgent, explicitly urgent or lazy; guards on variables,
/// parameters and sometimes inputs, strict or not; resets to constants, shifts, other variables,
/// parameters), 1 or 2 initial states (points and intervals), and 2 to 5 properties (`always`,
/// `never`, `reach`, some `within T`) whose predicates combine comparisons of sums of variables and
/// parameters, `in MODE`, `not`, `and`, `or`. Constants are short decimals that the parser reads
/// to the same double. Every name is drawn from ShortNamePool().
/// `options` (RandomAutomatonOptions) chooses the flows; the default draws exactly what the
/// overload without options draws.
RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng);
RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng,
                                              const RandomAutomatonOptions& options);

/// sum's value; every factor must be in `values` (throws std::out_of_range otherwise).
double EvaluateSum(const RandomSum& sum, const std::map<std::string, double>& values);

/// `p` at a state (`values`: variables and parameters; `mode`: the current mode's name), judged
/// with margin `tolerance` on every comparison: a comparison in positive position (under an even
/// number of `not`) holds when it holds within tolerance * (1 + the magnitude of its terms and
/// constant) when tolerance > 0, and only with that margin when tolerance < 0; under `not` the
/// roles swap. So Holds(p, +tol) false means p fails clearly, Holds(p, -tol) true means p holds
/// clearly.
bool Holds(const RandomPredicate& p, const std::map<std::string, double>& values,
           std::string_view mode, double tolerance);

/// Parameter values of `a`: nominal values, except those named in `overrides` (which replace
/// them), with derived parameters (RandomParameter::definition) evaluated in declaration order.
std::map<std::string, double> EvaluateParameters(
    const RandomHybridAutomaton& a, const std::map<std::string, double>& overrides = {});

// ---- composed systems ----

/// `instance NAME = AUTOMATON { local = SYSTEM_NAME; ... }` (NAME empty: `instance AUTOMATON;`,
/// whose names are not qualified).
struct RandomInstance {
  std::string name;
  int automaton = 0;  ///< index into RandomSystem::automata
  /// Binds: a name of the automaton (symbol or transition label) and the system name it takes.
  std::vector<std::pair<std::string, std::string>> binds;
};

/// The kind of a deliberate conflict between the declarations of two instances, which the IR
/// refuses at load (System::AddComponent throws ConflictError, the parser reports it).
enum class RandomConflict {
  kNone,
  kInitialValue,  ///< a shared or bound variable started at different values
  kInputBounds,   ///< a shared or bound input with different bounds
  kDiscrete,      ///< a shared or bound discrete variable given values by two instances
  kResets,        ///< transitions synchronised by one label both reset one variable
};

/// "none", "initial value", "input bounds", "discrete values", "synchronised resets".
std::string ConflictName(RandomConflict conflict);

/// A random composed system in a form the test understands without the code under test: the
/// automata as declared (their properties empty), shared names, instances with binds, and
/// properties over system names (`A.x`, a shared `x`, `A.c`, `in A.m`).
struct RandomSystem {
  std::string name;
  std::vector<RandomHybridAutomaton> automata;
  std::vector<std::string> shared;  ///< `share a, b;`
  std::vector<RandomInstance> instances;
  std::vector<RandomProperty> properties;
  std::optional<RandomScenario> scenario;  ///< over system input names; none from the generator
  /// kNone for a system every engine must accept; otherwise the conflict it was given on purpose,
  /// between instances `conflict_instances` (earlier, later), which the parser must refuse with
  /// a message containing `conflict_message`.
  RandomConflict conflict = RandomConflict::kNone;
  std::pair<int, int> conflict_instances = {-1, -1};
  std::string conflict_message;
  /// How the conflicting names are connected: "share" or "bind" (empty without a conflict).
  std::string conflict_via;

  /// The model-language text: the automata, then the system. `automaton_options[k]`, if
  /// given, prints automaton k (lazy choices, explicit rates; first_init must be 0 here or name
  /// an init the text keeps).
  std::string Text(const std::vector<PrintOptions>& automaton_options = {}) const;
  /// The text of property `i` as declared.
  std::string PropertyText(int i) const;
  /// The system name of `local` (a symbol or label of instance `instance`'s automaton): its
  /// bind target if bound, `local` if shared or the instance is unqualified, else `NAME.local`.
  std::string SystemName(int instance, const std::string& local) const;
  /// The name of mode `mode` of instance `instance` at system level (`A.m`, or `m`).
  std::string ModeName(int instance, const std::string& mode) const;
};

/// How to draw a RandomSystem.
struct RandomSystemOptions {
  /// Chance (percent) that the system is given a conflict on purpose (RandomSystem::conflict);
  /// a system with fewer than two instances of different automata gets none.
  int conflict_percent = 0;
  /// How the instances' automata are drawn (the default keeps every seed's systems).
  RandomAutomatonOptions automata = {};
  /// Instances that interact only through shared or bound inputs and parameters (no shared or
  /// bound variable, label or discrete variable): 2 or 3 of them, most each its own interaction
  /// group (System::InteractionGroups; a shared name still joins two instances that both
  /// declare it as a variable). false keeps every seed's systems.
  bool independent_instances = false;
};

/// A random system: 1 to 3 instances (sometimes two of one automaton, sometimes one unqualified:
/// `instance a;`) of random automata (GenerateRandomAutomaton, then decorated with discrete
/// variables and their mode values, labels on transitions, and derived parameters
/// `param q = 2 * p;` read by flows, guards, resets or properties). Between instances: shared
/// (`share x;`) and bound (`instance B = b { x = A.y; }`) variables, inputs, labels, parameters
/// and discrete variables. The declarations are made to agree where the IR requires it (one
/// initial value per shared variable, one flow owner, equal input bounds and parameters, one
/// value for a shared discrete variable, no variable reset by two synchronised transitions),
/// unless a conflict is drawn (options). 2 to 5 properties (`always`, `never`, `reach`, some
/// `within T`) over system names: comparisons of variables (also across instances), against
/// parameters, of discrete variables (`A.c == 1`), `in A.m`, `not`, `and`, `or`. Every name is
/// drawn from ShortNamePool().
RandomSystem GenerateRandomSystem(std::mt19937_64& rng, const RandomSystemOptions& options = {});

/// Values of every parameter of `s` by system name (EvaluateParameters per instance), with the
/// uncertain ones named in `overrides` (system names) set.
std::map<std::string, double> SystemParameterValues(
    const RandomSystem& s, const std::map<std::string, double>& overrides = {});

/// Adds the values of the discrete variables of `s` (system names) when instance k is in mode
/// `modes[k]` (index into its automaton's modes) to `values`.
void AddDiscreteValues(const RandomSystem& s, const std::vector<int>& modes,
                       std::map<std::string, double>& values);

/// The system names of the modes `modes` (one index per instance): what `in MODE` reads.
std::set<std::string> ModeNames(const RandomSystem& s, const std::vector<int>& modes);

/// Whether every instance's invariant (in mode `modes[k]`) holds at `values` (system names)
/// within `tolerance` (relative, as in Holds).
bool InsideInvariants(const RandomSystem& s, const std::vector<int>& modes,
                      const std::map<std::string, double>& values, double tolerance);

/// Holds for a system state: `in M` holds when M is one of `modes` (ModeNames).
bool HoldsInModes(const RandomPredicate& p, const std::map<std::string, double>& values,
                  const std::set<std::string>& modes, double tolerance);

/// A uniform integer in [lo, hi] drawn from `rng` (same values on every platform).
int UniformInt(std::mt19937_64& rng, int lo, int hi);
/// A uniform double in [lo, hi) drawn from `rng` (same values on every platform).
double UniformReal(std::mt19937_64& rng, double lo, double hi);
/// True with probability percent / 100.
bool RandomChance(std::mt19937_64& rng, int percent);

/// `x` as the shortest decimal that reads back to the same double ("0.3", "-2", "1e-07").
std::string DecimalText(double x);

}  // namespace hybrid::testing
