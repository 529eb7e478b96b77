#include "solvers/verification/query_meter.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <utility>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/log.h"

namespace hybrid {

std::uint64_t StepUnits(const Automaton& automaton) {
  return kUnitsPerEncodedElement *
         static_cast<std::uint64_t>(automaton.num_modes() + automaton.num_transitions() + 1);
}

std::uint64_t PathUnits(const Automaton& automaton, int k, int m, bool one_move) {
  HYBRID_ASSERT(k >= 1 && m < automaton.num_modes(), "a path of at least one step, from a mode");
  HYBRID_ASSERT(!one_move || m >= 0, "one move is a move from a mode");
  std::uint64_t last =
      static_cast<std::uint64_t>(automaton.num_modes() + automaton.num_transitions() + 1);
  if (one_move) {
    last = 1;  // the flow or one transition
  } else if (m >= 0) {
    last = 1;
    for (const Transition& t : automaton.transitions()) last += t.source.value() == m ? 1 : 0;
  }
  const auto steps = static_cast<std::uint64_t>(std::max(k - 1, 0));
  return kUnitsPerEncodedElement *
         (static_cast<std::uint64_t>(k + 1) *
              static_cast<std::uint64_t>(automaton.num_modes() + 1) +
          steps *
              static_cast<std::uint64_t>(automaton.num_modes() + automaton.num_transitions() + 1) +
          last);
}

z3::solver MakeSolver(z3::context& ctx) {
  const z3::tactic pre = z3::tactic(ctx, "simplify") & z3::tactic(ctx, "propagate-values") &
                         z3::tactic(ctx, "solve-eqs");
  return (pre & z3::cond(z3::probe(ctx, "is-qflra"), z3::tactic(ctx, "qflra"),
                         z3::tactic(ctx, "qfnra-nlsat")))
      .mk_solver();
}

z3::solver MakeIncremental(z3::context& ctx) {
  z3::solver s(ctx);
  z3::params p(ctx);
  p.set("ignore_solver1", true);
  p.set("solver2_unknown", 0u);
  p.set("arith.nl.nra", false);
  s.set(p);
  return s;
}

void AddWithDefinitions(z3::solver& s, SmtEncoding& enc, const z3::expr& e) {
  s.add(e);
  s.add(enc.TakeDefinitions());
}

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

QueryMeter::QueryMeter(z3::context& ctx, SolverBudget& budget, QueryDump dump)
    : budget_(budget), dump_(std::move(dump)), ctx_(ctx), running_(&ctx), watchdog_([this] {
        running_.load()->interrupt();
      }) {
  HYBRID_ASSERT(dump_.directory.empty() || dump_.count != nullptr,
                "a dump directory comes with its file counter");
}

bool QueryMeter::Stopped(const z3::solver& s) const {
  for (const z3::solver& stopped : stopped_solvers_) {
    if (static_cast<Z3_solver>(stopped) == static_cast<Z3_solver>(s)) return true;
  }
  return false;
}

std::uint64_t QueryMeter::Allowed(unsigned cap, std::uint64_t ceiling) const {
  HYBRID_ASSERT(budget_.used() < ceiling, "a query runs only below its ceiling");
  // What is left, rounded down to a power of two when less than `cap`: setting a solver's
  // parameters costs time on a large incremental solver, so they change only when the
  // rounded value does.
  const std::uint64_t left = ceiling - budget_.used();
  std::uint64_t allowed = cap;
  if (left < cap) {
    allowed = 1;
    while (allowed * 2 <= left) allowed *= 2;
  }
  return allowed;
}

std::uint64_t QueryMeter::Allow(z3::solver& s, unsigned cap, std::uint64_t ceiling) {
  const std::uint64_t allowed = Allowed(cap, ceiling);
  const bool same =
      last_solver_ && static_cast<Z3_solver>(*last_solver_) == static_cast<Z3_solver>(s);
  if (!same || last_allowed_ != allowed) {
    z3::params p(s.ctx());
    p.set("rlimit", static_cast<unsigned>(allowed));
    s.set(p);
    last_solver_ = s;  // held, so that no other solver can take its address
    last_allowed_ = allowed;
  }
  return allowed;
}

void QueryMeter::DumpQuery(z3::solver& s, std::uint64_t allowed) {
  if (dump_.directory.empty()) return;
  const std::string path = dump_.directory + "/q" + std::to_string((*dump_.count)++) + ".smt2";
  std::ofstream out(path);
  out << "; rlimit " << allowed << "\n" << s.to_smt2();
  if (!out) Log(LogLevel::kWarning, "prove", "cannot write the query file " + path);
}

bool QueryMeter::MayRun(std::uint64_t ceiling, const std::string& what) {
  if (budget_.used() >= ceiling || budget_.SafetyExpired()) {
    ++starved_;
    if (LogEnabled(LogLevel::kDebug)) {
      Log(LogLevel::kDebug, "prove", "query (" + what + ") not run: budget spent");
    }
    return false;
  }
  if (LogEnabled(LogLevel::kDebug)) {
    Log(LogLevel::kDebug, "prove", "query start (" + what + ")");
  }
  return true;
}

void QueryMeter::Settle(z3::check_result r, std::uint64_t spent, std::uint64_t allowed,
                        unsigned cap, bool stopped, double seconds, const std::string& what) {
  if (stopped) {
    // Where the net stopped the query depends on the machine's speed; what it charges and
    // what follows on this solver must not: the whole allowance, and no further query.
    budget_.Charge(std::max<std::uint64_t>(spent, allowed));
    budget_.NoteSafetyStop();
  } else {
    budget_.Charge(spent);
  }
  if (r == z3::unknown && allowed < cap) ++starved_;
  if (LogEnabled(LogLevel::kInfo)) {
    std::ostringstream line;
    line << "query (" << what << "): " << r << ", " << spent << " units, " << seconds << " s";
    if (stopped) line << ", stopped by the CPU-time safety net";
    Log(LogLevel::kInfo, "prove", line.str());
  }
}

z3::check_result QueryMeter::Check(z3::solver& s, unsigned cap, std::uint64_t ceiling,
                                   const std::string& what) {
  HYBRID_ASSERT(cap > 0, "a query may use some resource units");
  if (!MayRun(ceiling, what) || Stopped(s)) return z3::unknown;
  // The CPU-time limit of the query comes from the units it may use (10 s per budget second, at
  // least 10 s): work Z3's count misses (a search query of the finger's modes spent 100 s on 1.8
  // million units) is cut there.
  const std::uint64_t allowed = Allow(s, cap, ceiling);
  DumpQuery(s, allowed);
  const auto t0 = std::chrono::steady_clock::now();
  watchdog_.Arm(budget_.SafetyCpuSeconds(allowed));
  z3::check_result r = s.check();
  const bool stopped = watchdog_.Disarm();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::uint64_t count = ResourceCount(s);
  const std::uint64_t spent = count > seen_ ? count - seen_ : 0;
  seen_ = std::max(seen_, count);
  if (stopped) {
    r = z3::unknown;
    stopped_solvers_.push_back(s);
  }
  Settle(r, spent, allowed, cap, stopped, seconds, what);
  return r;
}

z3::check_result QueryMeter::CheckApart(const z3::expr_vector& query, unsigned cap,
                                        std::uint64_t ceiling, const std::string& what,
                                        const std::vector<z3::expr>& watch,
                                        std::vector<bool>& holds, long group) {
  HYBRID_ASSERT(cap > 0, "a query may use some resource units");
  holds.clear();
  if (!MayRun(ceiling, what)) return z3::unknown;
  const std::uint64_t allowed = Allowed(cap, ceiling);
  if (!dump_.directory.empty()) {
    z3::solver dumped = MakeSolver(ctx_);
    for (const z3::expr& e : query) dumped.add(e);
    DumpQuery(dumped, allowed);
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (!apart_ || apart_group_ != group) {
    apart_ = std::make_unique<z3::context>();
    apart_group_ = group;
    apart_seen_ = 0;
  }
  bool stopped = false;
  std::uint64_t count = 0;
  z3::check_result r = SolveApart(query, allowed, watch, holds, stopped, count);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::uint64_t spent = count > apart_seen_ ? count - apart_seen_ : 0;
  apart_seen_ = std::max(apart_seen_, count);
  if (stopped) {
    r = z3::unknown;
    apart_.reset();  // its state depends on where the net stopped it: the next query gets another
  }
  Settle(r, spent, allowed, cap, stopped, seconds, what);
  return r;
}

z3::check_result QueryMeter::SolveApart(const z3::expr_vector& query, std::uint64_t allowed,
                                        const std::vector<z3::expr>& watch,
                                        std::vector<bool>& holds, bool& stopped,
                                        std::uint64_t& count) {
  z3::context& apart = *apart_;
  z3::solver solver = MakeSolver(apart);
  z3::params p(apart);
  p.set("rlimit", static_cast<unsigned>(allowed));
  solver.set(p);
  const auto translate = [&](const z3::expr& e) {
    return z3::expr(apart, Z3_translate(ctx_, e, apart));
  };
  for (const z3::expr& e : query) solver.add(translate(e));
  running_ = &apart;
  watchdog_.Arm(budget_.SafetyCpuSeconds(allowed));
  const z3::check_result r = solver.check();
  stopped = watchdog_.Disarm();
  running_ = &ctx_;
  if (r == z3::sat && !stopped) {
    const z3::model model = solver.get_model();
    for (const z3::expr& w : watch) holds.push_back(model.eval(translate(w), true).is_true());
  }
  count = ResourceCount(solver);
  return r;
}

bool QueryMeter::Afford(std::uint64_t units, std::uint64_t ceiling) {
  if (budget_.used() + units > ceiling || budget_.SafetyExpired()) {
    ++starved_;
    return false;
  }
  budget_.Charge(units);
  return true;
}

}  // namespace hybrid
