#include "solvers/simulation/compiled_component.h"

#include <algorithm>
#include <stdexcept>

#include "automaton/internal_assert.h"

namespace hybrid {

bool MayJump(const Expression& e, const std::function<bool(int)>& varies) {
  std::vector<Expression> stack = {e};
  std::set<const void*> seen;
  while (!stack.empty()) {
    const Expression node = stack.back();
    stack.pop_back();
    if (!seen.insert(node.node_id()).second) continue;
    switch (node.op()) {
      case Op::kSign:
      case Op::kTan:
      case Op::kAtan2:
        return true;
      case Op::kDiv: {
        const std::vector<int> slots = node.args()[1].Slots();
        if (std::any_of(slots.begin(), slots.end(), varies)) return true;
        break;
      }
      default:
        break;
    }
    for (const Expression& arg : node.args()) stack.push_back(arg);
  }
  return false;
}

namespace {

// Compiles one component of a System: its flows, guards, resets and invariants as expressions over
// the System's slots (through the component's global_slot map), with what the run needs to know
// about each comparison (linearity, jumps) and the component's first initial state.
class ComponentCompiler {
 public:
  // `x_index`: System slot -> index in x (-1 for a slot that is not a continuous variable);
  // `parameter_env`: the System's slots with the parameters filled. All must outlive the compiler.
  // `fixed`: System slot -> whether the compiled model holds the parameter there as a constant
  // (set by Compile; see SimulationOptions::parameters).
  ComponentCompiler(const SymbolTable& symbols, const Component& comp,
                    const std::vector<int>& x_index, const std::vector<double>& parameter_env,
                    std::vector<char>& fixed)
      : symbols_(symbols),
        comp_(comp),
        x_index_(x_index),
        parameter_env_(parameter_env),
        fixed_(fixed) {
    HYBRID_ASSERT(x_index.size() == static_cast<size_t>(symbols.size()) &&
                      parameter_env.size() == x_index.size() && fixed.size() == x_index.size(),
                  "the slot maps of the compiler cover the System's slots");
  }

  // The compiled component: its modes, then its transitions (each the outgoing one of its source
  // mode), then its first initial state (interval values at their
  // midpoint). Throws std::invalid_argument if the component has no initial state.
  CompiledComponent Compile() const {
    const Automaton& a = comp_.automaton;
    CompiledComponent cc;
    cc.instance = comp_.instance;
    for (const Mode& m : a.modes()) {
      CompiledMode cm = CompileMode(m);
      cc.mode_names.push_back(m.name);
      cc.modes.push_back(std::move(cm));
    }
    for (int t = 0; t < a.num_transitions(); ++t) {
      const Transition& tr = a.transitions()[t];
      CompiledTransition ct = CompileTransition(tr);
      HYBRID_ASSERT(ct.source >= 0 && ct.source < static_cast<int>(cc.modes.size()),
                    "a transition's source is a mode of its automaton");
      cc.modes[ct.source].outgoing.push_back(t);
      cc.transitions.push_back(std::move(ct));
    }
    if (a.initial_states().empty()) {
      throw std::invalid_argument("component '" + a.name() +
                                  "' has no initial state: it cannot be simulated");
    }
    const InitialState& init = a.initial_states().front();
    cc.initial_mode = init.mode.value();
    const std::vector<double> env = a.ParameterEnvironment();
    for (const InitialValue& v : init.values) {
      const double lo = v.range.lo.Evaluate(env);
      const double hi = v.range.hi.Evaluate(env);
      for (const Expression* bound : {&v.range.lo, &v.range.hi}) {
        for (const int slot : Global(*bound).Slots()) FixParameter(slot);
      }
      cc.initial_values.emplace_back(x_index_[comp_.global_slot[v.slot]], 0.5 * (lo + hi));
    }
    return cc;
  }

 private:
  // `e` with the component's slots renamed to the System's.
  Expression Global(const Expression& e) const {
    return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
      const int g = comp_.global_slot[slot];
      return Expression::Symbol(symbols_[g].name, g);
    });
  }

  // The linearity of `e` (System slots): its affine terms in x with the parameters folded, if it
  // is affine, and every slot it reads.
  Linearity LinearityOf(const Expression& e) const {
    Linearity l;
    l.slots = e.Slots();
    const Expression folded =
        e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
          if (symbols_[slot].kind != SymbolKind::kParameter) return std::nullopt;
          return Expression::Constant(parameter_env_[slot]);
        });
    if (const auto affine = folded.AsAffine()) {
      // Coefficients that parameters may change: not affine with the parameters as unknowns.
      if (!e.AsAffine()) {
        for (const int slot : l.slots) FixParameter(slot);
      }
      l.terms.emplace();
      for (const auto& [slot, coefficient] : affine->terms) {
        if (x_index_[slot] >= 0) l.terms->emplace_back(x_index_[slot], coefficient);
      }
    }
    return l;
  }

  // A guard or invariant comparison of the component.
  CompiledComparison CompileComparison(const Comparison& c) const {
    const Expression residual = Global(c.Residual());
    return CompiledComparison{CompiledExpression(residual),
                              c.relation,
                              c.ToString(),
                              LinearityOf(residual),
                              CompiledExpression(Global(c.lhs)),
                              CompiledExpression(Global(c.rhs)),
                              MayJump(residual, [&](int slot) {
                                return symbols_[slot].kind == SymbolKind::kVariable ||
                                       symbols_[slot].kind == SymbolKind::kInput;
                              })};
  }

  // A mode: flows (constant_rate when none reads a continuous variable), invariant, discrete
  // values; its outgoing transitions are added by Compile.
  CompiledMode CompileMode(const Mode& m) const {
    CompiledMode cm;
    cm.constant_rate = true;
    for (const auto& [slot, rhs] : m.flows) {
      const Expression e = Global(rhs);
      cm.flows.emplace_back(x_index_[comp_.global_slot[slot]], CompiledExpression(e));
      for (int read : e.Slots()) {
        cm.constant_rate = cm.constant_rate && x_index_[read] < 0;
        cm.flow_slots.push_back(read);
      }
    }
    for (const Comparison& c : m.invariant.comparisons)
      cm.invariant.push_back(CompileComparison(c));
    for (const auto& [slot, value] : m.discrete_values) {
      cm.discrete.emplace_back(comp_.global_slot[slot], value);
    }
    return cm;
  }

  // A transition, its name qualified by the instance.
  CompiledTransition CompileTransition(const Transition& tr) const {
    CompiledTransition ct;
    ct.name = comp_.instance.empty() ? tr.name : comp_.instance + "." + tr.name;
    ct.label = tr.label;
    ct.source = tr.source.value();
    ct.target = tr.target.value();
    ct.urgency = tr.urgency;
    for (const Comparison& c : tr.guard.comparisons) ct.guard.push_back(CompileComparison(c));
    for (const Reset& r : tr.resets) {
      ct.resets.emplace_back(x_index_[comp_.global_slot[r.slot]],
                             CompiledExpression(Global(r.value)));
    }
    return ct;
  }

  void FixParameter(int slot) const {
    if (symbols_[slot].kind == SymbolKind::kParameter) fixed_[slot] = 1;
  }

  const SymbolTable& symbols_;
  const Component& comp_;
  const std::vector<int>& x_index_;
  const std::vector<double>& parameter_env_;
  std::vector<char>& fixed_;
};

}  // namespace

CompiledComponent CompileComponent(const SymbolTable& symbols, const Component& component,
                                   const std::vector<int>& x_index,
                                   const std::vector<double>& parameter_env,
                                   std::vector<char>& fixed) {
  return ComponentCompiler(symbols, component, x_index, parameter_env, fixed).Compile();
}

}  // namespace hybrid
