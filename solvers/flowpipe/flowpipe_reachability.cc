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

// The result for property `k` (`p`) from one exploration from `pieces` initial boxes (see the
// class comment).
CheckResult Result(const Property& p, std::size_t k, const Exploration& ex, double cap,
                   std::size_t pieces, double seconds) {
  const Exploration::Finding& f = ex.findings()[k];
  const double frontier = ex.frontier();
  const std::string stop = ex.stop_reason().empty() ? "" : " (" + ex.stop_reason() + ")";
  const std::string effort = std::to_string(pieces) + " initial box" + (pieces == 1 ? "" : "es") +
                             ", " + std::to_string(ex.steps()) + " Taylor steps, " +
                             std::to_string(ex.entries()) + " mode entries";
  CheckResult r;
  r.property = p.name;
  r.kind = p.kind;
  r.method = "flowpipe";
  r.seconds = seconds;
  const bool reach = p.kind == Property::Kind::kReach;
  const Verdict decided = reach ? Verdict::kUnreachable : Verdict::kProved;
  const std::string meets = reach ? "meets the target" : "violates it";
  if (f.met) {
    r.reason = std::string("the flowpipe (an over-approximation) may ") +
               (reach ? "reach the target" : "meet a violation") + " in mode " + f.met_mode +
               " from t = " + Number(f.met_time) + " (" + effort + ")";
  } else if (p.horizon) {
    if (frontier >= *p.horizon) {
      r.verdict = decided;
      r.reason =
          "no state reachable within " + Number(*p.horizon) + " " + meets + " (" + effort + ")";
    } else {
      r.reason = "the flowpipe covers only t < " + Number(frontier) + stop;
    }
  } else if (std::isinf(frontier)) {
    r.verdict = decided;
    r.reason = "the flowpipe reached a fixpoint: no reachable state " + meets + ", for all time (" +
               effort + ")";
  } else if (frontier > 0) {
    r.verdict = decided;
    r.within = std::min(frontier, cap);
    r.reason = "no state reachable within " + Number(*r.within) + " " + meets +
               "; later times not covered" +
               (frontier >= cap ? " (the scenario's horizon)" : stop) + " (" + effort + ")";
  } else {
    r.reason = "the flowpipe covers no time" + stop;
  }
  return r;
}

// Splits every box in two along its widest component (state components: variables and
// uncertain parameters); false when no box has width left.
bool SplitAll(std::vector<FlowpipeModel::Initial>& pieces) {
  std::vector<FlowpipeModel::Initial> out;
  bool split = false;
  for (const FlowpipeModel::Initial& p : pieces) {
    std::size_t widest = 0;
    double width = 0.0;
    for (std::size_t i = 0; i < p.box.size(); ++i) {
      const double w = p.box[i].hi - p.box[i].lo;
      if (w > width) {
        width = w;
        widest = i;
      }
    }
    if (!(width > 0) || !std::isfinite(width)) {
      out.push_back(p);
      continue;
    }
    split = true;
    const double mid = p.box[widest].Mid();
    FlowpipeModel::Initial lower = p, upper = p;
    lower.box[widest].hi = mid;
    upper.box[widest].lo = mid;
    out.push_back(std::move(lower));
    out.push_back(std::move(upper));
  }
  pieces = std::move(out);
  return split;
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
  std::string why;
  if (!Handles(system, properties, &why)) {  // e.g. --method flowpipe on a model it cannot read
    std::vector<CheckResult> results;
    for (const Property& p : properties) {
      CheckResult r;
      r.property = p.name;
      r.kind = p.kind;
      r.method = "flowpipe";
      r.reason = "the flowpipe engine does not apply: " + why;
      results.push_back(std::move(r));
    }
    return results;
  }
  flowpipe_internal::RoundingGuard rounding;
  FlowpipeModel model(system);
  const double cap = TimeCap(system, properties);
  std::vector<std::optional<CheckResult>> decided(properties.size());
  std::vector<CheckResult> last(properties.size());
  std::vector<char> not_worth(properties.size(), 0);  // evidently false: not refined
  std::vector<FlowpipeModel::Initial> pieces = model.Initials();
  Usage total;
  for (int level = 0;; ++level) {
    FlowpipeReachability::Options options = options_;
    options.max_steps = options_.max_steps - total.steps;
    if (reach_set) *reach_set = {};
    Exploration ex(model, properties, options, cap, reach_set);
    ex.Run(pieces);
    total.steps += ex.steps();
    total.entries += ex.entries();
    total.frontier = ex.frontier();
    total.complete = std::isinf(ex.frontier());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    bool open = false;
    for (std::size_t k = 0; k < properties.size(); ++k) {
      if (decided[k]) continue;
      last[k] = Result(properties[k], k, ex, cap, pieces.size(), seconds);
      if (last[k].verdict != Verdict::kUnknown) {
        decided[k] = last[k];
      } else if (!ex.findings()[k].met_wholly && !not_worth[k]) {
        open = true;
      }
    }
    if (open && level == 0 && options_.evidently_false) {
      std::vector<Property> asked;
      std::vector<std::size_t> where;
      for (std::size_t k = 0; k < properties.size(); ++k) {
        if (!decided[k] && !ex.findings()[k].met_wholly) {
          asked.push_back(properties[k]);
          where.push_back(k);
        }
      }
      const std::vector<bool> refuted = options_.evidently_false(system, asked);
      open = false;
      for (std::size_t i = 0; i < where.size(); ++i) {
        if (i < refuted.size() && refuted[i]) {
          not_worth[where[i]] = true;
        } else {
          open = true;
        }
      }
    }
    // Split the initial sets where a property is still open, while the budget lasts.
    if (!open || total.steps >= options_.max_steps ||
        static_cast<int>(pieces.size()) * 2 > options_.max_pieces)
      break;
    if (!SplitAll(pieces)) break;
  }
  std::vector<CheckResult> results;
  for (std::size_t k = 0; k < properties.size(); ++k)
    results.push_back(decided[k] ? *decided[k] : last[k]);
  if (usage) *usage = total;
  return results;
}

}  // namespace hybrid
