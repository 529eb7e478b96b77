#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/system.h"
#include "hybrid/checking/trace.h"

namespace hybrid {

/// The answer of a checker about one property.
///
/// Invariants (`always P`, `never P`) are `proved` (P holds in every reachable state, for every
/// admissible input), `violated` (a trace reaches a state where P fails; the simulator replayed
/// it) or `unknown`. Reachability queries (`reach P`) are `reachable` (a replayed witness trace
/// ends in a P-state), `unreachable` (no reachable state satisfies P: proved) or `unknown`.
/// Sampling never yields `proved` or `unreachable`.
enum class Verdict { kProved, kViolated, kReachable, kUnreachable, kUnknown };

/// "proved", "violated", "reachable", "unreachable", "unknown".
std::string_view VerdictName(Verdict verdict);

/// Result of checking one property.
struct CheckResult {
  std::string property;
  Property::Kind kind = Property::Kind::kAlways;
  Verdict verdict = Verdict::kUnknown;
  /// The name of the PropertyChecker that gave the verdict (PropertyChecker::name(): "reach",
  /// "prove", "sample"; a FallbackChecker reports the engine that decided).
  std::string method;
  /// Wall-clock seconds spent on this property.
  double seconds = 0.0;
  /// How the verdict was reached (induction depth, number of samples, ...) or, for `unknown`,
  /// why no verdict.
  std::string reason;
  /// For `violated` and `reachable`: the counterexample or witness, replayed by the simulator.
  std::optional<Trace> trace;
  /// For `proved` and `unreachable` of a property without `within`: set when the verdict covers
  /// only the runs up to this model time (an engine that explored the reachable states that far
  /// and no farther: "proved within T"); absent for a verdict that holds for all time.
  std::optional<double> within;
  /// For `unknown`: the engine computed the reachable states exactly (up to the closure of the
  /// model's strict constraints) and they meet the property's bad (or target) states; only a run
  /// that replays is missing. An engine that can only prove, by enclosing the reachable states
  /// (PropertyChecker::Falsifies false), cannot decide it, so FallbackChecker does not ask one.
  bool states_met = false;
};

/// The gate every verdict that rests on a trace passes before it is reported. For `violated`
/// and `reachable`: replays a fresh copy of result.trace (its start, inputs and jump schedule) for
/// `property` (ReplayTrace, default options); if there is no trace, or it does not reach a
/// counterexample (witness) state, or the replay throws, the verdict becomes `unknown`, the trace
/// is dropped and the reason says why; otherwise the trace is replaced by the fresh replay. Other
/// verdicts are left as they are.
void ConfirmTrace(const System& system, const Property& property, CheckResult& result);

}  // namespace hybrid
