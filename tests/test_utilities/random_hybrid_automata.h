#pragma once

// Random hybrid automata written as model-language TEXT, for the differential soundness test
// (tests/solvers/verification/soundness_test.cc). The generator never touches the IR builders of
// the code under test: it keeps its own small description of the automaton (flows, guards, resets,
// properties as sums of products of names), prints that as a `.ha` text for the parser, and
// evaluates the properties' predicates itself, so that a test can judge a simulated state without
// the checker's code. Randomness comes from a caller-owned std::mt19937_64 only (no distribution
// objects, whose output the C++ standard leaves to the library): one seed gives the same models
// everywhere.

#include <cstdint>
#include <map>
#include <optional>
#include <random>
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

enum class RandomRelation { kLess, kLessEqual, kGreater, kGreaterEqual };

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
};

struct RandomTransition {
  enum class Urgency { kDefault, kUrgent, kLazy };
  std::string name;
  std::string source;
  std::string target;
  std::vector<RandomComparison> guard;                    ///< conjunction (empty: true)
  std::vector<std::pair<std::string, RandomSum>> resets;  ///< variable := sum
  Urgency urgency = Urgency::kDefault;
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

  /// The model-language text.
  std::string Text(const PrintOptions& options = {}) const;
  /// The text of property `i` as declared (`property NAME: always ...;`).
  std::string PropertyText(int i) const;
};

/// Name of the choice input of lazy transition `transition` (PrintOptions::lazy_choices).
std::string LazyChoiceInput(int transition);
/// Name of the input that picks the rate of `variable` (PrintOptions::explicit_rates).
std::string RateInput(const std::string& variable);

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
RandomHybridAutomaton GenerateRandomAutomaton(std::mt19937_64& rng);

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

/// A uniform integer in [lo, hi] drawn from `rng` (same values on every platform).
int UniformInt(std::mt19937_64& rng, int lo, int hi);
/// A uniform double in [lo, hi) drawn from `rng` (same values on every platform).
double UniformReal(std::mt19937_64& rng, double lo, double hi);
/// True with probability percent / 100.
bool RandomChance(std::mt19937_64& rng, int percent);

/// `x` as the shortest decimal that reads back to the same double ("0.3", "-2", "1e-07").
std::string DecimalText(double x);

}  // namespace hybrid::testing
