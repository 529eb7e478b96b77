#include "hybrid/verification/solver_budget.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "hybrid/automaton/expression.h"
#include "solvers/verification/cpu_watchdog.h"

namespace hybrid {

SolverBudget::SolverBudget(double seconds) : seconds_(seconds) {
  if (!(seconds > 0) || !(seconds <= 1e6)) {
    throw std::invalid_argument("the solver budget must be a number of budget seconds in (0, " +
                                std::string("1e6], not ") + FormatNumber(seconds));
  }
  total_ = static_cast<std::uint64_t>(
      std::ceil(seconds * static_cast<double>(kResourceUnitsPerBudgetSecond)));
  start_cpu_ = CpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
}

double SolverBudget::SafetySeconds() const { return std::max(60.0, 10.0 * seconds_); }

double SolverBudget::SafetyCpuSeconds(std::uint64_t units) const {
  const double seconds =
      10.0 * static_cast<double>(units) / static_cast<double>(kResourceUnitsPerBudgetSecond);
  return std::clamp(seconds, 10.0, SafetySeconds());
}

bool SolverBudget::SafetyExpired() const {
  return CpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - start_cpu_ > SafetySeconds();
}

}  // namespace hybrid
