#include "solvers/verification/trace_builder.h"

#include <algorithm>
#include <utility>

#include "automaton/internal_assert.h"

namespace hybrid {

TraceBuilder::TraceBuilder(const System& system, const ProofJob& job, SmtEncoding& encoding)
    : system_(system), job_(job), enc_(encoding), a_(encoding.automaton()) {
  HYBRID_ASSERT(job.automaton == &encoding.automaton(), "the encoding is of the job's automaton");
}

std::optional<Trace> TraceBuilder::Build(const z3::model& model,
                                         const std::vector<SmtEncoding::PathStep>& path) {
  HYBRID_ASSERT(!path.empty(), "a path has a first state");
  const int depth = static_cast<int>(path.size()) - 1;
  Trace trace;
  trace.parameters = enc_.ReadParameters(model);
  // The initial state the path starts from, and its values where that state is a box.
  const int start = enc_.InitialIndex(model);
  if (start < 0) return std::nullopt;
  AddInitialStates(start, trace);
  AddInitialValues(start, path[0], trace);
  AddInputSchedule(path, depth, trace);
  return trace;
}

void TraceBuilder::AddInitialStates(int start, Trace& trace) const {
  if (job_.component >= 0) {
    trace.initial_states.emplace_back(job_.component, start);
    return;
  }
  // A product's initial state `start`, decomposed (mixed radix, the last component fastest).
  const auto components = system_.components();
  std::vector<std::pair<int, int>> states;
  for (auto c = job_.product_components.rbegin(); c != job_.product_components.rend(); ++c) {
    const int n = static_cast<int>(components[*c].automaton.initial_states().size());
    HYBRID_ASSERT(n > 0, "a component of a product has an initial state");
    states.emplace_back(*c, start % n);
    start /= n;
  }
  trace.initial_states.assign(states.rbegin(), states.rend());
}

void TraceBuilder::AddInitialValues(int start, const SmtEncoding::PathStep& s0,
                                    Trace& trace) const {
  const InitialState& init = a_.initial_states()[static_cast<std::size_t>(start)];
  for (const InitialValue& iv : init.values) {
    if (iv.is_point) continue;
    int index = 0;
    for (const VariableInfo& v : a_.variables()) {
      if (v.slot == iv.slot) break;
      ++index;
    }
    HYBRID_ASSERT(
        index < static_cast<int>(s0.x.size()) && iv.slot < static_cast<int>(job_.to_system.size()),
        "an initial box sets a continuous variable of the job's automaton");
    trace.initial_values.emplace_back(system_.symbols()[job_.to_system[iv.slot]].name, s0.x[index]);
  }
}

void TraceBuilder::AddInputSchedule(const std::vector<SmtEncoding::PathStep>& path, int depth,
                                    Trace& trace) const {
  const int ni = static_cast<int>(a_.inputs().size());
  std::vector<InputSignal> signals(ni);
  double t = 0.0;
  for (int i = 0; i < ni; ++i) {
    signals[i].slot = job_.to_system[a_.inputs()[i].slot];
    signals[i].shape = InputSignal::Shape::kStep;
  }
  auto add_piece = [&](const std::vector<double>& u, double duration) {
    for (int i = 0; i < ni; ++i) {
      auto& pts = signals[i].points;
      if (pts.empty() || pts.back().second != u[i]) {
        if (!pts.empty() && pts.back().first == t)
          pts.back().second = u[i];
        else
          pts.emplace_back(t, u[i]);
      }
    }
    t += duration;
  };
  // The input held: a flow's, then at a jump the values its guard reads (the jump happens at
  // that instant, where the input takes them; a flow that follows at the same instant with
  // other values overrides them, and then the replay decides).
  std::vector<double> current(ni, 0.0);
  for (int k = 0; k < depth; ++k) {
    if (path[k].flow && path[k].duration > 0) {
      current = path[k].input;
      add_piece(current, path[k].duration);
    } else if (!path[k].flow && path[k].transition >= 0) {
      if (GuardInputs(path[k], current)) add_piece(current, 0.0);
    }
  }
  // A short tail with the last input held, so that events due exactly at the end of the path
  // happen (an input that changed there would decide them instead).
  const double tail = std::max(1e-6, 1e-6 * t);
  add_piece(current, tail);
  trace.inputs.until = t;
  for (auto& s : signals) {
    if (s.points.empty()) s.points.emplace_back(0.0, 0.0);
    trace.inputs.inputs.push_back(s);
  }
}

bool TraceBuilder::GuardInputs(const SmtEncoding::PathStep& jump,
                               std::vector<double>& current) const {
  const hybrid::Transition& tr = a_.transitions()[static_cast<std::size_t>(jump.transition)];
  bool changed = false;
  for (std::size_t i = 0; i < current.size(); ++i) {
    const int slot = a_.inputs()[i].slot;
    bool read = false;
    for (const Comparison& c : tr.guard.comparisons) {
      for (int s : c.Residual().Slots()) read = read || s == slot;
    }
    if (read && current[i] != jump.input[i]) {
      current[i] = jump.input[i];
      changed = true;
    }
  }
  return changed;
}

}  // namespace hybrid
