#include "solvers/reachability/variable_liveness.h"

#include <algorithm>
#include <set>

namespace hybrid {
namespace {

// The System slots `e` reads (component c's slots mapped through global_slot).
void AddReads(const Component& c, const Expression& e, std::set<int>& out) {
  for (const int s : e.Slots()) out.insert(c.global_slot[static_cast<size_t>(s)]);
}

void AddReads(const Component& c, const Constraint& k, std::set<int>& out) {
  for (const Comparison& cmp : k.comparisons) {
    AddReads(c, cmp.lhs, out);
    AddReads(c, cmp.rhs, out);
  }
}

// What one component reads in each mode and on each transition, in System slots.
struct ComponentReads {
  std::vector<std::set<int>> mode;        // invariant and flows of each mode
  std::vector<std::set<int>> transition;  // guard and reset right-hand sides
  std::vector<std::set<int>> written;     // slots each transition resets
  std::set<int> mentioned;                // everything above, declared variables, initial values
};

ComponentReads ReadsOf(const Component& c) {
  const Automaton& a = c.automaton;
  ComponentReads r;
  for (const Mode& m : a.modes()) {
    std::set<int>& reads = r.mode.emplace_back();
    AddReads(c, m.invariant, reads);
    for (const auto& [slot, rhs] : m.flows) {
      AddReads(c, rhs, reads);
      r.mentioned.insert(c.global_slot[static_cast<size_t>(slot)]);
    }
    r.mentioned.insert(reads.begin(), reads.end());
  }
  for (const Transition& t : a.transitions()) {
    std::set<int>& reads = r.transition.emplace_back();
    std::set<int>& written = r.written.emplace_back();
    AddReads(c, t.guard, reads);
    for (const Reset& reset : t.resets) {
      AddReads(c, reset.value, reads);
      written.insert(c.global_slot[static_cast<size_t>(reset.slot)]);
    }
    r.mentioned.insert(reads.begin(), reads.end());
    r.mentioned.insert(written.begin(), written.end());
  }
  for (const VariableInfo& v : a.variables()) {
    r.mentioned.insert(c.global_slot[static_cast<size_t>(v.slot)]);
  }
  for (const InitialState& init : a.initial_states()) {
    for (const InitialValue& v : init.values) {
      r.mentioned.insert(c.global_slot[static_cast<size_t>(v.slot)]);
    }
  }
  return r;
}

// The modes of `a` where `slot` is live (the least fixpoint of the class comment).
std::vector<bool> LiveModes(const Automaton& a, const ComponentReads& r, int slot) {
  std::vector<bool> live(static_cast<size_t>(a.num_modes()), false);
  for (int m = 0; m < a.num_modes(); ++m) live[static_cast<size_t>(m)] = r.mode[m].count(slot);
  for (bool changed = true; changed;) {
    changed = false;
    for (int t = 0; t < a.num_transitions(); ++t) {
      const Transition& tr = a.transition(TransitionId(t));
      const size_t from = static_cast<size_t>(tr.source.value());
      if (live[from]) continue;
      const bool reads = r.transition[static_cast<size_t>(t)].count(slot) > 0;
      const bool passes_on = r.written[static_cast<size_t>(t)].count(slot) == 0 &&
                             live[static_cast<size_t>(tr.target.value())];
      if (reads || passes_on) {
        live[from] = true;
        changed = true;
      }
    }
  }
  return live;
}

}  // namespace

VariableLiveness::VariableLiveness(const System& system, const std::vector<int>& observed) {
  const std::span<const Component> components = system.components();
  std::vector<ComponentReads> reads;
  std::vector<int> mentions(static_cast<size_t>(system.symbols().size()), 0);
  for (const Component& c : components) {
    reads.push_back(ReadsOf(c));
    for (const int s : reads.back().mentioned) ++mentions[static_cast<size_t>(s)];
  }
  for (const int s : observed) mentions[static_cast<size_t>(s)] += 2;
  for (size_t c = 0; c < components.size(); ++c) {
    const Automaton& a = components[c].automaton;
    std::vector<std::vector<int>>& dead = dead_.emplace_back(static_cast<size_t>(a.num_modes()));
    for (const int s : reads[c].mentioned) {
      if (system.symbols()[s].kind != SymbolKind::kVariable ||
          mentions[static_cast<size_t>(s)] != 1)
        continue;
      const std::vector<bool> live = LiveModes(a, reads[c], s);
      for (int m = 0; m < a.num_modes(); ++m) {
        if (!live[static_cast<size_t>(m)]) dead[static_cast<size_t>(m)].push_back(s);
      }
    }
  }
}

const std::vector<int>& VariableLiveness::DeadAt(int component, int mode) const {
  return dead_.at(static_cast<size_t>(component)).at(static_cast<size_t>(mode));
}

}  // namespace hybrid
