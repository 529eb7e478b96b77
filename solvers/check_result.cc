#include "solvers/check_result.h"

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

}  // namespace hybrid
