#include "solvers/verification/proof_run.h"

#include <algorithm>
#include <exception>
#include <random>
#include <utility>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/log.h"
#include "hybrid/checking/trace.h"
#include "solvers/verification/induction_round.h"

namespace hybrid {

namespace {

const Automaton& AutomatonOf(const ProofJob& job) {
  HYBRID_ASSERT(job.automaton != nullptr, "a job to run has its automaton");
  return *job.automaton;
}

}  // namespace

ProofRun::ProofRun(const System& system, const PropertyProver::Options& options,
                   SolverBudget& budget, std::chrono::steady_clock::time_point start,
                   std::vector<CheckResult>& results, const ProofJob& job, std::uint64_t share,
                   QueryDump dump)
    : system_(system),
      options_(options),
      budget_(budget),
      start_(start),
      results_(results),
      job_(job),
      a_(AutomatonOf(job)),
      enc_(ctx_, a_),
      meter_(ctx_, budget, std::move(dump)),
      bmc_(MakeIncremental(ctx_)),
      traces_(system, job, enc_),
      first_(budget.used()),
      share_(share) {}

void ProofRun::Run() {
  HYBRID_ASSERT(cands_.empty(), "a proof run runs once");
  // The candidates are not added to or removed from after this: rounds of induction point at
  // them.
  for (const ProofGoal& g : job_.goals) cands_.push_back(ProofCandidate::Of(g));
  BaseCase();
  Induction();
  DeepSearch();
  NoteRefuted();
  UnreachableTargets();
  Conclude();
}

// 1. Base case: no violation on paths of fewer than max_induction steps (what k-induction
//    needs, whatever max_depth is). Bounded model checking uses Z3's default (incremental)
//    solver, which handles long unrollings better than nlsat.
void ProofRun::BaseCase() {
  AddWithDefinitions(bmc_, enc_, enc_.Initial());
  AddWithDefinitions(bmc_, enc_, enc_.State(0));
  const int starved = meter_.starved();
  for (int n = 0; n < options_.max_induction; ++n) Search(n, true, {true, false}, Ceiling(0.5));
  base_complete_ = bmc_complete_;
  proof_cut_ = meter_.starved() > starved;
}

// 2. k-induction with Houdini over the surviving invariants (InductionRound), while the base
//    case covers the paths k needs.
void ProofRun::Induction() {
  const int before_induction = meter_.starved();
  for (int k = 1; k <= options_.max_induction && Open() && base_complete_; ++k) {
    std::vector<ProofCandidate*> set;
    for (ProofCandidate& c : cands_) {
      if (c.invariant && !c.refuted && !c.decided) set.push_back(&c);
    }
    InductionRound round(enc_, meter_, options_.resource_limit, k, std::move(set), Ceiling(0.5));
    round.Run();
    proof_cut_ = proof_cut_ || round.cut();
    DecideInductive(k, round.Inductive());
  }
  proof_cut_ = proof_cut_ || meter_.starved() > before_induction;
}

void ProofRun::DecideInductive(int k, const std::vector<ProofCandidate*>& inductive) {
  const std::size_t lemmas = inductive.size();
  for (ProofCandidate* c : inductive) {
    Decide(*c, Verdict::kProved,
           "proved by " + std::to_string(k) + "-induction, together with " +
               std::to_string(lemmas - 1) + " other invariant(s) as lemmas");
    c->proved = true;
  }
}

// After the search: a candidate the encoding refutes without a path that replays.
void ProofRun::NoteRefuted() {
  for (ProofCandidate& c : cands_) {
    if (!c.decided && c.refuted) {
      Decide(c, Verdict::kUnknown,
             "the encoding (an over-approximation) reaches a violation, but no path of at most " +
                 std::to_string(options_.max_depth) + " steps found replays in the simulator");
    }
  }
}

// 4. Reach targets without a witness: unreachable if no initial state is in them and their
//    negations are 1-inductive together, relative to the proved invariants (Houdini, as the
//    induction: a target entered only from other unreachable targets is proved with them).
void ProofRun::UnreachableTargets() {
  std::vector<ProofCandidate*> targets;  // of the negations, in order
  std::vector<ProofCandidate> negations;
  for (ProofCandidate& c : cands_) {
    if (c.decided || c.invariant || c.goal->result < 0) continue;
    const int starved = meter_.starved();
    if (InitiallyOutside(c)) {
      targets.push_back(&c);
      negations.push_back({c.goal, c.bad, true});
    }
    unreach_cut_ = unreach_cut_ || meter_.starved() > starved;
  }
  if (negations.empty()) return;
  std::vector<ProofCandidate*> set;
  for (ProofCandidate& n : negations) set.push_back(&n);
  std::vector<const ProofCandidate*> lemmas;
  for (const ProofCandidate& c : cands_) {
    if (c.invariant && c.proved) lemmas.push_back(&c);
  }
  const int starved = meter_.starved();
  InductionRound round(enc_, meter_, options_.resource_limit, 1, std::move(set), Ceiling(1.0),
                       std::move(lemmas));
  round.Run();
  unreach_cut_ = unreach_cut_ || round.cut() || meter_.starved() > starved;
  const std::vector<ProofCandidate*> inductive = round.Inductive();
  const std::string others = std::to_string(inductive.size() - 1);
  for (const ProofCandidate* n : inductive) {
    Decide(*targets[static_cast<std::size_t>(n - negations.data())], Verdict::kUnreachable,
           "proved by 1-induction of its negation, together with the negations of " + others +
               " other unreachable target(s) and with the proved invariants as lemmas");
  }
}

// No initial state of the job is in `reach` target `c`.
bool ProofRun::InitiallyOutside(const ProofCandidate& c) {
  const std::uint64_t ceiling = Ceiling(1.0);
  if (!meter_.Afford(StepUnits(a_), ceiling)) return false;
  z3::solver base = MakeSolver(ctx_);
  AddWithDefinitions(base, enc_, enc_.Initial() && enc_.State(0) && enc_.Holds(c.bad, 0, 0.0));
  return meter_.Check(base, options_.resource_limit, ceiling, "unreachability, initial") ==
         z3::unsat;
}

bool ProofRun::Open() const {
  for (const ProofCandidate& c : cands_) {
    if (!c.decided && c.goal->result >= 0) return true;
  }
  return false;
}

void ProofRun::Decide(ProofCandidate& c, Verdict v, std::string reason,
                      std::optional<Trace> trace) {
  HYBRID_ASSERT(!c.decided, "a goal is decided once");
  c.decided = true;
  if (c.goal->result < 0) return;
  std::vector<int> targets = c.goal->also;
  targets.insert(targets.begin(), c.goal->result);
  for (int index : targets) {
    HYBRID_ASSERT(index >= 0 && index < static_cast<int>(results_.size()),
                  "a goal's result is one of the Check's");
    CheckResult& r = results_[index];
    r.verdict = v;
    r.reason = reason;
    r.trace = trace;
    r.seconds = SecondsSince(start_);
  }
}

bool ProofRun::TryTrace(const z3::model& model, int depth, ProofCandidate& c) {
  const auto path = enc_.ReadPath(model, depth);
  std::optional<Trace> trace = traces_.Build(model, path);
  if (!trace) return false;
  return ReplayPath(path, c, std::move(*trace));
}

bool ProofRun::ReplayPath(const std::vector<SmtEncoding::PathStep>& path, ProofCandidate& c,
                          Trace trace) {
  const int depth = static_cast<int>(path.size()) - 1;
  HYBRID_ASSERT(c.Pending(), "only a pending candidate's path is replayed");
  ++c.replays;
  bool replayed = false;
  try {
    replayed = ReplayTrace(system_, c.goal->original, trace);
  } catch (const std::exception& e) {
    Log(LogLevel::kDebug, "prove", std::string("the replay failed: ") + e.what());
  }
  if (!replayed) {
    if (LogEnabled(LogLevel::kDebug)) {
      Log(LogLevel::kDebug, "prove",
          "a path of " + std::to_string(depth) + " steps for " + c.goal->property.name +
              " does not replay:");
      for (const std::string& line : DescribePath(a_, path, trace.parameters)) {
        Log(LogLevel::kDebug, "prove", line);
      }
    }
    std::optional<Trace> moved = OffTie(c, trace);
    if (!moved) return false;
    Decide(c, c.invariant ? Verdict::kViolated : Verdict::kReachable,
           std::string(c.invariant ? "counterexample" : "witness") + " near a path of " +
               std::to_string(depth) +
               " steps found by bounded model checking (its parameters moved off a tie between "
               "events), replayed by the simulator",
           std::move(*moved));
    return true;
  }
  Decide(c, c.invariant ? Verdict::kViolated : Verdict::kReachable,
         std::string(c.invariant ? "counterexample" : "witness") + " of " + std::to_string(depth) +
             " steps found by bounded model checking, replayed by the simulator",
         std::move(trace));
  return true;
}

// A path whose events fall at one instant for its parameter values (a tie: gob1 = gob2 = 140)
// need not replay: the simulator breaks ties by declaration order, the path may not. The trace
// again with its uncertain parameters moved off the tie, each by a random fraction of its range
// (up to 1/64, kOffTieTries tries from a fixed seed: the same on every run) within the range,
// and its horizon 10% longer for the events moved later.
std::optional<Trace> ProofRun::OffTie(const ProofCandidate& c, const Trace& trace) {
  if (trace.parameters.empty()) return std::nullopt;
  const std::vector<UncertainParameter> uncertain = UncertainParameters(system_);
  std::vector<UncertainParameter> ranges;
  for (const auto& [name, value] : trace.parameters) {
    for (const UncertainParameter& u : uncertain) {
      if (u.name == name) ranges.push_back(u);
    }
  }
  if (ranges.size() != trace.parameters.size()) return std::nullopt;
  std::mt19937_64 bits(0x6A09E667F3BCC909ull + static_cast<std::uint64_t>(c.replays));
  for (int attempt = 0; attempt < kOffTieTries; ++attempt) {
    Trace moved = trace;
    moved.inputs.until *= 1.1;
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      const double unit = static_cast<double>(bits() >> 11) * 0x1.0p-53;  // in [0, 1)
      const double width = ranges[i].hi - ranges[i].lo;
      double& value = moved.parameters[i].second;
      value = std::clamp(value + (2.0 * unit - 1.0) * width / 64.0, ranges[i].lo, ranges[i].hi);
    }
    try {
      if (ReplayTrace(system_, c.goal->original, moved)) return moved;
    } catch (const std::exception& e) {
      Log(LogLevel::kDebug, "prove", std::string("the replay failed: ") + e.what());
    }
  }
  return std::nullopt;
}

bool ProofRun::Extend(int n, std::uint64_t ceiling) {
  while (bmc_depth_ < n) {
    if (bmc_depth_ >= 0 && !meter_.Afford(StepUnits(a_), ceiling)) return false;
    ++bmc_depth_;
    if (bmc_depth_ > 0) {
      AddWithDefinitions(bmc_, enc_, enc_.Transition(bmc_depth_ - 1));
      AddWithDefinitions(bmc_, enc_, enc_.State(bmc_depth_));
    }
  }
  return true;
}

z3::expr ProofRun::Bad(const ProofCandidate& c, int n, double margin) {
  return c.invariant ? !enc_.Holds(Predicate::Not(c.bad), n, margin) : enc_.Holds(c.bad, n, 0.0);
}

// Paths of exactly n steps: parameters at their nominal values first (fewer ties between
// events, which the simulator breaks by declaration order), then over their ranges. Per pass, one
// query for the candidates not yet tried: unsat settles them all; a model names those it breaks
// (or reaches), which are tried alone (One) and the rest asked again; a query that runs out
// leaves every remaining candidate to One.
void ProofRun::Search(int n, bool invariants_only, std::initializer_list<bool> passes,
                      std::uint64_t ceiling) {
  if (!Extend(n, ceiling)) {
    bmc_complete_ = false;
    return;
  }
  auto wanted = [&](const ProofCandidate& c) {
    // Lemmas need no counterexample of their own beyond the base case.
    return c.Pending() && (!invariants_only || c.invariant) && !(deep_ && c.goal->result < 0);
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
      AddWithDefinitions(bmc_, enc_, z3::mk_or(any));
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

// ProofCandidate `c` alone on paths of exactly n steps: robust violations first (they replay clear
// of rounding), then exact ones; a path found is replayed (TryTrace).
void ProofRun::One(ProofCandidate& c, int n, bool pinned, std::uint64_t ceiling) {
  for (double margin : {options_.robust_margin, 0.0}) {
    if (!c.Pending() || (!c.invariant && margin > 0)) continue;
    bmc_.push();
    AddWithDefinitions(bmc_, enc_, Bad(c, n, margin));
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

// Counterexamples and witnesses for what is still open, up to max_depth steps. Search order:
// short paths with nominal and with free parameters; then longer paths with nominal parameters
// (cheap: fewer branches; at most 40% of this phase); then longer paths with every parameter
// value (the search space grows fast with the depth).
void ProofRun::DeepSearch() {
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

void ProofRun::Conclude() {
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
  for (ProofCandidate& c : cands_) {
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

}  // namespace hybrid
