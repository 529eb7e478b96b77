#include "solvers/verification/property_prover.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "solvers/verification/cpu_watchdog.h"
#include "solvers/verification/smt_encoding.h"

namespace hybrid {

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

Predicate Remap(const Predicate& p, const std::function<Expression(const Expression&)>& expr,
                const std::function<std::string(const std::string&)>& mode) {
  switch (p.kind()) {
    case Predicate::Kind::kTrue:
    case Predicate::Kind::kFalse:
      return p;
    case Predicate::Kind::kComparison: {
      const Comparison& c = p.comparison();
      return Predicate::Compare({expr(c.lhs), c.relation, expr(c.rhs)});
    }
    case Predicate::Kind::kInMode:
      return Predicate::InMode(mode(p.mode()));
    case Predicate::Kind::kNot:
      return Predicate::Not(Remap(p.operands()[0], expr, mode));
    case Predicate::Kind::kAnd:
      return Predicate::And(Remap(p.operands()[0], expr, mode), Remap(p.operands()[1], expr, mode));
    case Predicate::Kind::kOr:
      return Predicate::Or(Remap(p.operands()[0], expr, mode), Remap(p.operands()[1], expr, mode));
  }
  return p;
}

// A property to decide on one automaton (its own slots and mode names).
struct Goal {
  Property property;      // local
  int result = -1;        // index into the results, -1 for a lemma only
  Property original;      // as asked (System names), for the replay
  std::vector<int> also;  // further results asking the same question
};

struct Job {
  const Automaton* automaton = nullptr;
  // Its component's index in the System, or -1 for a product of components.
  int component = -1;
  // For a product: its components (System indices, in product order). The product's initial
  // states are the cartesian product of theirs, the first component varying slowest
  // (System::Product).
  std::vector<int> product_components;
  // automaton slot -> System slot
  std::vector<int> to_system;
  std::vector<Goal> goals;
};

// Prints a path of a model (HYBRID_CHECK_DEBUG).
void DebugPath(SmtEncoding& enc, const z3::model& model, int n) {
  const auto path = enc.ReadPath(model, n);
  for (const auto& [name, v] : enc.ReadParameters(model)) std::cerr << "  " << name << " = " << v;
  std::cerr << "\n";
  for (int k = 0; k <= n; ++k) {
    const auto& s = path[k];
    std::cerr << "  s" << k << " " << enc.automaton().modes()[s.mode].name;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      std::cerr << " " << enc.automaton().symbols()[enc.automaton().variables()[i].slot].name << "="
                << s.x[i];
    }
    for (double u : s.input) std::cerr << " u=" << u;
    if (k < n) {
      if (s.flow)
        std::cerr << "  --flow d=" << s.duration;
      else
        std::cerr << "  --jump " << enc.automaton().transitions()[s.transition].name;
    }
    std::cerr << "\n";
  }
}

// The solver for the induction and unreachability queries: Z3's nlsat (complete for polynomial
// real arithmetic, with Boolean structure), which handles the separable (nonlinear) flows far
// better than the default core. Its limits are set per query (Meter).
z3::solver MakeSolver(z3::context& ctx) { return z3::tactic(ctx, "qfnra-nlsat").mk_solver(); }

// Z3's default solver, for bounded model checking (incremental) and the one-query induction
// step: always its SMT core (`ignore_solver1`, and `solver2_unknown` = 0: an `unknown` stays
// unknown), never the tactic portfolio it otherwise tries first or falls back to, whose
// strategies for nonlinear arithmetic switch on wall-clock time (`try_for`), so that the same
// query gave different answers and resource counts from run to run; and without the core's calls
// to nlsat (`arith.nl.nra`), whose algebraic number work Z3 neither counts in the resource limit
// nor interrupts on time (a query of the finger's search ran for minutes on 600,000 units).
// Incomplete for nonlinear problems: such a query may come back `unknown`.
z3::solver MakeIncremental(z3::context& ctx) {
  z3::solver s(ctx);
  z3::params p(ctx);
  p.set("ignore_solver1", true);
  p.set("solver2_unknown", 0u);
  p.set("arith.nl.nra", false);
  s.set(p);
  return s;
}

// Asserts `e` and the definitions of the auxiliary variables it introduced.
void Add(z3::solver& s, SmtEncoding& enc, const z3::expr& e) {
  s.add(e);
  s.add(enc.TakeDefinitions());
}

// The resource units charged per mode and per transition for each step of the encoding asserted
// in a solver: the work of building and asserting it, which Z3's count leaves out (about what
// Z3 counts for the same time, measured on chains of 300 to 10^4 modes).
constexpr std::uint64_t kUnitsPerEncodedElement = 400;

// Z3's count of resource units spent so far in the context of `s` (cumulative over all its
// solvers), from the solver's statistics.
std::uint64_t ResourceCount(const z3::solver& s) {
  const z3::stats st = s.statistics();
  for (unsigned i = 0; i < st.size(); ++i) {
    const std::string key = st.key(i);
    if (key == "rlimit count" || key == "rlimit-count") {
      return st.is_uint(i) ? st.uint_value(i) : static_cast<std::uint64_t>(st.double_value(i));
    }
  }
  return 0;
}

// Runs the solver queries of one Z3 context against a SolverBudget.
class Meter {
 public:
  Meter(z3::context& ctx, SolverBudget& budget)
      : budget_(budget), watchdog_([&ctx] { ctx.interrupt(); }) {}

  // s.check() (for `what`, in HYBRID_CHECK_TIMING's report) with at most `cap` resource units
  // and never past `ceiling` (a level of
  // budget.used()): z3::unknown without a query once the ceiling is reached (counted in
  // starved(), as a query that the budget, not `cap`, cut short).
  z3::check_result Check(z3::solver& s, unsigned cap, std::uint64_t ceiling, const char* what) {
    if (budget_.used() >= ceiling || budget_.SafetyExpired()) {
      ++starved_;
      return z3::unknown;
    }
    for (const z3::solver& stopped : stopped_solvers_) {
      if (static_cast<Z3_solver>(stopped) == static_cast<Z3_solver>(s)) return z3::unknown;
    }
    if (std::getenv("HYBRID_CHECK_TIMING")) std::cerr << "query start (" << what << ")\n";
    // What is left, rounded down to a power of two when less than `cap`: setting a solver's
    // parameters costs time on a large incremental solver, so they change only when the
    // rounded value does.
    const std::uint64_t left = ceiling - budget_.used();
    std::uint64_t allowed = cap;
    if (left < cap) {
      allowed = 1;
      while (allowed * 2 <= left) allowed *= 2;
    }
    // The CPU-time limit of the query, from the units it may use (10 s per budget second, at
    // least 10 s): work Z3's count misses (a search query of the finger's --modes spent 100 s on
    // 1.8 million units) is cut there.
    const bool same =
        last_solver_ && static_cast<Z3_solver>(*last_solver_) == static_cast<Z3_solver>(s);
    if (!same || last_allowed_ != allowed) {
      z3::params p(s.ctx());
      p.set("rlimit", static_cast<unsigned>(allowed));
      s.set(p);
      last_solver_ = s;  // held, so that no other solver can take its address
      last_allowed_ = allowed;
    }
    if (const char* dir = std::getenv("HYBRID_CHECK_DUMP")) {
      std::ofstream(std::string(dir) + "/q" + std::to_string(dumped_++) + ".smt2")
          << "; rlimit " << allowed << "\n"
          << s.to_smt2();
    }
    const Clock::time_point t0 = Clock::now();
    watchdog_.Arm(budget_.SafetyCpuSeconds(allowed));
    z3::check_result r = s.check();
    const bool stopped = watchdog_.Disarm();
    const double seconds = Since(t0);
    const std::uint64_t count = ResourceCount(s);
    const std::uint64_t spent = count > seen_ ? count - seen_ : 0;
    seen_ = std::max(seen_, count);
    if (stopped) {
      // Where the net stopped the query depends on the machine's speed; what it charges and
      // what follows on this solver must not: the whole allowance, and no further query.
      r = z3::unknown;
      budget_.Charge(std::max<std::uint64_t>(spent, allowed));
      budget_.NoteSafetyStop();
      stopped_solvers_.push_back(s);
    } else {
      budget_.Charge(spent);
    }
    if (r == z3::unknown && allowed < cap) ++starved_;
    if (std::getenv("HYBRID_CHECK_TIMING")) {
      std::cerr << "query: " << r << ", " << spent << " units, " << seconds << " s (" << what
                << ")\n";
    }
    return r;
  }
  // How many queries the budget refused or cut short so far.
  int starved() const { return starved_; }

  // Pays `units` for work Z3 does not count (building and asserting the encoding) if the
  // ceiling allows it; otherwise sets starved() and returns false.
  bool Afford(std::uint64_t units, std::uint64_t ceiling) {
    if (budget_.used() + units > ceiling || budget_.SafetyExpired()) {
      ++starved_;
      return false;
    }
    budget_.Charge(units);
    return true;
  }

 private:
  SolverBudget& budget_;
  std::uint64_t seen_ = 0;  // the context's count after the last query
  int starved_ = 0;
  int dumped_ = 0;
  std::optional<z3::solver> last_solver_;  // the solver of the last query, and its rlimit
  std::uint64_t last_allowed_ = 0;
  // Solvers whose query the safety net stopped: their state depends on where it stopped, so
  // they get no further query (held, so that no other solver can take their address).
  std::vector<z3::solver> stopped_solvers_;
  CpuWatchdog watchdog_;  // the safety net; interrupts the context
};

// The check of one automaton (one Job) within `share` resource units of the budget: its Z3
// context, encoding and candidates, and the phases of PropertyProver's comment.
class JobRun {
 public:
  JobRun(const System& system, const PropertyProver::Options& options, SolverBudget& budget,
         Clock::time_point start, std::vector<CheckResult>& results, const Job& job,
         std::uint64_t share)
      : system_(system),
        options_(options),
        budget_(budget),
        start_(start),
        results_(results),
        job_(job),
        a_(*job.automaton),
        enc_(ctx_, a_),
        meter_(ctx_, budget),
        bmc_(MakeIncremental(ctx_)),
        first_(budget.used()),
        share_(share) {}

  void Go();

 private:
  struct Candidate {
    const Goal* goal;
    Predicate bad;         // a state that is a counterexample / witness
    bool invariant;        // always/never (else reach)
    bool decided = false;  // a verdict is in results_ (or a lemma was refuted)
    bool refuted = false;  // the encoding reaches `bad`: not a lemma
    bool proved = false;   // an invariant of every run (usable as a lemma)
    int replays = 0;
  };

  // The budget level up to which a phase may draw: a fraction of this job's share.
  std::uint64_t Ceiling(double fraction) const {
    return first_ + static_cast<std::uint64_t>(static_cast<double>(share_) * fraction);
  }
  bool Open() const;
  // Bounded properties are checked like unbounded ones (sound for `proved`); their traces are
  // replayed with the horizon.
  static bool Pending(const Candidate& c) { return !c.decided && c.replays < 8; }
  void Decide(Candidate& c, Verdict v, std::string reason, std::optional<Trace> trace = {});
  // Turns the path of `depth` steps in `model` into a Trace (parameters, initial state and
  // values, input schedule) and replays it for `c` (ReplayPath); false if it does not replay.
  bool TryTrace(const z3::model& model, int depth, Candidate& c);
  // Adds to `trace` the values s0 gives the variables that initial state `start` sets in a box.
  // Which `init` declaration each component of the job starts from (trace.initial_states).
  void AddInitialStates(int start, Trace& trace) const;
  void AddInitialValues(int start, const SmtEncoding::PathStep& s0, Trace& trace) const;
  // Adds to `trace` the input schedule of `path`: one step piece per flow segment of positive
  // duration, the values a jump's guard reads from the jump's instant, then a short tail with
  // the last input held.
  void AddInputSchedule(const std::vector<SmtEncoding::PathStep>& path, int depth,
                        Trace& trace) const;
  // Sets in `current` the inputs that the guard of `jump`'s transition reads to the jump's
  // values; whether any changed.
  bool GuardInputs(const SmtEncoding::PathStep& jump, std::vector<double>& current) const;
  // Replays `trace` (of the path of `depth` steps in `model`) for `c`: if it replays, decides `c`
  // violated (reachable for `reach`) with it; false otherwise.
  bool ReplayPath(const z3::model& model, int depth, Candidate& c, Trace trace);
  bool Extend(int n, std::uint64_t ceiling);
  // The charge for one step of the encoding (a State and a Transition) asserted in a solver.
  std::uint64_t StepUnits() const {
    return kUnitsPerEncodedElement *
           static_cast<std::uint64_t>(a_.num_modes() + a_.num_transitions() + 1);
  }
  // What a path of k steps whose last step leaves mode m (any mode: m < 0) puts in a new solver:
  // k + 1 states (each linear in the modes), k - 1 full steps and the last step (from m: its flow
  // and its outgoing transitions only).
  std::uint64_t PathUnits(int k, int m) const {
    std::uint64_t last = static_cast<std::uint64_t>(a_.num_modes() + a_.num_transitions() + 1);
    if (m >= 0) {
      last = 1;
      for (const Transition& t : a_.transitions()) last += t.source.value() == m ? 1 : 0;
    }
    const auto steps = static_cast<std::uint64_t>(std::max(k - 1, 0));
    return kUnitsPerEncodedElement *
           (static_cast<std::uint64_t>(k + 1) * static_cast<std::uint64_t>(a_.num_modes() + 1) +
            steps * static_cast<std::uint64_t>(a_.num_modes() + a_.num_transitions() + 1) + last);
  }
  z3::expr Bad(const Candidate& c, int n, double margin);
  void Search(int n, bool invariants_only, std::initializer_list<bool> passes,
              std::uint64_t ceiling);
  void One(Candidate& c, int n, bool pinned, std::uint64_t ceiling);

  // One round of k-induction (Houdini): the candidates, which are still alive, and the formulas
  // of the step queries, each built once.
  struct InductionRound {
    int k = 1;
    std::uint64_t ceiling = 0;
    std::vector<Candidate*> set;
    std::vector<bool> alive;
    std::vector<std::optional<z3::expr>> path_from;  // the path of k steps, per last mode
    std::optional<z3::expr> hypotheses;              // of the alive candidates
    std::optional<z3::expr> path_any;                // the path of k steps, any last mode

    // The indices of the candidates still alive.
    std::vector<std::size_t> Living() const;
    // Drops the candidates `failed`; whether any was alive (then the hypotheses are rebuilt).
    bool Drop(const std::vector<std::size_t>& failed);
  };
  void Induction(int k);
  // The round of k-induction over the invariants neither refuted nor decided, all alive.
  InductionRound StartInduction(int k);
  // The step from each mode in turn for the living candidates (split per candidate where a
  // query runs out); drops those that fail and returns whether any was dropped.
  bool StepPerMode(InductionRound& round);
  // The step query from mode m, or from any mode (m = -1, with Z3's default solver): a path of k
  // steps on which the living candidates hold before s_k and one of `goals` fails at s_k. On sat,
  // `failed` gets the goals the model breaks (all of them when it cannot tell).
  z3::check_result StepQuery(InductionRound& round, int m, const std::vector<std::size_t>& goals,
                             unsigned limit, std::vector<std::size_t>& failed);
  // The path of the step query from mode m (any: m < 0), built on first use.
  const z3::expr& StepPath(InductionRound& round, int m);
  // The living candidates hold at s_0 .. s_k-1: built on first use after each drop.
  const z3::expr& Hypotheses(InductionRound& round);
  // The candidates still alive are inductive together: proved.
  void DecideInductive(const InductionRound& round);
  void DeepSearch();
  bool Unreachable(const Candidate& c);
  void Conclude();

  const System& system_;
  const PropertyProver::Options& options_;
  SolverBudget& budget_;
  Clock::time_point start_;
  std::vector<CheckResult>& results_;
  const Job& job_;
  const Automaton& a_;
  z3::context ctx_;
  SmtEncoding enc_;
  Meter meter_;
  z3::solver bmc_;  // the incremental solver of bounded model checking
  std::vector<Candidate> cands_;
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

bool JobRun::Open() const {
  for (const Candidate& c : cands_) {
    if (!c.decided && c.goal->result >= 0) return true;
  }
  return false;
}

void JobRun::Decide(Candidate& c, Verdict v, std::string reason, std::optional<Trace> trace) {
  c.decided = true;
  if (c.goal->result < 0) return;
  std::vector<int> targets = c.goal->also;
  targets.insert(targets.begin(), c.goal->result);
  for (int index : targets) {
    CheckResult& r = results_[index];
    r.verdict = v;
    r.reason = reason;
    r.trace = trace;
    r.seconds = Since(start_);
  }
}

bool JobRun::TryTrace(const z3::model& model, int depth, Candidate& c) {
  const auto path = enc_.ReadPath(model, depth);
  Trace trace;
  trace.parameters = enc_.ReadParameters(model);
  // The initial state the path starts from, and its values where that state is a box.
  const int start = enc_.InitialIndex(model);
  if (start < 0) return false;
  AddInitialStates(start, trace);
  AddInitialValues(start, path[0], trace);
  AddInputSchedule(path, depth, trace);
  return ReplayPath(model, depth, c, std::move(trace));
}

void JobRun::AddInitialStates(int start, Trace& trace) const {
  if (job_.component >= 0) {
    trace.initial_states.emplace_back(job_.component, start);
    return;
  }
  // A product's initial state `start`, decomposed (mixed radix, the last component fastest).
  const auto components = system_.components();
  std::vector<std::pair<int, int>> states;
  for (auto c = job_.product_components.rbegin(); c != job_.product_components.rend(); ++c) {
    const int n = static_cast<int>(components[*c].automaton.initial_states().size());
    states.emplace_back(*c, start % n);
    start /= n;
  }
  trace.initial_states.assign(states.rbegin(), states.rend());
}

void JobRun::AddInitialValues(int start, const SmtEncoding::PathStep& s0, Trace& trace) const {
  const InitialState& init = a_.initial_states()[static_cast<std::size_t>(start)];
  for (const InitialValue& iv : init.values) {
    if (iv.is_point) continue;
    int index = 0;
    for (const VariableInfo& v : a_.variables()) {
      if (v.slot == iv.slot) break;
      ++index;
    }
    trace.initial_values.emplace_back(system_.symbols()[job_.to_system[iv.slot]].name, s0.x[index]);
  }
}

void JobRun::AddInputSchedule(const std::vector<SmtEncoding::PathStep>& path, int depth,
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

bool JobRun::GuardInputs(const SmtEncoding::PathStep& jump, std::vector<double>& current) const {
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

bool JobRun::ReplayPath(const z3::model& model, int depth, Candidate& c, Trace trace) {
  ++c.replays;
  bool replayed = false;
  try {
    replayed = ReplayTrace(system_, c.goal->original, trace);
  } catch (const std::exception& e) {
    if (std::getenv("HYBRID_CHECK_DEBUG")) std::cerr << "replay failed: " << e.what() << "\n";
  }
  if (!replayed) {
    if (std::getenv("HYBRID_CHECK_DEBUG")) {
      std::cerr << "path of " << depth << " steps for " << c.goal->property.name
                << " does not replay:\n";
      DebugPath(enc_, model, depth);
    }
    return false;
  }
  Decide(c, c.invariant ? Verdict::kViolated : Verdict::kReachable,
         std::string(c.invariant ? "counterexample" : "witness") + " of " + std::to_string(depth) +
             " steps found by bounded model checking, replayed by the simulator",
         std::move(trace));
  return true;
}

// Adds the paths of up to n steps to bmc_, each step paid for (StepUnits) before it is built;
// false when the ceiling does not allow it.
bool JobRun::Extend(int n, std::uint64_t ceiling) {
  while (bmc_depth_ < n) {
    if (bmc_depth_ >= 0 && !meter_.Afford(StepUnits(), ceiling)) return false;
    ++bmc_depth_;
    if (bmc_depth_ > 0) {
      Add(bmc_, enc_, enc_.Transition(bmc_depth_ - 1));
      Add(bmc_, enc_, enc_.State(bmc_depth_));
    }
  }
  return true;
}

// s_n is a counterexample (by at least `margin`) or a witness of `c`.
z3::expr JobRun::Bad(const Candidate& c, int n, double margin) {
  return c.invariant ? !enc_.Holds(Predicate::Not(c.bad), n, margin) : enc_.Holds(c.bad, n, 0.0);
}

// Paths of exactly n steps: parameters at their nominal values first (fewer ties between
// events, which the simulator breaks by declaration order), then over their ranges. Per pass, one
// query for the candidates not yet tried: unsat settles them all; a model names those it breaks
// (or reaches), which are tried alone (One) and the rest asked again; a query that runs out
// leaves every remaining candidate to One.
void JobRun::Search(int n, bool invariants_only, std::initializer_list<bool> passes,
                    std::uint64_t ceiling) {
  if (!Extend(n, ceiling)) {
    bmc_complete_ = false;
    return;
  }
  auto wanted = [&](const Candidate& c) {
    // Lemmas need no counterexample of their own beyond the base case.
    return Pending(c) && (!invariants_only || c.invariant) && !(deep_ && c.goal->result < 0);
  };
  for (bool pinned : passes) {
    if (pinned && enc_.uncertain().empty()) continue;
    std::vector<bool> tried(cands_.size(), false);
    for (bool more = true; more;) {
      z3::expr_vector any(ctx_);
      std::vector<std::size_t> asked;
      for (std::size_t i = 0; i < cands_.size(); ++i) {
        if (!wanted(cands_[i]) || tried[i]) continue;
        any.push_back(Bad(cands_[i], n, 0.0));
        asked.push_back(i);
      }
      if (asked.empty()) break;
      bmc_.push();
      Add(bmc_, enc_, z3::mk_or(any));
      if (pinned) bmc_.add(enc_.NominalParameters());
      const z3::check_result r = meter_.Check(bmc_, options_.resource_limit, ceiling, "search");
      std::vector<std::size_t> hit;
      std::optional<z3::model> model;
      if (r == z3::sat) {
        model = bmc_.get_model();
        for (std::size_t j = 0; j < asked.size(); ++j) {
          if (model->eval(any[static_cast<int>(j)], true).is_true()) hit.push_back(asked[j]);
        }
      }
      bmc_.pop();
      if (r == z3::unsat) break;
      if (r == z3::unknown) {
        if (!pinned) bmc_complete_ = false;
        more = false;
      }
      if (hit.empty()) hit = asked;  // cannot tell which: each alone
      for (std::size_t i : hit) {
        tried[i] = true;
        One(cands_[i], n, pinned, ceiling);
      }
    }
  }
}

// Candidate `c` alone on paths of exactly n steps: robust violations first (they replay clear of
// rounding), then exact ones; a path found is replayed (TryTrace).
void JobRun::One(Candidate& c, int n, bool pinned, std::uint64_t ceiling) {
  for (double margin : {options_.robust_margin, 0.0}) {
    if (!Pending(c) || (!c.invariant && margin > 0)) continue;
    bmc_.push();
    Add(bmc_, enc_, Bad(c, n, margin));
    if (pinned) bmc_.add(enc_.NominalParameters());
    const z3::check_result rc =
        meter_.Check(bmc_, options_.resource_limit, ceiling, "search, one property");
    if (rc == z3::sat) {
      c.refuted = c.refuted || c.invariant;
      TryTrace(bmc_.get_model(), n, c);
    } else if (rc == z3::unknown && !pinned) {
      bmc_complete_ = false;
    }
    bmc_.pop();
    if (rc == z3::sat) break;
  }
}

// k-induction with Houdini over the surviving invariants. The step query is split on the mode
// of s_(k-1): one small nonlinear problem per mode is far easier for nlsat than their
// disjunction. Per mode, all candidates are checked at once; a model names the ones that fail
// (dropped), a query that runs out splits per candidate, and one that runs out alone is dropped.
void JobRun::Induction(int k) {
  InductionRound round = StartInduction(k);
  // First the step from any mode in one query (cheap where the flows are simple, however many
  // modes), while it decides; then per mode.
  bool whole = true;
  bool changed = true;
  while (changed) {
    changed = false;
    round.hypotheses.reset();
    if (whole && !round.Living().empty() && budget_.used() < round.ceiling &&
        !budget_.SafetyExpired()) {
      std::vector<std::size_t> failed;
      const z3::check_result r =
          StepQuery(round, -1, round.Living(), options_.resource_limit / 25, failed);
      if (r == z3::unsat) break;
      if (r == z3::sat) {
        changed = round.Drop(failed);
        continue;
      }
      whole = false;
    }
    changed = StepPerMode(round) || changed;
  }
  DecideInductive(round);
}

JobRun::InductionRound JobRun::StartInduction(int k) {
  InductionRound round;
  round.k = k;
  for (Candidate& c : cands_) {
    if (c.invariant && !c.refuted && !c.decided) round.set.push_back(&c);
  }
  round.ceiling = Ceiling(0.5);
  round.alive.assign(round.set.size(), true);
  round.path_from.resize(a_.num_modes());
  return round;
}

std::vector<std::size_t> JobRun::InductionRound::Living() const {
  std::vector<std::size_t> goals;
  for (std::size_t j = 0; j < set.size(); ++j) {
    if (alive[j]) goals.push_back(j);
  }
  return goals;
}

bool JobRun::InductionRound::Drop(const std::vector<std::size_t>& failed) {
  bool changed = false;
  for (std::size_t j : failed) {
    changed = changed || alive[j];
    alive[j] = false;
  }
  if (changed) hypotheses.reset();  // weaker now: modes already passed are checked again
  return changed;
}

bool JobRun::StepPerMode(InductionRound& round) {
  bool changed = false;
  for (int m = 0; m < a_.num_modes(); ++m) {
    std::vector<std::size_t> goals = round.Living(), failed;
    if (goals.empty()) break;
    if (budget_.used() >= round.ceiling || budget_.SafetyExpired()) {
      proof_cut_ = true;  // nothing left to prove with: every candidate is dropped
      failed = goals;
    } else if (StepQuery(round, m, goals, options_.resource_limit / 25, failed) == z3::unknown) {
      // Split per candidate with a larger limit, then the full one (a candidate dropped for
      // want of resources takes with it every candidate that needs it as a lemma).
      for (std::size_t j : goals) {
        std::vector<std::size_t> f;
        if (StepQuery(round, m, {j}, options_.resource_limit / 5, f) == z3::unknown &&
            StepQuery(round, m, {j}, options_.resource_limit, f) == z3::unknown) {
          f.push_back(j);
        }
        failed.insert(failed.end(), f.begin(), f.end());
      }
    }
    changed = round.Drop(failed) || changed;
  }
  return changed;
}

z3::check_result JobRun::StepQuery(InductionRound& round, int m,
                                   const std::vector<std::size_t>& goals, unsigned limit,
                                   std::vector<std::size_t>& failed) {
  const int k = round.k;
  // A path of k steps (k + 1 states) asserted in a new solver.
  if (!meter_.Afford(PathUnits(k, m), round.ceiling)) return z3::unknown;
  z3::solver s = m < 0 ? MakeIncremental(ctx_) : MakeSolver(ctx_);
  s.add(StepPath(round, m));
  s.add(Hypotheses(round));
  z3::expr_vector bad(ctx_);
  std::vector<z3::expr> at_k;
  for (std::size_t j : goals) {
    at_k.push_back(enc_.Holds(round.set[j]->bad, k, 0.0));
    bad.push_back(at_k.back());
  }
  Add(s, enc_, z3::mk_or(bad));
  const z3::check_result r =
      meter_.Check(s, limit, round.ceiling, m < 0 ? "induction" : "induction, one mode");
  if (r == z3::sat) {
    const z3::model model = s.get_model();
    for (std::size_t g = 0; g < goals.size(); ++g) {
      if (model.eval(at_k[g], true).is_true()) failed.push_back(goals[g]);
    }
    if (std::getenv("HYBRID_CHECK_DEBUG")) {
      std::cerr << "induction k=" << k << " from mode "
                << (m < 0 ? std::string("(any)") : a_.modes()[m].name) << " fails:\n";
      DebugPath(enc_, model, k);
    }
    if (failed.empty()) failed = goals;  // cannot tell which: drop all (sound)
  }
  return r;
}

const z3::expr& JobRun::StepPath(InductionRound& round, int m) {
  const int k = round.k;
  std::optional<z3::expr>& path = m < 0 ? round.path_any : round.path_from[m];
  if (!path) {
    z3::expr_vector e(ctx_);
    for (int i = 0; i <= k; ++i) e.push_back(enc_.State(i));
    for (int i = 0; i + 1 < k; ++i) e.push_back(enc_.Transition(i));
    e.push_back(m < 0 ? enc_.Transition(k - 1) : enc_.TransitionFrom(k - 1, ModeId(m)));
    e.push_back(enc_.TakeDefinitions());
    path = z3::mk_and(e);
  }
  return *path;
}

const z3::expr& JobRun::Hypotheses(InductionRound& round) {
  if (!round.hypotheses) {
    z3::expr_vector e(ctx_);
    for (std::size_t j = 0; j < round.set.size(); ++j) {
      if (!round.alive[j]) continue;
      for (int i = 0; i < round.k; ++i) e.push_back(!enc_.Holds(round.set[j]->bad, i, 0.0));
    }
    e.push_back(enc_.TakeDefinitions());
    round.hypotheses = z3::mk_and(e);
  }
  return *round.hypotheses;
}

void JobRun::DecideInductive(const InductionRound& round) {
  std::size_t lemmas = 0;
  for (std::size_t j = 0; j < round.set.size(); ++j) lemmas += round.alive[j] ? 1 : 0;
  for (std::size_t j = 0; j < round.set.size(); ++j) {
    if (!round.alive[j]) continue;
    Candidate& c = *round.set[j];
    Decide(c, Verdict::kProved,
           "proved by " + std::to_string(round.k) + "-induction, together with " +
               std::to_string(lemmas - 1) + " other invariant(s) as lemmas");
    c.proved = true;
  }
}

// Counterexamples and witnesses for what is still open, up to max_depth steps. Search order:
// short paths with nominal and with free parameters; then longer paths with nominal parameters
// (cheap: fewer branches; at most 40% of this phase); then longer paths with every parameter
// value (the search space grows fast with the depth).
void JobRun::DeepSearch() {
  deep_ = true;
  const std::uint64_t end = Ceiling(0.9);
  const std::uint64_t from = std::min(budget_.used(), end);
  const std::uint64_t pinned_end = from + (end - from) * 2 / 5;
  const int shallow = std::min(options_.max_depth, 3);
  struct Pass {
    int from, to;
    std::initializer_list<bool> pinned;
    std::uint64_t ceiling;
  };
  const Pass passes[] = {{0, shallow, {true, false}, end},
                         {shallow + 1, options_.max_depth, {true}, pinned_end},
                         {shallow + 1, options_.max_depth, {false}, end}};
  for (const Pass& pass : passes) {
    const bool pinned_only = pass.pinned.size() == 1 && *pass.pinned.begin();
    if (pinned_only && enc_.uncertain().empty()) continue;  // the next pass covers it
    for (int n = pass.from; n <= pass.to && Open(); ++n) {
      const int starved = meter_.starved();
      if (budget_.used() < pass.ceiling && !budget_.SafetyExpired()) {
        Search(n, false,
               enc_.uncertain().empty() ? std::initializer_list<bool>{false} : pass.pinned,
               pass.ceiling);
      }
      const bool cut =
          meter_.starved() > starved || budget_.used() >= pass.ceiling || budget_.SafetyExpired();
      if (cut && !pinned_only) search_cut_ = true;
      if (cut) break;  // the pinned pass leaves the rest of its share to the next one
      if (!pinned_only) searched_ = n;
    }
    if (search_cut_) break;
  }
}

// `reach` target `c`: no initial state is in it, and `not P` is inductive relative to the proved
// invariants (checked per mode, as the induction).
bool JobRun::Unreachable(const Candidate& c) {
  const std::uint64_t ceiling = Ceiling(1.0);
  if (!meter_.Afford(StepUnits(), ceiling)) return false;
  z3::solver base = MakeSolver(ctx_);
  Add(base, enc_, enc_.Initial() && enc_.State(0) && enc_.Holds(c.bad, 0, 0.0));
  if (meter_.Check(base, options_.resource_limit, ceiling, "unreachability, initial") !=
      z3::unsat) {
    return false;
  }
  for (int m = 0; m < a_.num_modes(); ++m) {
    if (!meter_.Afford(PathUnits(1, m), ceiling)) return false;
    z3::solver s = MakeSolver(ctx_);
    z3::expr_vector e(ctx_);
    e.push_back(enc_.State(0));
    e.push_back(enc_.State(1));
    e.push_back(enc_.TransitionFrom(0, ModeId(m)));
    e.push_back(!enc_.Holds(c.bad, 0, 0.0));
    e.push_back(enc_.Holds(c.bad, 1, 0.0));
    for (const Candidate& lemma : cands_) {
      if (lemma.invariant && lemma.proved) e.push_back(!enc_.Holds(lemma.bad, 0, 0.0));
    }
    Add(s, enc_, z3::mk_and(e));
    if (meter_.Check(s, options_.resource_limit, ceiling, "unreachability, one mode") !=
        z3::unsat) {
      return false;
    }
  }
  return true;
}

void JobRun::Conclude() {
  const std::string budget =
      "the solver budget (" + FormatNumber(budget_.seconds()) + " budget seconds) ran out";
  std::string note;
  if (!bmc_complete_ && !proof_cut_ && !search_cut_) {
    note = "an SMT query ran out of its resource limit; ";
  }
  if (budget_.safety_stopped()) {
    note +=
        "a solver query was stopped by the CPU-time safety limit (work the solver does not "
        "count), so this result may depend on the machine's speed; ";
  }
  const std::string depth = std::to_string(options_.max_depth);
  const std::string paths = searched_ >= 0 ? " after paths of " + std::to_string(searched_) +
                                                 (searched_ == 1 ? " step" : " steps")
                                           : " before any path was searched";
  for (Candidate& c : cands_) {
    if (c.decided) continue;
    std::string why = note;
    if (c.invariant) {
      why += proof_cut_
                 ? budget + " before k-induction could prove it"
                 : "not proved by k-induction for k <= " + std::to_string(options_.max_induction);
      why += search_cut_ ? "; " + budget + " in the search for counterexamples" + paths
                         : ", and no counterexample within " + depth + " steps";
    } else {
      why += search_cut_ ? budget + " in the search for witnesses" + paths
                         : "no witness within " + depth + " steps that replays";
      why += unreach_cut_ ? "; " + budget + " before unreachability could be proved"
                          : ", and unreachability not proved by induction";
    }
    Decide(c, Verdict::kUnknown, why);
  }
}

void JobRun::Go() {
  for (const Goal& g : job_.goals) {
    const Property& p = g.property;
    switch (p.kind) {
      case Property::Kind::kAlways:
        cands_.push_back({&g, Predicate::Not(p.predicate), true});
        break;
      case Property::Kind::kNever:
        cands_.push_back({&g, p.predicate, true});
        break;
      case Property::Kind::kReach:
        cands_.push_back({&g, p.predicate, false});
        break;
    }
  }
  // 1. Base case: no violation on paths of fewer than max_induction steps (what k-induction
  //    needs, whatever max_depth is). Bounded model checking uses Z3's default (incremental)
  //    solver, which handles long unrollings better than nlsat.
  Add(bmc_, enc_, enc_.Initial());
  Add(bmc_, enc_, enc_.State(0));
  const int starved = meter_.starved();
  for (int n = 0; n < options_.max_induction; ++n) Search(n, true, {true, false}, Ceiling(0.5));
  base_complete_ = bmc_complete_;
  proof_cut_ = meter_.starved() > starved;
  // 2. k-induction with Houdini over the surviving invariants.
  const int before_induction = meter_.starved();
  for (int k = 1; k <= options_.max_induction && Open() && base_complete_; ++k) Induction(k);
  proof_cut_ = proof_cut_ || meter_.starved() > before_induction;
  // 3. Counterexamples and witnesses for what is still open.
  DeepSearch();
  for (Candidate& c : cands_) {
    if (!c.decided && c.refuted) {
      Decide(c, Verdict::kUnknown,
             "the encoding (an over-approximation) reaches a violation, but no path of at most " +
                 std::to_string(options_.max_depth) + " steps found replays in the simulator");
    }
  }
  // 4. Reach targets without a witness: unreachable if no initial state is a target and `not P`
  //    is inductive relative to the proved invariants.
  for (Candidate& c : cands_) {
    if (c.decided || c.invariant || c.goal->result < 0) continue;
    const int starved = meter_.starved();
    const bool unreachable = Unreachable(c);
    unreach_cut_ = unreach_cut_ || meter_.starved() > starved;
    if (unreachable) {
      Decide(c, Verdict::kUnreachable,
             "proved by 1-induction of its negation, with the proved invariants as lemmas");
    }
  }
  Conclude();
}

// Slots and modes a predicate reads.
void Collect(const Predicate& p, std::set<int>& slots, std::set<std::string>& modes) {
  p.ForEachComparison([&](const Comparison& c) {
    for (int s : c.lhs.Slots()) slots.insert(s);
    for (int s : c.rhs.Slots()) slots.insert(s);
  });
  p.ForEachMode([&](const std::string& m) { modes.insert(m); });
}

}  // namespace

namespace {

// Which components write each System slot (continuous variables).
std::vector<std::vector<int>> SlotOwners(const System& system) {
  const auto components = system.components();
  std::vector<std::vector<int>> owners(system.symbols().size());
  for (std::size_t c = 0; c < components.size(); ++c) {
    for (const VariableInfo& v : components[c].automaton.variables()) {
      owners[components[c].global_slot[v.slot]].push_back(static_cast<int>(c));
    }
  }
  return owners;
}

// The components that hold the variables (`slots`) and `modes` property `p` reads, or component 0
// when it reads none. Throws std::invalid_argument for a property that reads an input.
std::set<int> ComponentsRead(const System& system, const Property& p, const std::set<int>& slots,
                             const std::set<std::string>& modes) {
  const auto components = system.components();
  std::set<int> comps;
  for (int s : slots) {
    const SymbolKind kind = system.symbols()[s].kind;
    if (kind == SymbolKind::kInput) {
      throw std::invalid_argument("property '" + p.name + "' reads input '" +
                                  system.symbols()[s].name +
                                  "': properties may read variables, parameters and modes");
    }
    if (kind == SymbolKind::kParameter) continue;
    for (std::size_t c = 0; c < components.size(); ++c) {
      const auto& g = components[c].global_slot;
      if (std::find(g.begin(), g.end(), s) != g.end()) comps.insert(static_cast<int>(c));
    }
  }
  for (const std::string& m : modes) {
    if (auto found = system.FindMode(m)) comps.insert(found->first);
  }
  // A parameter none of those components has (another instance's `A.p`): the first component
  // that declares it joins, so that the job has the parameter (and its range) too.
  for (int s : slots) {
    if (system.symbols()[s].kind != SymbolKind::kParameter) continue;
    auto has = [&](int c) {
      const auto& g = components[static_cast<std::size_t>(c)].global_slot;
      return std::find(g.begin(), g.end(), s) != g.end();
    };
    if (std::any_of(comps.begin(), comps.end(), has)) continue;
    for (int c = 0; c < static_cast<int>(components.size()); ++c) {
      if (has(c)) {
        comps.insert(c);
        break;
      }
    }
  }
  if (comps.empty()) comps.insert(0);
  return comps;
}

// Whether component c alone over-approximates what it does in the system, so that a property
// reading only c may be checked on c alone: no other component has a continuous variable of c,
// and no urgent transition of c synchronises with another component (a partner that is not
// ready lets time pass beyond the point where c alone would have to jump; lazy synchronised
// transitions only lose jumps in the system, which is sound).
bool WritesAlone(const System& system, const std::vector<std::vector<int>>& owners, int c) {
  const Component& comp = system.components()[c];
  for (const VariableInfo& v : comp.automaton.variables()) {
    if (owners[comp.global_slot[v.slot]].size() > 1) return false;
  }
  for (const Transition& t : comp.automaton.transitions()) {
    if (t.urgency != Urgency::kUrgent || t.label.empty()) continue;
    for (int other = 0; other < static_cast<int>(system.components().size()); ++other) {
      if (other != c && system.Alphabet(other).count(t.label)) return false;
    }
  }
  return true;
}

// `p` (System slots) over the slots of a job whose slot i is System slot to_system[i], its mode
// names mapped by `mode`.
Property OverJobSlots(const Property& p, const std::vector<int>& to_system, int system_slots,
                      const std::function<std::string(const std::string&)>& mode) {
  std::vector<int> local(static_cast<std::size_t>(system_slots), -1);
  for (std::size_t s = 0; s < to_system.size(); ++s) local[to_system[s]] = static_cast<int>(s);
  Property q = p;
  q.predicate = Remap(
      p.predicate,
      [&](const Expression& e) {
        return e.Substitute([&](const std::string& name, int slot) -> std::optional<Expression> {
          return Expression::Symbol(name, local.at(slot));
        });
      },
      mode);
  return q;
}

// `p` (System slots and mode names) over component c's own slots and mode names.
Property Localise(const System& system, int c, const Property& p) {
  const Component& comp = system.components()[c];
  return OverJobSlots(p, comp.global_slot, system.symbols().size(), [&](const std::string& m) {
    auto found = system.FindMode(m);
    return found ? comp.automaton.mode(found->second).name : m;
  });
}

// Adds `q`, the local form of property number i (`p`), to component c's job; the same question
// asked twice is answered once (`asked`: goals looked up by their text, then compared).
void AddGoal(int c, const Property& q, int i, const Property& p,
             std::map<std::string, std::vector<int>>& asked, std::vector<Job>& jobs) {
  const std::string key = std::to_string(c) + " " + std::string(KindKeyword(q.kind)) + " " +
                          q.predicate.ToString() + " " +
                          (q.horizon ? FormatNumber(*q.horizon) : std::string("-"));
  for (const int g : asked[key]) {
    Goal& goal = jobs[c].goals[g];
    if (goal.property.kind == q.kind && goal.property.predicate == q.predicate &&
        goal.property.horizon == q.horizon) {
      goal.also.push_back(i);
      return;
    }
  }
  asked[key].push_back(static_cast<int>(jobs[c].goals.size()));
  jobs[c].goals.push_back({q, i, p, {}});
}

// The product of a group of components and the job that asks it the properties that read
// them; the product is made on first use.
struct ProductJob {
  std::optional<Automaton> automaton;
  std::vector<int> components;           // the System's components, in product order
  std::vector<std::vector<int>> tuples;  // product mode -> component modes
  std::string failure;                   // why the product could not be made
  Job job;
};
// Keyed by the components (ascending indices); a map, so that job.automaton stays valid.
using ProductJobs = std::map<std::vector<int>, ProductJob>;

// For each component, a representative of its interaction group: the least set of components
// closed under sharing a variable (continuous or discrete) or a synchronisation label. Groups
// meet only through inputs (free in a check) and parameters (constants), so a property that
// reads some groups is decided by the product of those groups alone.
std::vector<int> InteractionGroups(const System& system) {
  const auto components = system.components();
  std::vector<int> parent(components.size());
  for (std::size_t c = 0; c < parent.size(); ++c) parent[c] = static_cast<int>(c);
  auto find = [&](int c) {
    while (parent[c] != c) c = parent[c] = parent[parent[c]];
    return c;
  };
  std::map<int, int> slot_user;           // System slot -> a component that has it
  std::map<std::string, int> label_user;  // label -> a component that uses it
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    for (const int g : components[c].global_slot) {
      const SymbolKind kind = system.symbols()[g].kind;
      if (kind != SymbolKind::kVariable && kind != SymbolKind::kDiscrete) continue;
      const auto [it, added] = slot_user.emplace(g, c);
      if (!added) parent[find(c)] = find(it->second);
    }
    for (const std::string& label : system.Alphabet(c)) {
      const auto [it, added] = label_user.emplace(label, c);
      if (!added) parent[find(c)] = find(it->second);
    }
  }
  std::vector<int> group(components.size());
  for (std::size_t c = 0; c < group.size(); ++c) group[c] = find(static_cast<int>(c));
  return group;
}

// The components of the interaction groups of `comps`, ascending.
std::vector<int> GroupsOf(const std::vector<int>& group, const std::set<int>& comps) {
  std::set<int> representatives;
  for (const int c : comps) representatives.insert(group[c]);
  std::vector<int> out;
  for (std::size_t c = 0; c < group.size(); ++c) {
    if (representatives.count(group[c])) out.push_back(static_cast<int>(c));
  }
  return out;
}

// Makes the product of components `which` into `pj` (automaton and to_system), or records why
// it cannot be made.
void MakeProduct(const System& system, const std::vector<int>& which, int max_product_modes,
                 ProductJob& pj) {
  const System restricted = system.Restricted(which);
  pj.components = which;
  pj.job.product_components = which;
  try {
    pj.automaton = restricted.Product(max_product_modes, &pj.tuples);
  } catch (const std::invalid_argument& e) {
    pj.failure = std::string(
                     "the property reads several components and their product is too "
                     "large: ") +
                 e.what();
    return;
  }
  for (int s = 0; s < restricted.symbols().size(); ++s) {
    pj.job.to_system.push_back(*system.symbols().Find(restricted.symbols()[s].name));
  }
}

// The disjunction of `atoms[lo, hi)`, as a balanced tree (depth log2 of their number); false for
// none.
Predicate AnyOf(const std::vector<Predicate>& atoms, std::size_t lo, std::size_t hi) {
  if (lo >= hi) return Predicate::False();
  if (hi - lo == 1) return atoms[lo];
  const std::size_t mid = lo + (hi - lo) / 2;
  return Predicate::Or(AnyOf(atoms, lo, mid), AnyOf(atoms, mid, hi));
}

// `p` with every `in A.m` atom (a mode of one component) replaced by the disjunction of the
// product modes of `pj` whose A part is m.
Predicate OverProductModes(const System& system, const ProductJob& pj, const Predicate& p) {
  switch (p.kind()) {
    case Predicate::Kind::kInMode: {
      const auto found = system.FindMode(p.mode());
      const auto at = found ? std::find(pj.components.begin(), pj.components.end(), found->first)
                            : pj.components.end();
      if (at == pj.components.end()) return Predicate::False();
      const std::size_t i = static_cast<std::size_t>(at - pj.components.begin());
      std::vector<Predicate> atoms;
      for (std::size_t m = 0; m < pj.tuples.size(); ++m) {
        if (pj.tuples[m][i] == found->second.value()) {
          atoms.push_back(Predicate::InMode(pj.automaton->modes()[m].name));
        }
      }
      return AnyOf(atoms, 0, atoms.size());
    }
    case Predicate::Kind::kNot:
      return Predicate::Not(OverProductModes(system, pj, p.operands()[0]));
    case Predicate::Kind::kAnd:
      return Predicate::And(OverProductModes(system, pj, p.operands()[0]),
                            OverProductModes(system, pj, p.operands()[1]));
    case Predicate::Kind::kOr:
      return Predicate::Or(OverProductModes(system, pj, p.operands()[0]),
                           OverProductModes(system, pj, p.operands()[1]));
    default:
      return p;
  }
}

// Adds property number i (`p`) to the job of the product of components `which`, making the
// product on first use (its `in A.m` atoms become disjunctions of product modes); or leaves it
// `unknown` when the product is too large.
void AddProductGoal(const System& system, const Property& p, int i, const std::vector<int>& which,
                    int max_product_modes, std::vector<CheckResult>& results,
                    ProductJobs& products) {
  ProductJob& pj = products[which];
  if (!pj.automaton && pj.failure.empty()) MakeProduct(system, which, max_product_modes, pj);
  if (!pj.automaton) {
    results[i].verdict = Verdict::kUnknown;
    results[i].reason = pj.failure;
    return;
  }
  // Modes are kept (OverProductModes maps them).
  Property q = OverJobSlots(p, pj.job.to_system, system.symbols().size(),
                            [](const std::string& m) { return m; });
  q.predicate = OverProductModes(system, pj, q.predicate);
  pj.job.goals.push_back({std::move(q), i, p, {}});
}

// Sorts `properties` into jobs: one per component for a property that reads only that
// component's own variables (in its slots and mode names), a product job for the others (the
// product of the interaction groups the property reads), or a verdict right away (`unknown`)
// when neither is possible.
void PlanJobs(const System& system, std::span<const Property> properties, int max_product_modes,
              std::vector<CheckResult>& results, std::vector<Job>& jobs, ProductJobs& products) {
  const std::vector<std::vector<int>> owners = SlotOwners(system);
  const std::vector<int> group = InteractionGroups(system);
  std::map<std::string, std::vector<int>> asked;  // goals by their text (see AddGoal)
  for (std::size_t i = 0; i < properties.size(); ++i) {
    const Property& p = properties[i];
    results[i].property = p.name;
    results[i].kind = p.kind;
    results[i].method = "prove";
    std::set<int> slots;
    std::set<std::string> modes;
    Collect(p.predicate, slots, modes);
    const std::set<int> comps = ComponentsRead(system, p, slots, modes);
    if (comps.size() == 1 && WritesAlone(system, owners, *comps.begin())) {
      const int c = *comps.begin();
      AddGoal(c, Localise(system, c, p), static_cast<int>(i), p, asked, jobs);
      continue;
    }
    AddProductGoal(system, p, static_cast<int>(i), GroupsOf(group, comps), max_product_modes,
                   results, products);
  }
}

// The declared invariants of component `c` join its job as lemmas.
void AddLemmas(const System& system, int c, Job& job) {
  const auto components = system.components();
  // The component's own declared invariants serve as lemmas.
  for (const Property& lemma : components[c].automaton.properties()) {
    if (lemma.kind == Property::Kind::kReach) continue;
    bool dup = false;
    for (const Goal& g : job.goals) {
      dup = dup || (g.property.kind == lemma.kind && g.property.predicate == lemma.predicate &&
                    g.property.horizon == lemma.horizon);
    }
    if (dup) continue;
    Property original = lemma;
    original.predicate = Remap(
        lemma.predicate,
        [&](const Expression& e) {
          return e.Substitute([&](const std::string& name, int slot) -> std::optional<Expression> {
            return Expression::Symbol(name, components[c].global_slot[slot]);
          });
        },
        [&](const std::string& m) {
          auto id = components[c].automaton.FindMode(m);
          return id ? system.QualifiedModeName(c, *id) : m;
        });
    job.goals.push_back({lemma, -1, original, {}});
  }
}

// An earlier component, instance of the same automaton, whose job asks the same questions as
// component `c`'s (its proof serves for both), or -1.
int SameInstance(const System& system, const std::vector<Job>& jobs, int c) {
  const auto components = system.components();
  const Job& job = jobs[c];
  int same = -1;
  for (int c0 = 0; c0 < c && same < 0; ++c0) {
    const Job& j0 = jobs[c0];
    if (j0.goals.size() != job.goals.size() || !(components[c0].source == components[c].source)) {
      continue;
    }
    // Compare with the declared (unqualified) names: slots are the same in both instances.
    auto plain = [&](const Predicate& p, const Component& comp) {
      return Remap(
          p,
          [&](const Expression& e) {
            return e.Substitute([&](const std::string&, int slot) -> std::optional<Expression> {
              return Expression::Symbol(comp.source.symbols()[slot].name, slot);
            });
          },
          [&](const std::string& m) {
            auto id = comp.automaton.FindMode(m);
            return id ? comp.source.mode(*id).name : m;
          });
    };
    bool equal = true;
    for (std::size_t g = 0; g < job.goals.size() && equal; ++g) {
      const Property& a = j0.goals[g].property;
      const Property& b = job.goals[g].property;
      equal = a.kind == b.kind && a.horizon == b.horizon &&
              plain(a.predicate, components[c0]) == plain(b.predicate, components[c]);
    }
    if (equal) same = c0;
  }
  return same;
}

// Where one job's proof serves for another: the names of the first mapped to the second's
// (`rename`), component indices likewise (`component`), and how the proof is named in reasons.
struct SharedProof {
  std::function<std::string(const std::string&)> rename;
  std::map<int, int> component;
  std::string source;  // "instance A", "instances A, ctlA"
  std::string target;
  std::string why;  // ", an instance of the same automaton"
};

// Copies the results of job `from` to job `to` (which asks the same questions), each trace
// renamed and replayed for `to` (a trace that does not replay leaves the property `unknown`).
void CopyResults(const System& system, const Job& from, const Job& to, const SharedProof& how,
                 Clock::time_point start, std::vector<CheckResult>& results) {
  for (std::size_t g = 0; g < to.goals.size(); ++g) {
    const int src = from.goals[g].result;
    if (src < 0 || to.goals[g].result < 0) continue;
    std::vector<int> targets = to.goals[g].also;
    targets.insert(targets.begin(), to.goals[g].result);
    for (int dst : targets) {
      CheckResult r = results[src];
      r.property = results[dst].property;
      r.kind = results[dst].kind;
      if (r.trace) {
        Trace t = *r.trace;
        for (auto& [name, v] : t.parameters) name = how.rename(name);
        for (auto& [name, v] : t.initial_values) name = how.rename(name);
        for (auto& [component, index] : t.initial_states) {
          if (auto it = how.component.find(component); it != how.component.end()) {
            component = it->second;
          }
        }
        for (InputSignal& in : t.inputs.inputs) {
          const auto slot = system.symbols().Find(how.rename(system.symbols()[in.slot].name));
          if (slot) in.slot = *slot;
        }
        bool ok = false;
        try {
          ok = ReplayTrace(system, to.goals[g].original, t);
        } catch (const std::exception&) {
        }
        if (ok) {
          r.trace = std::move(t);
        } else {
          r.trace.reset();
          r.verdict = Verdict::kUnknown;
          r.reason = "the trace found for " + how.source + " does not replay for " + how.target;
        }
      }
      r.reason += " (the proof for " + how.source + how.why + ")";
      r.seconds = Since(start);
      results[dst] = std::move(r);
    }
  }
}

// Copies the results of component `same`'s job to component `c`'s (CopyResults).
void CopyShared(const System& system, const std::vector<Job>& jobs, int c, int same,
                Clock::time_point start, std::vector<CheckResult>& results) {
  const auto components = system.components();
  const std::string from = components[same].instance + ".", to = components[c].instance + ".";
  SharedProof how;
  how.rename = [from, to](const std::string& name) {
    return name.rfind(from, 0) == 0 ? to + name.substr(from.size()) : name;
  };
  how.component = {{same, c}};
  how.source = "instance " + components[same].instance;
  how.target = "instance " + components[c].instance;
  how.why = ", an instance of the same automaton";
  CopyResults(system, jobs[same], jobs[c], how, start, results);
}

// "A, ctlA"
std::string InstanceList(const System& system, const std::vector<int>& which) {
  std::string out;
  for (const int c : which) {
    out += (out.empty() ? "" : ", ") + system.components()[c].instance;
  }
  return out;
}

// How the proof for the product of components `a` serves for that of `b`, or nullopt: a[i] and
// b[i] must be named instances of one automaton (as set), bound alike up to the instance names.
std::optional<SharedProof> Corresponding(const System& system, const std::vector<int>& a,
                                         const std::vector<int>& b) {
  const auto components = system.components();
  if (a.size() != b.size() || a == b) return std::nullopt;
  std::map<std::string, std::string> prefixes;  // "A." -> "B."
  SharedProof how;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Component& ca = components[a[i]];
    const Component& cb = components[b[i]];
    if (ca.instance.empty() || cb.instance.empty() || !(ca.source == cb.source)) {
      return std::nullopt;
    }
    prefixes[ca.instance + "."] = cb.instance + ".";
    how.component[a[i]] = b[i];
  }
  how.rename = [prefixes](const std::string& name) {
    for (const auto& [from, to] : prefixes) {
      if (name.rfind(from, 0) == 0) return to + name.substr(from.size());
    }
    return name;
  };
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& binds_a = components[a[i]].binds;
    const auto& binds_b = components[b[i]].binds;
    if (binds_a.size() != binds_b.size()) return std::nullopt;
    for (const auto& [name, bound] : binds_a) {
      const auto it = binds_b.find(name);
      if (it == binds_b.end() || it->second != how.rename(bound)) return std::nullopt;
    }
  }
  how.source = "instances " + InstanceList(system, a);
  how.target = "instances " + InstanceList(system, b);
  how.why = ", instances of the same automata bound alike";
  return how;
}

// Whether jobs `x` and `y`, over products that correspond slot for slot, ask the same questions
// (compared by slot: their names differ by the instance names).
bool SameQuestions(const Job& x, const Job& y) {
  if (x.goals.size() != y.goals.size()) return false;
  auto by_slot = [](const Predicate& p) {
    return Remap(
        p,
        [](const Expression& e) {
          return e.Substitute([](const std::string&, int slot) -> std::optional<Expression> {
            return Expression::Symbol("s" + std::to_string(slot), slot);
          });
        },
        [](const std::string& m) { return m; });
  };
  for (std::size_t g = 0; g < x.goals.size(); ++g) {
    const Property& a = x.goals[g].property;
    const Property& b = y.goals[g].property;
    if (a.kind != b.kind || a.horizon != b.horizon ||
        !(by_slot(a.predicate) == by_slot(b.predicate))) {
      return false;
    }
  }
  return true;
}

}  // namespace

SolverBudget::SolverBudget(double seconds) : seconds_(seconds) {
  if (!(seconds > 0) || !(seconds <= 1e6)) {
    throw std::invalid_argument("the solver budget must be a number of budget seconds in (0, " +
                                std::string("1e6], not ") + FormatNumber(seconds));
  }
  total_ = static_cast<std::uint64_t>(
      std::ceil(seconds * static_cast<double>(kResourceUnitsPerBudgetSecond)));
  start_cpu_ = CpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
}

double SolverBudget::SafetySeconds() const { return std::max(60.0, 10.0 * seconds_); }

double SolverBudget::SafetyCpuSeconds(std::uint64_t units) const {
  const double seconds =
      10.0 * static_cast<double>(units) / static_cast<double>(kResourceUnitsPerBudgetSecond);
  return std::clamp(seconds, 10.0, SafetySeconds());
}

bool SolverBudget::SafetyExpired() const {
  return CpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - start_cpu_ > SafetySeconds();
}

double PropertyProver::BudgetSeconds() const {
  return options_.search_seconds > 0 ? options_.search_seconds : options_.budget;
}

std::vector<CheckResult> PropertyProver::Check(const System& system,
                                               std::span<const Property> properties) const {
  SolverBudget budget(BudgetSeconds());
  return Check(system, properties, budget);
}

std::vector<CheckResult> PropertyProver::Check(const System& system,
                                               std::span<const Property> properties,
                                               SolverBudget& budget) const {
  const Clock::time_point start = Clock::now();
  std::vector<CheckResult> results(properties.size());
  const auto components = system.components();
  std::vector<Job> jobs(components.size());
  ProductJobs products;
  PlanJobs(system, properties, options_.max_product_modes, results, jobs, products);
  std::vector<int> same(components.size(), -1);
  int runs = 0;  // jobs that need a check of their own
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    Job& job = jobs[c];
    if (job.goals.empty()) continue;
    job.automaton = &components[c].automaton;
    job.component = c;
    job.to_system = components[c].global_slot;
    AddLemmas(system, c, job);
    same[c] = SameInstance(system, jobs, c);
    if (same[c] < 0) ++runs;
  }
  // Product jobs whose proof another's serves for: (job, the earlier job, how).
  std::vector<std::tuple<const Job*, const Job*, SharedProof>> copies;
  std::set<const Job*> copied;
  for (auto& [which, pj] : products) {
    if (pj.job.goals.empty()) continue;
    pj.job.automaton = &*pj.automaton;
    for (const auto& [earlier, pe] : products) {
      if (earlier == which) break;
      if (pe.job.goals.empty() || copied.count(&pe.job)) continue;
      auto how = Corresponding(system, earlier, which);
      if (how && SameQuestions(pe.job, pj.job)) {
        copies.emplace_back(&pj.job, &pe.job, std::move(*how));
        copied.insert(&pj.job);
        break;
      }
    }
    if (!copied.count(&pj.job)) ++runs;
  }
  // Each job gets an equal share of what is left of the budget; what one leaves goes on.
  auto run = [&](const Job& job) {
    const std::uint64_t share = budget.remaining() / std::max(runs--, 1);
    JobRun(system, options_, budget, start, results, job, share).Go();
  };
  for (int c = 0; c < static_cast<int>(components.size()); ++c) {
    if (jobs[c].goals.empty()) continue;
    if (same[c] < 0) {
      run(jobs[c]);
    } else {
      CopyShared(system, jobs, c, same[c], start, results);
    }
  }
  for (const auto& [which, pj] : products) {
    if (!pj.job.goals.empty() && !copied.count(&pj.job)) run(pj.job);
  }
  for (const auto& [job, from, how] : copies) CopyResults(system, *from, *job, how, start, results);
  // The gate of every verdict that rests on a trace: a fresh replay.
  for (std::size_t i = 0; i < properties.size(); ++i) {
    ConfirmTrace(system, properties[i], results[i]);
  }
  return results;
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ReachableModes(const System& system,
                                                                             int component) const {
  SolverBudget budget(BudgetSeconds());
  return ReachableModes(system, component, budget);
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ReachableModes(
    const System& system, int component, SolverBudget& budget) const {
  const Component& comp = system.components()[component];
  std::vector<Property> queries;
  for (int m = 0; m < comp.automaton.num_modes(); ++m) {
    const std::string name = system.QualifiedModeName(component, ModeId(m));
    queries.push_back({"reach " + name, Property::Kind::kReach, Predicate::InMode(name), {}});
  }
  const std::vector<CheckResult> results = Check(system, queries, budget);
  std::vector<ModeReachability> out;
  for (int m = 0; m < comp.automaton.num_modes(); ++m) {
    const Mode& mode = comp.automaton.mode(ModeId(m));
    ModeReachability r;
    r.mode = system.QualifiedModeName(component, ModeId(m));
    for (const auto& [slot, value] : mode.discrete_values) {
      // The declared (unqualified) name: `source` has the same slots.
      r.discrete.emplace_back(comp.source.symbols()[slot].name, value);
    }
    r.verdict = results[m].verdict;
    r.reason = results[m].reason;
    r.trace = results[m].trace;
    out.push_back(std::move(r));
  }
  return out;
}

// Every property the model declares, over System slots: the system's own, then (for composed
// systems) each component's, named INSTANCE.NAME.
std::vector<Property> DeclaredProperties(const System& system) {
  std::vector<Property> out(system.properties().begin(), system.properties().end());
  for (std::size_t c = 0; c < system.components().size(); ++c) {
    const Component& comp = system.components()[c];
    if (comp.instance.empty()) continue;
    for (const Property& p : comp.automaton.properties()) {
      Property q = p;
      q.name = comp.instance + "." + p.name;
      std::function<Predicate(const Predicate&)> remap = [&](const Predicate& x) -> Predicate {
        switch (x.kind()) {
          case Predicate::Kind::kComparison: {
            auto sub = [&](const Expression& e) {
              return e.Substitute(
                  [&](const std::string& name, int slot) -> std::optional<Expression> {
                    return Expression::Symbol(name, comp.global_slot[slot]);
                  });
            };
            const Comparison& k = x.comparison();
            return Predicate::Compare({sub(k.lhs), k.relation, sub(k.rhs)});
          }
          case Predicate::Kind::kInMode: {
            auto id = comp.automaton.FindMode(x.mode());
            return Predicate::InMode(id ? system.QualifiedModeName(static_cast<int>(c), *id)
                                        : x.mode());
          }
          case Predicate::Kind::kNot:
            return Predicate::Not(remap(x.operands()[0]));
          case Predicate::Kind::kAnd:
            return Predicate::And(remap(x.operands()[0]), remap(x.operands()[1]));
          case Predicate::Kind::kOr:
            return Predicate::Or(remap(x.operands()[0]), remap(x.operands()[1]));
          default:
            return x;
        }
      };
      q.predicate = remap(p.predicate);
      out.push_back(std::move(q));
    }
  }
  return out;
}

}  // namespace hybrid
