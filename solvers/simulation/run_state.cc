#include "solvers/simulation/run_state.h"

#include <algorithm>
#include <cmath>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/constraint.h"

namespace hybrid {

namespace {

// Residual semantics (include/hybrid/automaton/constraint.h's ResidualHolds, the one definition of
// a comparison within tolerance). `closure`: strict comparisons are taken as non-strict.
bool Holds(Relation relation, double r, double tol, bool closure) {
  return ResidualHolds(relation, r, tol, closure ? Boundary::kClosure : Boundary::kExact);
}

// Crossing direction that makes a guard comparison become true.
int GuardDirection(Relation r) {
  switch (r) {
    case Relation::kLess:
    case Relation::kLessEqual:
      return -1;
    case Relation::kGreater:
    case Relation::kGreaterEqual:
      return 1;
    case Relation::kEqual:
      return 0;
  }
  return 0;
}

}  // namespace

RunState::RunState(const CompiledModel& model, std::vector<double> env,
                   std::vector<InputSignal> signals, const SimulationOptions& options)
    : model_(model), env_(std::move(env)), signals_(std::move(signals)), options_(options) {
  HYBRID_ASSERT(env_.size() == static_cast<size_t>(model.system().symbols().size()),
                "the environment holds one value per System slot");
}

void RunState::Derivatives(double t, const double* x, double* dxdt) {
  Load(t, x);
  for (size_t i = 0; i < std::max<size_t>(x_size(), 1); ++i) dxdt[i] = 0.0;
  for (const auto& [index, rhs] : active_flows_) dxdt[index] = rhs->Evaluate(env_.data());
}

void RunState::Roots(double t, const double* x, double* g) {
  Load(t, x);
  for (size_t i = 0; i < root_residuals_.size(); ++i) {
    g[i] = root_residuals_[i]->Evaluate(env_.data());
  }
}

void RunState::Load(double t, const double* x) {
  const std::vector<int>& variable_slots = model_.variable_slots();
  for (size_t i = 0; i < variable_slots.size(); ++i) env_[variable_slots[i]] = x[i];
  for (const InputSignal& s : signals_) {
    if (s.shape == InputSignal::Shape::kLinear) env_[s.slot] = s.ValueAt(t);
  }
}

void RunState::SetStepInputs(double t) {
  for (const InputSignal& s : signals_) {
    if (s.shape == InputSignal::Shape::kStep) env_[s.slot] = s.ValueAt(t);
  }
}

void RunState::SetModes(const std::vector<int>& modes) {
  const std::vector<CompiledComponent>& components = model_.components();
  HYBRID_ASSERT(modes.size() == components.size(), "one mode per component");
  modes_ = modes;
  active_flows_.clear();
  roots_.clear();
  directions_.clear();
  for (size_t c = 0; c < components.size(); ++c) {
    HYBRID_ASSERT(modes_[c] >= 0 && modes_[c] < static_cast<int>(components[c].modes.size()),
                  "a component's mode index is in range");
    const CompiledMode& m = components[c].modes[modes_[c]];
    for (const auto& [index, rhs] : m.flows) active_flows_.emplace_back(index, &rhs);
    for (const auto& [slot, value] : m.discrete) env_[slot] = value;
    for (int t : m.outgoing) {
      const CompiledTransition& tr = components[c].transitions[t];
      for (size_t k = 0; k < tr.guard.size(); ++k) {
        roots_.push_back({false, static_cast<int>(c), t, static_cast<int>(k),
                          GuardDirection(tr.guard[k].relation)});
      }
    }
    for (size_t k = 0; k < m.invariant.size(); ++k) {
      if (m.invariant[k].relation == Relation::kEqual) continue;
      roots_.push_back({true, static_cast<int>(c), 0, static_cast<int>(k),
                        -GuardDirection(m.invariant[k].relation)});
    }
  }
  for (const RootRef& r : roots_) directions_.push_back(r.direction);
  // Resolved once per mode change: Roots runs at every step and inside CVODE's root search.
  root_residuals_.clear();
  for (const RootRef& r : roots_) root_residuals_.push_back(&ComparisonOf(r).residual);
  // Exact segments: every flow constant and every root function affine in the state, none of
  // them reading an input that varies within a segment (a linear signal).
  exact_ = true;
  for (size_t c = 0; c < components.size() && exact_; ++c) {
    const CompiledMode& m = components[c].modes[modes_[c]];
    exact_ = m.constant_rate && Steady(m.flow_slots);
  }
  for (size_t i = 0; i < roots_.size() && exact_; ++i) {
    const Linearity& l = ComparisonOf(roots_[i]).linearity;
    exact_ = l.terms.has_value() && Steady(l.slots);
  }
}

bool RunState::Steady(const std::vector<int>& slots) const {
  return std::none_of(slots.begin(), slots.end(), [&](int slot) {
    return std::any_of(signals_.begin(), signals_.end(), [&](const InputSignal& s) {
      return s.slot == slot && s.shape == InputSignal::Shape::kLinear;
    });
  });
}

double RunState::Slope(int i, const Eigen::VectorXd& dxdt) const {
  HYBRID_ASSERT(i >= 0 && static_cast<size_t>(i) < roots_.size(), "a root index is in range");
  const Linearity& linearity = ComparisonOf(roots_[i]).linearity;
  HYBRID_ASSERT(linearity.terms.has_value(), "a slope is asked of an affine root function only");
  double slope = 0.0;
  for (const auto& [index, coefficient] : *linearity.terms) {
    slope += coefficient * dxdt[index];
  }
  return slope;
}

const CompiledComparison& RunState::ComparisonOf(const RootRef& r) const {
  const CompiledComponent& cc = model_.components()[r.component];
  return r.invariant ? cc.modes[modes_[r.component]].invariant[r.comparison]
                     : cc.transitions[r.index].guard[r.comparison];
}

bool RunState::GuardHolds(int component, int t, bool closure) const {
  for (const CompiledComparison& c : model_.components()[component].transitions[t].guard) {
    if (!Holds(c.relation, c.residual.Evaluate(env_.data()), options_.event_tolerance, closure)) {
      return false;
    }
  }
  return true;
}

std::optional<std::string> RunState::ViolatedInvariantOf(size_t c) const {
  for (const CompiledComparison& cmp : model_.components()[c].modes[modes_[c]].invariant) {
    if (!Holds(cmp.relation, cmp.residual.Evaluate(env_.data()), options_.event_tolerance, true)) {
      return cmp.text;
    }
  }
  return std::nullopt;
}

std::optional<std::string> RunState::ViolatedInvariant() const {
  for (size_t c = 0; c < model_.components().size(); ++c) {
    if (auto violated = ViolatedInvariantOf(c)) return violated;
  }
  return std::nullopt;
}

double RunState::ResolutionTolerance(const CompiledComparison& c) const {
  return options_.event_tolerance +
         options_.resolution_tolerance *
             (std::abs(c.lhs.Evaluate(env_.data())) + std::abs(c.rhs.Evaluate(env_.data())));
}

std::optional<std::pair<double, double>> RunState::OffBoundary(int i) const {
  const CompiledComparison& c = ComparisonOf(roots_[i]);
  if (c.may_jump) return std::nullopt;
  const double residual = c.residual.Evaluate(env_.data());
  const double tolerance = ResolutionTolerance(c);
  if (std::abs(residual) <= tolerance) return std::nullopt;
  return std::make_pair(residual, tolerance);
}

std::optional<std::pair<std::string, double>> RunState::OutsideInvariant(const StateSample& s,
                                                                         double input_time) {
  const std::vector<CompiledComponent>& components = model_.components();
  const std::vector<int>& variable_slots = model_.variable_slots();
  HYBRID_ASSERT(s.modes.size() == components.size() &&
                    static_cast<size_t>(s.x.size()) == variable_slots.size(),
                "a recorded state has one mode per component and one value per variable");
  for (size_t c = 0; c < components.size(); ++c) {
    for (const auto& [slot, value] : components[c].modes[s.modes[c]].discrete) {
      env_[slot] = value;
    }
  }
  for (size_t i = 0; i < variable_slots.size(); ++i) env_[variable_slots[i]] = s.x[i];
  for (const InputSignal& signal : signals_) env_[signal.slot] = signal.ValueAt(input_time);
  for (size_t c = 0; c < components.size(); ++c) {
    for (const CompiledComparison& cmp : components[c].modes[s.modes[c]].invariant) {
      if (cmp.may_jump) continue;
      const double residual = cmp.residual.Evaluate(env_.data());
      // What holds exactly holds within any tolerance >= 0: the tolerance (two evaluations more)
      // only for a residual past the boundary.
      if (Holds(cmp.relation, residual, 0.0, true)) continue;
      if (!Holds(cmp.relation, residual, ResolutionTolerance(cmp), true)) {
        return std::make_pair(cmp.text, residual);
      }
    }
  }
  return std::nullopt;
}

}  // namespace hybrid
