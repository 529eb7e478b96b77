#pragma once

// Internal to hybrid::verification: includes Z3's C++ API, which no public header exposes.

#include <z3++.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/verification/solver_budget.h"
#include "solvers/verification/cpu_watchdog.h"
#include "solvers/verification/smt_encoding.h"

namespace hybrid {

/// The resource units charged per mode and per transition for each step of the encoding asserted
/// in a solver: the work of building and asserting it, which Z3's count leaves out (about what
/// Z3 counts for the same time, measured on chains of 300 to 10^4 modes).
inline constexpr std::uint64_t kUnitsPerEncodedElement = 400;

/// The charge for one step of the encoding of `automaton` (a State and a Transition) asserted in
/// a solver: kUnitsPerEncodedElement * (modes + transitions + 1).
std::uint64_t StepUnits(const Automaton& automaton);

/// The charge for what a path of k steps whose last step leaves mode m (any mode: m < 0) puts in
/// a new solver: k + 1 states (each linear in the modes), k - 1 full steps and the last step
/// (from m: its flow and its outgoing transitions only; with `one_move`, one of them).
std::uint64_t PathUnits(const Automaton& automaton, int k, int m, bool one_move = false);

/// The solver for the induction and unreachability queries: the formula simplified (Z3's
/// simplify, propagate-values, solve-eqs), then Z3's simplex (qflra) if it is linear, else nlsat
/// (qfnra-nlsat: complete for polynomial real arithmetic, with Boolean structure), which handles
/// the separable (nonlinear) flows far better than the default core. Its limits are set per query
/// (QueryMeter).
z3::solver MakeSolver(z3::context& ctx);

/// Z3's default solver, for bounded model checking (incremental) and the one-query induction
/// step: always its SMT core (`ignore_solver1`, and `solver2_unknown` = 0: an `unknown` stays
/// unknown), never the tactic portfolio it otherwise tries first or falls back to, whose
/// strategies for nonlinear arithmetic switch on wall-clock time (`try_for`), so that the same
/// query gave different answers and resource counts from run to run; and without the core's calls
/// to nlsat (`arith.nl.nra`), whose algebraic number work Z3 neither counts in the resource limit
/// nor interrupts on time (a query of the finger's search ran for minutes on 600,000 units).
/// Incomplete for nonlinear problems: such a query may come back `unknown`.
z3::solver MakeIncremental(z3::context& ctx);

/// Asserts `e` in `s` and the definitions of the auxiliary variables it introduced
/// (SmtEncoding::TakeDefinitions).
void AddWithDefinitions(z3::solver& s, SmtEncoding& enc, const z3::expr& e);

/// Z3's count of resource units spent so far in the context of `s` (cumulative over all its
/// solvers), from the solver's statistics; 0 if they do not say.
std::uint64_t ResourceCount(const z3::solver& s);

/// Where a QueryMeter writes its queries before they run: into `directory` (empty: nowhere) as
/// q<N>.smt2, N counted in `*count` (borrowed: it must outlive the meters that use it; shared by
/// the meters of one Check, so that the files of a Check are numbered in the order its queries
/// run).
struct QueryDump {
  std::string directory;
  int* count = nullptr;
};

/// Runs the SMT queries of one Z3 context against a SolverBudget, so that what a query may use,
/// what it is charged and what follows depend on the formulas only:
/// - a query runs only while the budget is below its `ceiling` (a level of budget.used() that a
///   phase of the proof may draw up to) and the budget's safety deadline has not passed; it gets
///   at most `cap` resource units, or what is left below the ceiling rounded down to a power of
///   two (Z3's `rlimit`);
/// - it is charged what Z3's count says it used;
/// - the CPU-time safety net (CpuWatchdog, SolverBudget::SafetyCpuSeconds) interrupts a query
///   whose work Z3's count misses: that query is `unknown`, is charged its whole allowance, and
///   its solver gets no further query (each later one is `unknown` without running).
/// Work Z3 does not count (building and asserting the encoding) is paid with Afford.
///
/// Logs (topic "prove"): at kInfo one line per query run (its purpose, result, units and
/// seconds, and whether the safety net stopped it), at kDebug the start of each query and each
/// query the budget refused. With a dump directory, each query is written there first as
/// SMT-LIB 2 (PropertyProver::Options::query_dump_directory), a file that cannot be written
/// logged at kWarning.
class QueryMeter {
 public:
  /// A meter for the queries of context `ctx`, drawing from `budget`; both are borrowed and must
  /// outlive the meter (the context also the meter's watchdog thread, which the destructor
  /// joins).
  QueryMeter(z3::context& ctx, SolverBudget& budget, QueryDump dump = {});

  QueryMeter(const QueryMeter&) = delete;
  QueryMeter& operator=(const QueryMeter&) = delete;

  /// s.check() (for `what`, which names the query in the log) with at most `cap` resource units
  /// (cap > 0) and never past `ceiling` (a level of budget.used()): z3::unknown without a query
  /// once the ceiling is reached or the safety deadline passed (counted in starved(), as a query
  /// that the budget, not `cap`, cut short), or when the safety net stopped an earlier query of
  /// `s`. A query that comes back unknown with less than `cap` units counts in starved() too.
  z3::check_result Check(z3::solver& s, unsigned cap, std::uint64_t ceiling,
                         const std::string& what);

  /// Check for a query asked apart from the meter's context: the formulas `query` (of the meter's
  /// context) are copied into a context of the queries of `group` and solved there by
  /// MakeSolver's solver. A new context is made whenever `group` differs from the previous
  /// call's (and after the safety net stopped a query), so that what the solver does depends on
  /// the queries of the group alone, in their order, not on what other queries left in a
  /// context: Z3 orders terms by their creation in a context, and nlsat's effort on a nonlinear
  /// query swings with that order by orders of magnitude (the finger's `phase3_law` step from
  /// link 2's phase 3: decided in 0.03 to 0.07 s alone, not in 5 million units after the other
  /// queries of the check). Limits, charges, the safety net and the
  /// log as Check (the charge is what the group's context counted for the query). On sat,
  /// `holds` gets, for each of `watch` (Boolean formulas of the meter's context), whether the
  /// model makes it true; it is left empty otherwise.
  z3::check_result CheckApart(const z3::expr_vector& query, unsigned cap, std::uint64_t ceiling,
                              const std::string& what, const std::vector<z3::expr>& watch,
                              std::vector<bool>& holds, long group);

  /// How many queries the budget refused or cut short so far.
  int starved() const { return starved_; }

  /// Pays `units` for work Z3 does not count (building and asserting the encoding) if the
  /// ceiling allows it (budget.used() + units <= ceiling, safety deadline not passed); otherwise
  /// counts in starved() and returns false.
  bool Afford(std::uint64_t units, std::uint64_t ceiling);

  /// The budget the meter draws from.
  const SolverBudget& budget() const { return budget_; }

 private:
  // Whether the safety net stopped a query of `s` before.
  bool Stopped(const z3::solver& s) const;
  // The resource limit of the next query: `cap`, or what is left below `ceiling` rounded down to
  // a power of two.
  std::uint64_t Allowed(unsigned cap, std::uint64_t ceiling) const;
  // Allowed(cap, ceiling), set in `s` when it changed.
  std::uint64_t Allow(z3::solver& s, unsigned cap, std::uint64_t ceiling);
  // The query of CheckApart in apart_ (the solver, its model and the copied formulas gone on
  // return, so that apart_ may then be dropped): its result, whether the safety net `stopped`
  // it, apart_'s resource `count` after it, and on sat the values of `watch` in `holds`.
  z3::check_result SolveApart(const z3::expr_vector& query, std::uint64_t allowed,
                              const std::vector<z3::expr>& watch, std::vector<bool>& holds,
                              bool& stopped, std::uint64_t& count);
  // Whether a query may run (below the ceiling, safety deadline not passed); if not, counts it
  // in starved() and logs it.
  bool MayRun(std::uint64_t ceiling, const std::string& what);
  // Charges a query that used `spent` units of `allowed` (all of them if the safety net
  // `stopped` it) and logs it.
  void Settle(z3::check_result r, std::uint64_t spent, std::uint64_t allowed, unsigned cap,
              bool stopped, double seconds, const std::string& what);
  // Writes the query of `s` into the dump directory, if any.
  void DumpQuery(z3::solver& s, std::uint64_t allowed);

  SolverBudget& budget_;
  QueryDump dump_;
  std::uint64_t seen_ = 0;  // the context's count after the last query
  int starved_ = 0;
  std::optional<z3::solver> last_solver_;  // the solver of the last query, and its rlimit
  std::uint64_t last_allowed_ = 0;
  // Solvers whose query the safety net stopped: their state depends on where it stopped, so
  // they get no further query (held, so that no other solver can take their address).
  std::vector<z3::solver> stopped_solvers_;
  z3::context& ctx_;
  // The context the safety net interrupts: ctx_, or a query's own while CheckApart runs it
  // (changed only while the watchdog is not armed).
  std::atomic<z3::context*> running_;
  // The context of CheckApart's queries of group apart_group_ (null: none yet), and its count
  // after the last of them.
  std::unique_ptr<z3::context> apart_;
  long apart_group_ = 0;
  std::uint64_t apart_seen_ = 0;
  CpuWatchdog watchdog_;  // the safety net; interrupts running_
};

}  // namespace hybrid
