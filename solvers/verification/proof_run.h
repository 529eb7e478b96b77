#pragma once

// Internal to hybrid::verification: includes Z3's C++ API, which no public header exposes.

#include <z3++.h>

#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "hybrid/verification/property_prover.h"
#include "solvers/verification/proof_candidate.h"
#include "solvers/verification/proof_job.h"
#include "solvers/verification/query_meter.h"
#include "solvers/verification/smt_encoding.h"
#include "solvers/verification/trace_builder.h"

namespace hybrid {

/// The check of one job (one automaton and its goals) within `share` resource units of the
/// budget, in a Z3 context of its own: the phases of PropertyProver's class comment, in order.
/// 1. Base case: bounded model checking of the invariants on paths of fewer than max_induction
///    steps (nominal parameters first, then free), up to half the share.
/// 2. k-induction (InductionRound), k = 1 .. max_induction, on the invariants neither refuted
///    nor decided, while the base case was complete: the inductive ones are `proved`.
/// 3. The search for counterexamples and witnesses up to max_depth steps (short paths, then
///    longer ones with nominal parameters, then with free ones), up to 90% of the share; a path
///    found is turned into a Trace (TraceBuilder) and replayed by the simulator: `violated`
///    (`reachable`) if it replays.
/// 4. For `reach` targets without a witness: `unreachable` if no initial state is a target and
///    the targets' negations are 1-inductive together, relative to the proved invariants
///    (InductionRound: the largest such set; the rest of the share).
/// 5. Every goal still open is `unknown`, its reason saying which phase ran out of what.
/// Each decided goal's results (ProofGoal::result and ProofGoal::also) are written with
/// CheckResult::seconds measured from `start`; lemmas (result -1) are decided without a result.
class ProofRun {
 public:
  /// The run of `job` (its automaton set), whose goals name results in `results`. `system`,
  /// `options`, `budget`, `results` and `job` are borrowed and must outlive the run; `dump`
  /// as QueryDump.
  ProofRun(const System& system, const PropertyProver::Options& options, SolverBudget& budget,
           std::chrono::steady_clock::time_point start, std::vector<CheckResult>& results,
           const ProofJob& job, std::uint64_t share, QueryDump dump = {});

  ProofRun(const ProofRun&) = delete;
  ProofRun& operator=(const ProofRun&) = delete;

  /// Decides every goal of the job (phases 1 to 5). Call once.
  void Run();

 private:
  // The budget level up to which a phase may draw: a fraction of this job's share.
  std::uint64_t Ceiling(double fraction) const {
    return first_ + static_cast<std::uint64_t>(static_cast<double>(share_) * fraction);
  }
  // Whether some goal with a result is undecided.
  bool Open() const;
  void Decide(ProofCandidate& c, Verdict v, std::string reason, std::optional<Trace> trace = {});

  // Phase 1.
  void BaseCase();
  // Phase 2: InductionRound for each k while some goal is open.
  void Induction();
  // The candidates `inductive` (of a round of k-induction) are proved.
  void DecideInductive(int k, const std::vector<ProofCandidate*>& inductive);
  // Phase 3, and the refuted lemmas and goals without a replayed path.
  void DeepSearch();
  void NoteRefuted();
  // Phase 4.
  void UnreachableTargets();
  bool InitiallyOutside(const ProofCandidate& c);
  // Phase 5.
  void Conclude();

  // Adds the paths of up to n steps to bmc_, each step paid for (StepUnits) before it is built;
  // false when the ceiling does not allow it.
  bool Extend(int n, std::uint64_t ceiling);
  // s_n is a counterexample (by at least `margin`) or a witness of `c`.
  z3::expr Bad(const ProofCandidate& c, int n, double margin);
  // Paths of exactly n steps for the pending candidates (only the invariants if
  // `invariants_only`), per pass of `passes` (true: parameters pinned to their nominal values).
  void Search(int n, bool invariants_only, std::initializer_list<bool> passes,
              std::uint64_t ceiling);
  // Candidate `c` alone on paths of exactly n steps.
  void One(ProofCandidate& c, int n, bool pinned, std::uint64_t ceiling);
  // Turns the path of `depth` steps in `model` into a Trace (TraceBuilder) and replays it for
  // `c` (ReplayPath); false if there is no trace or it does not replay.
  bool TryTrace(const z3::model& model, int depth, ProofCandidate& c);
  // Replays `trace` (of `path`) for `c`: if it replays, decides `c` violated (reachable for
  // `reach`) with it; false otherwise (and logs the path at kDebug).
  bool ReplayPath(const std::vector<SmtEncoding::PathStep>& path, ProofCandidate& c, Trace trace);
  // `trace`, which does not replay for `c`, with its uncertain parameters moved a little at
  // random (kOffTieTries tries): the first that replays, if any.
  std::optional<Trace> OffTie(const ProofCandidate& c, const Trace& trace);
  static constexpr int kOffTieTries = 16;

  const System& system_;
  const PropertyProver::Options& options_;
  SolverBudget& budget_;
  std::chrono::steady_clock::time_point start_;
  std::vector<CheckResult>& results_;
  const ProofJob& job_;
  const Automaton& a_;
  z3::context ctx_;
  SmtEncoding enc_;
  QueryMeter meter_;
  z3::solver bmc_;  // the incremental solver of bounded model checking
  TraceBuilder traces_;
  std::vector<ProofCandidate> cands_;
  std::uint64_t first_;  // budget_.used() when this job started
  std::uint64_t share_;
  bool bmc_complete_ = true;
  bool base_complete_ = false;
  bool deep_ = false;   // in the counterexample search (lemmas need none of their own)
  int bmc_depth_ = -1;  // paths up to this length are in bmc_
  int searched_ = -1;   // the deep search covered paths up to this length
  // Where the budget ran out: it left the base case or the induction short, cut the search
  // for counterexamples and witnesses, or the unreachability proofs.
  bool proof_cut_ = false;
  bool search_cut_ = false;
  bool unreach_cut_ = false;
};

}  // namespace hybrid
