#include "solvers/verification/induction_round.h"

#include <algorithm>
#include <string>
#include <utility>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/log.h"

namespace hybrid {

InductionRound::InductionRound(SmtEncoding& encoding, QueryMeter& meter, unsigned resource_limit,
                               int k, std::vector<ProofCandidate*> candidates,
                               std::uint64_t ceiling, std::vector<const ProofCandidate*> lemmas)
    : enc_(encoding),
      meter_(meter),
      ctx_(encoding.context()),
      resource_limit_(resource_limit),
      k_(k),
      ceiling_(ceiling),
      set_(std::move(candidates)),
      lemmas_(std::move(lemmas)) {
  HYBRID_ASSERT(k >= 1, "k-induction starts at k = 1");
  for (const ProofCandidate* c : set_) {
    HYBRID_ASSERT(c != nullptr && c->invariant, "induction candidates are invariants");
  }
  for (const ProofCandidate* c : lemmas_) {
    HYBRID_ASSERT(c != nullptr && c->invariant && c->proved, "lemmas are proved invariants");
  }
  alive_.assign(set_.size(), true);
  hypotheses_from_.resize(enc_.automaton().num_modes());
}

void InductionRound::Run() {
  // First the step from any mode in one query (cheap where the flows are simple, however many
  // modes), while it decides; then per mode. Not where a flow is separable: its closed form is
  // polynomial, which the one-query solver (no nlsat) does not decide (the finger's, the hand's
  // and the controlled models' came back unknown after 10^6 units, 0.16 to 0.18 s each).
  bool whole = true;
  for (int m = 0; m < enc_.automaton().num_modes(); ++m) {
    whole = whole && enc_.flow_class(ModeId(m)) != FlowClass::kSeparable;
  }
  bool changed = true;
  while (changed) {
    changed = false;
    ForgetHypotheses();
    if (whole && !Living().empty() && meter_.budget().used() < ceiling_ &&
        !meter_.budget().SafetyExpired()) {
      std::vector<std::size_t> failed;
      const z3::check_result r = StepQuery(-1, Living(), resource_limit_ / 25, failed);
      if (r == z3::unsat) break;
      if (r == z3::sat) {
        changed = Drop(failed);
        continue;
      }
      whole = false;
    }
    changed = StepPerMode() || changed;
  }
}

std::vector<ProofCandidate*> InductionRound::Inductive() const {
  std::vector<ProofCandidate*> out;
  for (std::size_t j = 0; j < set_.size(); ++j) {
    if (alive_[j]) out.push_back(set_[j]);
  }
  return out;
}

std::vector<std::size_t> InductionRound::Living() const {
  std::vector<std::size_t> goals;
  for (std::size_t j = 0; j < set_.size(); ++j) {
    if (alive_[j]) goals.push_back(j);
  }
  return goals;
}

bool InductionRound::Drop(const std::vector<std::size_t>& failed) {
  bool changed = false;
  for (std::size_t j : failed) {
    HYBRID_ASSERT(j < alive_.size(), "a dropped candidate is one of the round's");
    changed = changed || alive_[j];
    alive_[j] = false;
  }
  if (changed) ForgetHypotheses();  // weaker now: modes already passed are checked again
  return changed;
}

bool InductionRound::StepPerMode() {
  bool changed = false;
  for (int m = 0; m < enc_.automaton().num_modes(); ++m) {
    std::vector<std::size_t> goals = Living(), failed;
    if (goals.empty()) break;
    if (meter_.budget().used() >= ceiling_ || meter_.budget().SafetyExpired()) {
      cut_ = true;  // nothing left to prove with: every candidate is dropped
      failed = goals;
    } else if (enc_.flow_class(ModeId(m)) != FlowClass::kSeparable) {
      failed = FailedFrom(m, goals, std::nullopt);
    } else {
      // A separable flow's closed form is polynomial: nlsat decides it alone far sooner than
      // beside the mode's jumps (the finger's phase-3 modes: each move at 1/100 of the limit,
      // where the moves together ran out). One move at a time, each for the candidates that the
      // moves before left standing.
      for (const Move& move : MovesFrom(m)) {
        std::vector<std::size_t> standing;
        for (std::size_t j : goals) {
          if (std::find(failed.begin(), failed.end(), j) == failed.end()) standing.push_back(j);
        }
        if (standing.empty()) break;
        const std::vector<std::size_t> f = FailedFrom(m, standing, move);
        failed.insert(failed.end(), f.begin(), f.end());
      }
    }
    changed = Drop(failed) || changed;
  }
  return changed;
}

std::vector<std::size_t> InductionRound::FailedFrom(int m, const std::vector<std::size_t>& goals,
                                                    std::optional<Move> move) {
  std::vector<std::size_t> failed;
  if (StepQuery(m, goals, resource_limit_ / 100, failed, false, move) != z3::unknown) {
    return failed;
  }
  // Split per candidate: in a context of the mode's own, then in this one with a larger limit
  // and the full one (a candidate dropped for want of resources takes with it every candidate
  // that needs it as a lemma).
  failed.clear();
  for (std::size_t j : goals) {
    std::vector<std::size_t> f;
    if (StepQuery(m, {j}, resource_limit_ / 25, f, true, move) == z3::unknown &&
        StepQuery(m, {j}, resource_limit_ / 5, f, false, move) == z3::unknown &&
        StepQuery(m, {j}, resource_limit_, f, false, move) == z3::unknown) {
      f.push_back(j);
    }
    failed.insert(failed.end(), f.begin(), f.end());
  }
  return failed;
}

z3::check_result InductionRound::StepQuery(int m, const std::vector<std::size_t>& goals,
                                           unsigned limit, std::vector<std::size_t>& failed,
                                           bool apart, std::optional<Move> move) {
  const int k = k_;
  // A path of k steps (k + 1 states) asserted in a new solver.
  if (!meter_.Afford(PathUnits(enc_.automaton(), k, m, move.has_value()), ceiling_)) {
    return z3::unknown;
  }
  z3::expr_vector query(ctx_);
  query.push_back(StepPath(m, move));
  query.push_back(Hypotheses(m));
  z3::expr_vector bad(ctx_);
  std::vector<z3::expr> at_k;
  const std::vector<bool> next = m < 0 ? std::vector<bool>() : StepModes(m, move).second;
  for (std::size_t j : goals) {
    at_k.push_back(m < 0 ? enc_.Holds(set_[j]->bad, k, 0.0) : enc_.HoldsIn(set_[j]->bad, k, next));
    bad.push_back(at_k.back());
  }
  query.push_back(z3::mk_or(bad));
  query.push_back(enc_.TakeDefinitions());
  const std::string what = QueryName(m, goals.size(), apart, move);
  std::vector<bool> broken;
  z3::check_result r;
  if (apart) {
    r = meter_.CheckApart(query, limit, ceiling_, what, at_k, broken, m);
  } else {
    z3::solver s = m < 0 ? MakeIncremental(ctx_) : MakeSolver(ctx_);
    for (const z3::expr& e : query) s.add(e);
    r = meter_.Check(s, limit, ceiling_, what);
    if (r == z3::sat) {
      const z3::model model = s.get_model();
      for (const z3::expr& e : at_k) broken.push_back(model.eval(e, true).is_true());
    }
  }
  if (r == z3::sat) {
    for (std::size_t g = 0; g < goals.size(); ++g) {
      if (broken[g]) failed.push_back(goals[g]);
    }
    if (failed.empty()) failed = goals;  // cannot tell which: drop all (sound)
    if (LogEnabled(LogLevel::kDebug)) LogFailedStep(m, failed);
  }
  return r;
}

std::string InductionRound::QueryName(int m, std::size_t goals, bool apart,
                                      std::optional<Move> move) const {
  if (m < 0) return "induction";
  const Automaton& a = enc_.automaton();
  std::string what = "induction from " + a.modes()[m].name;
  if (move) {
    what += move->transition ? ", by " + a.transition(*move->transition).name : ", by its flow";
  }
  return what + (goals == 1 ? ", one candidate" : "") + (apart ? ", apart" : "");
}

void InductionRound::LogFailedStep(int m, const std::vector<std::size_t>& failed) const {
  std::string names;
  for (std::size_t j : failed) names += (names.empty() ? "" : ", ") + set_[j]->goal->property.name;
  Log(LogLevel::kDebug, "prove",
      std::to_string(k_) + "-induction step from " +
          (m < 0 ? std::string("any mode") : "mode " + enc_.automaton().modes()[m].name) +
          " fails for " + names);
}

const z3::expr& InductionRound::StepPath(int m, std::optional<Move> move) {
  // Keyed by the last mode (any: -1) and the move (every move: -2, the flow: -1, a transition).
  const int which = !move ? -2 : move->transition ? move->transition->value() : -1;
  auto it = paths_.find({m, which});
  if (it == paths_.end()) it = paths_.emplace(std::pair(m, which), BuildPath(m, move)).first;
  return it->second;
}

z3::expr InductionRound::BuildPath(int m, std::optional<Move> move) {
  const int k = k_;
  z3::expr_vector e(ctx_);
  for (int i = 0; i + 1 < k || (m < 0 && i <= k); ++i) e.push_back(enc_.State(i));
  if (m >= 0) {
    // s_k-1 in m alone, s_k in the modes the step can reach: only those modes' constraints (a
    // large automaton's others would cost Z3 their simplification per mode).
    const auto [from, next] = StepModes(m, move);
    e.push_back(enc_.StateIn(k - 1, from));
    e.push_back(enc_.StateIn(k, next));
  }
  for (int i = 0; i + 1 < k; ++i) e.push_back(enc_.Transition(i));
  if (m < 0) {
    e.push_back(enc_.Transition(k - 1));
  } else {
    e.push_back(move ? enc_.MoveFrom(k - 1, ModeId(m), move->transition)
                     : enc_.TransitionFrom(k - 1, ModeId(m)));
  }
  e.push_back(enc_.TakeDefinitions());
  return z3::mk_and(e);
}

void InductionRound::ForgetHypotheses() {
  hypotheses_.reset();
  hypotheses_from_.assign(hypotheses_from_.size(), std::nullopt);
}

const z3::expr& InductionRound::Hypotheses(int m) {
  std::optional<z3::expr>& hypotheses = m < 0 ? hypotheses_ : hypotheses_from_[m];
  if (!hypotheses) {
    const std::vector<bool> from = m < 0 ? std::vector<bool>() : StepModes(m).first;
    // At s_k-1 the step from m is in m: the candidates read there as in m alone.
    const auto holds = [&](const Predicate& bad, int i) {
      return m >= 0 && i == k_ - 1 ? enc_.HoldsIn(bad, i, from) : enc_.Holds(bad, i, 0.0);
    };
    z3::expr_vector e(ctx_);
    for (std::size_t j = 0; j < set_.size(); ++j) {
      if (!alive_[j]) continue;
      for (int i = 0; i < k_; ++i) e.push_back(!holds(set_[j]->bad, i));
    }
    for (const ProofCandidate* lemma : lemmas_) {
      for (int i = 0; i < k_; ++i) e.push_back(!holds(lemma->bad, i));
    }
    e.push_back(enc_.TakeDefinitions());
    hypotheses = z3::mk_and(e);
  }
  return *hypotheses;
}

std::pair<std::vector<bool>, std::vector<bool>> InductionRound::StepModes(
    int m, std::optional<Move> move) const {
  const Automaton& a = enc_.automaton();
  std::vector<bool> from(static_cast<std::size_t>(a.num_modes()), false);
  from[static_cast<std::size_t>(m)] = true;
  std::vector<bool> next = from;
  if (move && move->transition) {
    next.assign(next.size(), false);
    next[static_cast<std::size_t>(a.transition(*move->transition).target.value())] = true;
  } else if (!move) {
    for (const Transition& t : a.transitions()) {
      if (t.source.value() == m) next[static_cast<std::size_t>(t.target.value())] = true;
    }
  }
  return {std::move(from), std::move(next)};
}

std::vector<InductionRound::Move> InductionRound::MovesFrom(int m) const {
  const Automaton& a = enc_.automaton();
  std::vector<Move> moves{Move{}};
  for (int t = 0; t < a.num_transitions(); ++t) {
    if (a.transitions()[t].source.value() == m) moves.push_back(Move{TransitionId(t)});
  }
  return moves;
}

}  // namespace hybrid
