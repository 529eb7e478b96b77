#include "hybrid/checking/check_result.h"

#include <exception>
#include <utility>

namespace hybrid {

std::string_view VerdictName(Verdict verdict) {
  switch (verdict) {
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

void ConfirmTrace(const System& system, const Property& property, CheckResult& result) {
  if (result.verdict != Verdict::kViolated && result.verdict != Verdict::kReachable) return;
  const std::string what = result.verdict == Verdict::kViolated ? "counterexample" : "witness";
  std::string failure;
  if (!result.trace) {
    failure = "no trace";
  } else {
    Trace fresh;
    fresh.parameters = result.trace->parameters;
    fresh.initial_states = result.trace->initial_states;
    fresh.initial_values = result.trace->initial_values;
    fresh.inputs = result.trace->inputs;
    fresh.schedule = result.trace->schedule;
    try {
      if (ReplayTrace(system, property, fresh)) {
        result.trace = std::move(fresh);
        return;
      }
      failure = "its trace does not replay in the simulator";
    } catch (const std::exception& e) {
      failure = std::string("its trace could not be replayed: ") + e.what();
    }
  }
  result.verdict = Verdict::kUnknown;
  result.trace.reset();
  result.reason = "a " + what + " was found (" + result.reason + "), but " + failure +
                  ", so it is not reported";
}

}  // namespace hybrid
