#include "solvers/simulation/jump_selector.h"

#include <algorithm>

#include "automaton/internal_assert.h"

namespace hybrid {

JumpSelector::JumpSelector(const std::vector<CompiledComponent>& components, const RunState& run)
    : components_(components),
      run_(run),
      reached_invariant_(components.size()),
      reached_guards_(components.size()) {}

void JumpSelector::ForgetAll() {
  for (auto& s : reached_invariant_) s.clear();
  for (auto& g : reached_guards_) g.clear();
}

void JumpSelector::Note(const std::vector<int>& crossed) {
  for (int r : crossed) {
    HYBRID_ASSERT(r >= 0 && static_cast<size_t>(r) < run_.roots().size(),
                  "a crossed root function is one of the current ones");
    const RootRef& ref = run_.roots()[r];
    if (ref.invariant) {
      reached_invariant_[ref.component] = components_[ref.component]
                                              .modes[run_.modes()[ref.component]]
                                              .invariant[ref.comparison]
                                              .text;
    } else {
      reached_guards_[ref.component].push_back(ref.index);
    }
  }
}

void JumpSelector::ReachInvariant(size_t c, std::string text) {
  HYBRID_ASSERT(c < reached_invariant_.size(), "a component index is in range");
  reached_invariant_[c] = std::move(text);
}

void JumpSelector::Forget(const Jump& jump) {
  for (const auto& [c, ti] : jump) {
    reached_invariant_[c].clear();
    reached_guards_[c].clear();
  }
}

std::optional<std::string> JumpSelector::FirstReachedInvariant() const {
  for (const std::string& text : reached_invariant_) {
    if (!text.empty()) return text;
  }
  return std::nullopt;
}

bool JumpSelector::GuardReached(int c, int ti) const {
  return std::find(reached_guards_[c].begin(), reached_guards_[c].end(), ti) !=
         reached_guards_[c].end();
}

std::vector<Jump> JumpSelector::Candidates() const {
  std::vector<Jump> jumps;
  for (int pass = 0; pass < 2; ++pass) {  // urgent first, then lazy
    const Urgency urgency = pass == 0 ? Urgency::kUrgent : Urgency::kLazy;
    for (size_t c = 0; c < components_.size(); ++c) {
      if (urgency == Urgency::kLazy && reached_invariant_[c].empty()) continue;
      const CompiledComponent& cc = components_[c];
      for (int ti : cc.modes[run_.modes()[c]].outgoing) {
        const CompiledTransition& tr = cc.transitions[ti];
        if (tr.urgency != urgency) continue;
        const bool crossed_now = GuardReached(static_cast<int>(c), ti);
        const bool enabled = urgency == Urgency::kLazy
                                 ? run_.GuardHolds(static_cast<int>(c), ti, true)
                                 : (crossed_now ? run_.GuardHolds(static_cast<int>(c), ti, true)
                                                : run_.GuardHolds(static_cast<int>(c), ti, false));
        if (!enabled) continue;
        // Synchronisation partners.
        Jump jump = {{static_cast<int>(c), ti}};
        if (tr.label.empty() || AddPartners(c, tr.label, &jump)) jumps.push_back(std::move(jump));
      }
    }
  }
  return jumps;
}

bool JumpSelector::AddPartners(size_t c, const std::string& label, Jump* jump) const {
  for (size_t d = 0; d < components_.size(); ++d) {
    if (d == c || !components_[d].alphabet.count(label)) continue;
    const CompiledComponent& dc = components_[d];
    bool found = false;
    for (int ui : dc.modes[run_.modes()[d]].outgoing) {
      // A partner's guard is read as the leader's: in its closure only where it crossed at this
      // instant (a comparison of an input or parameter stays strict, as in every engine).
      if (dc.transitions[ui].label == label &&
          run_.GuardHolds(static_cast<int>(d), ui, GuardReached(static_cast<int>(d), ui))) {
        jump->emplace_back(static_cast<int>(d), ui);
        found = true;
        break;
      }
    }
    if (!found) return false;
  }
  return true;
}

EventRecord::Cause JumpSelector::CauseInIteration(const std::vector<Jump>& jumps) const {
  EventRecord::Cause cause = EventRecord::Cause::kEnabled;
  if (!jumps.empty()) {
    const auto [c0, t0] = jumps.front().front();
    if (components_[c0].transitions[t0].urgency == Urgency::kLazy) {
      cause = EventRecord::Cause::kInvariant;
    } else {
      for (const auto& [c, ti] : jumps.front()) {
        if (GuardReached(c, ti)) cause = EventRecord::Cause::kCrossing;
      }
    }
  }
  return cause;
}

}  // namespace hybrid
