#pragma once

// Internal to hybrid::verification: includes Z3's C++ API, which no public header exposes.

#include <z3++.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "solvers/verification/proof_candidate.h"
#include "solvers/verification/query_meter.h"
#include "solvers/verification/smt_encoding.h"

namespace hybrid {

/// One round of k-induction with Houdini over candidate invariants: finds the largest subset of
/// the candidates that is inductive together, i.e. no path of k steps of the encoding on which
/// all of them hold at s_0 .. s_k-1 breaks one of them at s_k (the step query). Together with a
/// base case (no violation on paths of fewer than k steps from an initial state, which the
/// caller checks), the survivors are invariants of every run.
///
/// The step query is asked first from any mode in one query (Z3's default solver; cheap where
/// the flows are simple, however many modes; not asked when a flow is separable, whose
/// polynomial closed form that solver does not decide) while it decides, then split on the mode
/// of s_k-1 (nlsat: one small nonlinear problem per mode is far easier than their disjunction),
/// each built from the modes of the step only (SmtEncoding::StateIn). Per query, all living
/// candidates at once (at most resource_limit / 100): a model names those it breaks, which are
/// dropped (all of them when it cannot tell), and the rest are checked again; a per-mode query
/// that runs out is split per candidate: first in a context of the mode's own
/// (QueryMeter::CheckApart, resource_limit / 25), where nlsat's effort does not depend on the
/// other modes' queries, then in the round's context with resource_limit / 5 and
/// resource_limit; a candidate that runs out alone is dropped. From a mode with a separable
/// flow (a polynomial closed form), all this is done one move at a time: the flow, then each
/// transition from the mode (nlsat decides the law without the jumps' case split far sooner).
/// Dropping is always sound: what survives is inductive whatever was dropped. Once the budget
/// reaches `ceiling`, every living candidate is dropped (cut()).
///
/// Formulas are built once per round (the path per last mode and move, the hypotheses after each
/// drop).
/// Logs (topic "prove") at kDebug each failed step: k, the mode, the candidates it breaks (not
/// the path: reading it from the model would use the context, and so change what later queries
/// are charged).
class InductionRound {
 public:
  /// A round of `k`-induction (k >= 1) over `candidates` (invariants; borrowed, as are
  /// `encoding` and `meter`, which must be of one context: all must outlive the round), its
  /// queries drawing from `meter` up to `ceiling`, each at most `resource_limit` units.
  /// `lemmas` (invariants already proved) are assumed at s_0 .. s_k-1 beside the candidates: the
  /// survivors are then inductive relative to them.
  InductionRound(SmtEncoding& encoding, QueryMeter& meter, unsigned resource_limit, int k,
                 std::vector<ProofCandidate*> candidates, std::uint64_t ceiling,
                 std::vector<const ProofCandidate*> lemmas = {});

  InductionRound(const InductionRound&) = delete;
  InductionRound& operator=(const InductionRound&) = delete;

  /// Drops candidates until those left are inductive together (or none is left).
  void Run();

  /// The candidates still alive, in the order given: after Run(), inductive together.
  std::vector<ProofCandidate*> Inductive() const;

  /// Whether the budget dropped candidates (the ceiling was reached or the safety deadline
  /// passed before a per-mode step), rather than the step queries.
  bool cut() const { return cut_; }

 private:
  // The indices of the candidates still alive.
  std::vector<std::size_t> Living() const;
  // Drops the candidates `failed`; whether any was alive (then the hypotheses are rebuilt).
  bool Drop(const std::vector<std::size_t>& failed);
  // The step from each mode in turn for the living candidates (split per candidate where a
  // query runs out); drops those that fail and returns whether any was dropped.
  bool StepPerMode();
  // One move of the step from a mode: its flow (no transition) or the jump by `transition`.
  struct Move {
    std::optional<TransitionId> transition;
  };
  // The candidates among `goals` whose step from mode m (by `move` only, when given) fails
  // (a query of them all, split per candidate when it runs out).
  std::vector<std::size_t> FailedFrom(int m, const std::vector<std::size_t>& goals,
                                      std::optional<Move> move);
  // The step query from mode m (by `move` only, when given), or from any mode (m = -1, with
  // Z3's default solver): a path of k steps on which the living candidates hold before s_k and
  // one of `goals` fails at s_k. On sat, `failed` gets the goals the model breaks (all of them
  // when it cannot tell).
  z3::check_result StepQuery(int m, const std::vector<std::size_t>& goals, unsigned limit,
                             std::vector<std::size_t>& failed, bool apart = false,
                             std::optional<Move> move = std::nullopt);
  // Logs (kDebug) that the step from mode m (any: m < 0) fails for the candidates `failed`.
  void LogFailedStep(int m, const std::vector<std::size_t>& failed) const;
  // The path of the step query from mode m (any: m < 0; by `move` only, when given), built on
  // first use.
  const z3::expr& StepPath(int m, std::optional<Move> move = std::nullopt);
  // The path of StepPath, built.
  z3::expr BuildPath(int m, std::optional<Move> move);
  // The name of a step query in the log: its mode, move, number of goals and context.
  std::string QueryName(int m, std::size_t goals, bool apart, std::optional<Move> move) const;
  // The moves from mode m: its flow, then its transitions.
  std::vector<Move> MovesFrom(int m) const;
  // The living candidates and the lemmas hold at s_0 .. s_k-1 (for the step from mode m, read
  // at s_k-1 in m alone; any mode: m < 0): built on first use after each drop.
  const z3::expr& Hypotheses(int m);
  // Forgets the hypotheses built (after a drop).
  void ForgetHypotheses();
  // The modes of the step from m: s_k-1's (m alone) and s_k's (m and the targets of its
  // transitions; by `move` only: m for the flow, the transition's target), a flag per mode.
  std::pair<std::vector<bool>, std::vector<bool>> StepModes(
      int m, std::optional<Move> move = std::nullopt) const;

  SmtEncoding& enc_;
  QueryMeter& meter_;
  z3::context& ctx_;
  unsigned resource_limit_;
  int k_;
  std::uint64_t ceiling_;
  std::vector<ProofCandidate*> set_;
  std::vector<const ProofCandidate*> lemmas_;
  std::vector<bool> alive_;
  std::map<std::pair<int, int>, z3::expr> paths_;  // of k steps, per last mode and move (StepPath)
  std::optional<z3::expr> hypotheses_;             // of the alive candidates
  std::vector<std::optional<z3::expr>> hypotheses_from_;  // the same, per mode of s_k-1
  bool cut_ = false;
};

}  // namespace hybrid
