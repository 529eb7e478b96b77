#include "hybrid/flowpipe/flowpipe_reachability.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "solvers/flowpipe/exploration.h"
#include "solvers/flowpipe/flowpipe_model.h"
#include "solvers/flowpipe/rounding.h"

namespace hybrid {
namespace {

using flowpipe_internal::Exploration;
using flowpipe_internal::FlowpipeModel;

constexpr int kHandlesModeLimit = 2000;

std::string Number(double x) {
  std::ostringstream out;
  out.precision(6);
  out << x;
  return out.str();
}

// The time up to which the exploration must go: the largest `within T`, and for properties
// without one the scenario's horizon (infinity without a scenario: the budget decides).
double TimeCap(const System& system, std::span<const Property> properties) {
  double cap = 0.0;
  bool unbounded = false;
  for (const Property& p : properties) {
    if (p.horizon) {
      cap = std::max(cap, *p.horizon);
    } else {
      unbounded = true;
    }
  }
  if (!unbounded) return cap;
  if (!system.scenario()) return std::numeric_limits<double>::infinity();
  return std::max(cap, system.scenario()->until);
}

}  // namespace

FlowpipeReachability::FlowpipeReachability() : FlowpipeReachability(Options()) {}

FlowpipeReachability::FlowpipeReachability(Options options) : options_(std::move(options)) {}

bool FlowpipeReachability::Handles(const System& system, std::span<const Property>,
                                   std::string* why) {
  flowpipe_internal::RoundingGuard rounding;
  try {
    FlowpipeModel model(system);
    std::set<int> seen;
    std::vector<int> work;
    for (const FlowpipeModel::Initial& init : model.Initials()) work.push_back(init.mode);
    while (!work.empty()) {
      const int m = work.back();
      work.pop_back();
      if (!seen.insert(m).second) continue;
      if (static_cast<int>(seen.size()) > kHandlesModeLimit) break;
      const FlowpipeModel::CompiledMode& mode = model.Mode(m);
      if (!mode.tape) {
        if (why) *why = "mode " + mode.name + ": " + mode.unsupported;
        return false;
      }
      model.MakeJumps(m);
      for (const FlowpipeModel::Jump& j : model.Mode(m).jumps) work.push_back(j.target);
    }
  } catch (const std::exception& e) {
    if (why) *why = e.what();
    return false;
  }
  return true;
}

std::vector<CheckResult> FlowpipeReachability::Check(const System& system,
                                                     std::span<const Property> properties,
                                                     Usage* usage, ReachSet* reach_set) const {
  if (options_.order < 1 || options_.order > 12) {
    throw std::invalid_argument("the Taylor order must be from 1 to 12, not " +
                                std::to_string(options_.order));
  }
  if (!(options_.step >= 0) || !std::isfinite(options_.step)) {
    throw std::invalid_argument("the step must be a non-negative number, not " +
                                Number(options_.step));
  }
  if (options_.max_steps <= 0 || options_.max_entries <= 0 || options_.max_symbols < 0) {
    throw std::invalid_argument("the flowpipe budget (steps, entries, symbols) must be positive");
  }
  const auto start = std::chrono::steady_clock::now();
  flowpipe_internal::RoundingGuard rounding;
  FlowpipeModel model(system);
  const double cap = TimeCap(system, properties);
  Exploration ex(model, properties, options_, cap, reach_set);
  ex.Run();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double frontier = ex.frontier();
  const std::string stop = ex.stop_reason().empty() ? "" : " (" + ex.stop_reason() + ")";
  const std::string effort = std::to_string(ex.steps()) + " Taylor steps, " +
                             std::to_string(ex.entries()) + " mode entries";
  std::vector<CheckResult> results;
  for (std::size_t k = 0; k < properties.size(); ++k) {
    const Property& p = properties[k];
    const Exploration::Finding& f = ex.findings()[k];
    CheckResult r;
    r.property = p.name;
    r.kind = p.kind;
    r.method = "flowpipe";
    r.seconds = seconds;
    const bool reach = p.kind == Property::Kind::kReach;
    const Verdict decided = reach ? Verdict::kUnreachable : Verdict::kProved;
    if (f.met) {
      r.reason = std::string("the flowpipe (an over-approximation) may ") +
                 (reach ? "reach the target" : "meet a violation") + " in mode " + f.met_mode +
                 " from t = " + Number(f.met_time) + " (" + effort + ")";
    } else if (p.horizon) {
      if (frontier >= *p.horizon) {
        r.verdict = decided;
        r.reason = "no state reachable within " + Number(*p.horizon) + " " +
                   (reach ? "meets the target" : "violates it") +
                   ": flowpipe to t = " + Number(*p.horizon) + " (" + effort + ")";
      } else {
        r.reason = "the flowpipe covers only t < " + Number(frontier) + stop;
      }
    } else if (std::isinf(frontier)) {
      r.verdict = decided;
      r.reason = "the flowpipe reached a fixpoint: no reachable state " +
                 std::string(reach ? "meets the target" : "violates it") + ", for all time (" +
                 effort + ")";
    } else if (frontier > 0) {
      r.verdict = decided;
      r.within = std::min(frontier, cap);
      r.reason = "no state reachable within " + Number(*r.within) + " " +
                 (reach ? "meets the target" : "violates it") + "; later times not covered" +
                 (frontier >= cap ? " (the scenario's horizon)" : stop) + " (" + effort + ")";
    } else {
      r.reason = "the flowpipe covers no time" + stop;
    }
    results.push_back(std::move(r));
  }
  if (usage) {
    usage->steps = ex.steps();
    usage->entries = ex.entries();
    usage->frontier = frontier;
    usage->complete = std::isinf(frontier);
  }
  return results;
}

}  // namespace hybrid
