#include "solvers/simulation/run_inputs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "automaton/internal_assert.h"

namespace hybrid {

std::vector<InputSignal> MergedInputs(const System& system, std::span<const InputSignal> signals) {
  const SymbolTable& symbols = system.symbols();
  std::vector<InputSignal> inputs;
  if (system.scenario()) inputs = system.scenario()->inputs;
  for (const InputSignal& s : signals) {
    if (s.slot < 0 || s.slot >= symbols.size() || symbols[s.slot].kind != SymbolKind::kInput) {
      throw std::invalid_argument("a signal drives something that is not an input");
    }
    std::erase_if(inputs, [&](const InputSignal& x) { return x.slot == s.slot; });
    inputs.push_back(s);
  }
  return inputs;
}

void ValidateInputs(const System& system, const std::vector<InputSignal>& inputs) {
  const SymbolTable& symbols = system.symbols();
  auto fail = [&](const std::string& message) { throw std::invalid_argument(message); };
  for (const InputSignal& s : inputs) {
    HYBRID_ASSERT(s.slot >= 0 && s.slot < symbols.size(), "a signal drives a slot of the System");
    const std::string& name = symbols[s.slot].name;
    if (s.points.empty()) fail("signal for '" + name + "' has no points");
    for (size_t i = 0; i < s.points.size(); ++i) {
      if (!std::isfinite(s.points[i].first) || !std::isfinite(s.points[i].second)) {
        fail("signal for '" + name + "' has a non-finite point");
      }
      if (i > 0 && !(s.points[i - 1].first < s.points[i].first)) {
        fail("signal for '" + name + "': times must increase strictly");
      }
    }
    const auto [lo, hi] = system.InputBounds(s.slot);
    for (const auto& [t, v] : s.points) {
      if (v < lo || v > hi) {
        fail("input '" + name + "' = " + FormatNumber(v) + " at t = " + FormatNumber(t) +
             " lies outside its bounds [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
      }
    }
  }
  for (int s : symbols.SlotsOfKind(SymbolKind::kInput)) {
    const bool driven = std::any_of(inputs.begin(), inputs.end(),
                                    [s](const InputSignal& x) { return x.slot == s; });
    const auto [lo, hi] = system.InputBounds(s);
    if (!driven && (lo > 0.0 || hi < 0.0)) {
      fail("input '" + symbols[s].name + "' has no signal and 0 lies outside its bounds");
    }
  }
}

std::vector<double> Breakpoints(const std::vector<InputSignal>& inputs, double until,
                                const std::vector<ScheduledJump>& schedule) {
  std::vector<double> breakpoints;
  for (const InputSignal& s : inputs) {
    for (const auto& [t, v] : s.points) {
      if (t > 0.0 && t < until) breakpoints.push_back(t);
    }
  }
  for (const ScheduledJump& j : schedule) {
    if (j.time > 0.0 && j.time < until) breakpoints.push_back(j.time);
  }
  std::sort(breakpoints.begin(), breakpoints.end());
  breakpoints.erase(std::unique(breakpoints.begin(), breakpoints.end()), breakpoints.end());
  return breakpoints;
}

}  // namespace hybrid
