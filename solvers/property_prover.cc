#include "solvers/property_prover.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <set>
#include <stdexcept>

#include "solvers/smt_encoding.h"

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

// The solver for every query: Z3's nlsat (complete for polynomial real arithmetic, with Boolean
// structure), which handles the separable (nonlinear) flows far better than the default core.
// Limits are Z3 resource units (`rlimit`), not seconds, so that verdicts do not depend on the
// machine's load; about 2.5 million units per second on the development machine.
z3::solver MakeSolver(z3::context& ctx, unsigned resource_limit) {
  z3::solver s = z3::tactic(ctx, "qfnra-nlsat").mk_solver();
  z3::params p(ctx);
  p.set("rlimit", resource_limit);
  p.set("timeout", 10000u);  // a safety net: the resource limit is the intended bound
  s.set(p);
  return s;
}

// Asserts `e` and the definitions of the auxiliary variables it introduced.
void Add(z3::solver& s, SmtEncoding& enc, const z3::expr& e) {
  s.add(e);
  s.add(enc.TakeDefinitions());
}

class Engine {
 public:
  Engine(const System& system, const PropertyProver::Options& options, Clock::time_point start,
         std::vector<CheckResult>& results)
      : system_(system), options_(options), start_(start), results_(results) {}

  void Run(const Job& job);

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

  bool TryTrace(const Job& job, SmtEncoding& enc, const z3::model& model, int depth, Candidate& c);
  void Decide(const Candidate& c, Verdict v, std::string reason, std::optional<Trace> trace = {});

  const System& system_;
  const PropertyProver::Options& options_;
  Clock::time_point start_;
  std::vector<CheckResult>& results_;
};

void Engine::Decide(const Candidate& c, Verdict v, std::string reason, std::optional<Trace> trace) {
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

bool Engine::TryTrace(const Job& job, SmtEncoding& enc, const z3::model& model, int depth,
                      Candidate& c) {
  const Automaton& a = *job.automaton;
  const auto path = enc.ReadPath(model, depth);
  Trace trace;
  trace.parameters = enc.ReadParameters(model);
  // Initial values where the model's initial state is a box.
  for (const InitialState& init : a.initial_states()) {
    if (init.mode.value() != path[0].mode) continue;
    for (const InitialValue& iv : init.values) {
      if (iv.is_point) continue;
      int index = 0;
      for (const VariableInfo& v : a.variables()) {
        if (v.slot == iv.slot) break;
        ++index;
      }
      trace.initial_values.emplace_back(system_.symbols()[job.to_system[iv.slot]].name,
                                        path[0].x[index]);
    }
  }
  // The input schedule: one step piece per flow segment of positive duration.
  const int ni = static_cast<int>(a.inputs().size());
  std::vector<InputSignal> signals(ni);
  double t = 0.0;
  for (int i = 0; i < ni; ++i) {
    signals[i].slot = job.to_system[a.inputs()[i].slot];
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
  for (int k = 0; k < depth; ++k) {
    if (path[k].flow && path[k].duration > 0) add_piece(path[k].input, path[k].duration);
  }
  // A short tail with the last input held, so that events due exactly at the end of the path
  // happen (an input that changed there would decide them instead).
  std::vector<double> last(ni, 0.0);
  for (int k = depth - 1; k >= 0; --k) {
    if (path[k].flow && path[k].duration > 0) {
      last = path[k].input;
      break;
    }
  }
  const double tail = std::max(1e-6, 1e-6 * t);
  add_piece(last, tail);
  trace.inputs.until = t;
  for (auto& s : signals) {
    if (s.points.empty()) s.points.emplace_back(0.0, 0.0);
    trace.inputs.inputs.push_back(s);
  }
  ++c.replays;
  bool replayed = false;
  try {
    replayed = ReplayTrace(system_, c.goal->original, trace);
  } catch (const std::exception&) {
  }
  if (!replayed) {
    if (std::getenv("HYBRID_CHECK_DEBUG")) {
      std::cerr << "path of " << depth << " steps for " << c.goal->property.name
                << " does not replay:\n";
      DebugPath(enc, model, depth);
    }
    return false;
  }
  Decide(c, c.invariant ? Verdict::kViolated : Verdict::kReachable,
         std::string(c.invariant ? "counterexample" : "witness") + " of " + std::to_string(depth) +
             " steps found by bounded model checking, replayed by " + "the simulator",
         std::move(trace));
  c.decided = true;
  return true;
}

void Engine::Run(const Job& job) {
  const Automaton& a = *job.automaton;
  z3::context ctx;
  SmtEncoding enc(ctx, a);
  std::vector<Candidate> cands;
  for (const Goal& g : job.goals) {
    const Property& p = g.property;
    switch (p.kind) {
      case Property::Kind::kAlways:
        cands.push_back({&g, Predicate::Not(p.predicate), true});
        break;
      case Property::Kind::kNever:
        cands.push_back({&g, p.predicate, true});
        break;
      case Property::Kind::kReach:
        cands.push_back({&g, p.predicate, false});
        break;
    }
  }
  // Bounded properties are checked like unbounded ones (sound for `proved`); their traces are
  // replayed with the horizon.
  auto pending = [&](const Candidate& c) { return !c.decided && c.replays < 8; };

  // 1. Base case: no violation within max_induction - 1 steps (what k-induction needs).
  // Bounded model checking: Z3's default (incremental) solver, which handles long unrollings
  // better than nlsat.
  z3::solver bmc(ctx);
  {
    z3::params p(ctx);
    p.set("rlimit", options_.resource_limit);
    p.set("timeout", 10000u);  // a safety net: not every engine honours the resource limit
    bmc.set(p);
  }
  Add(bmc, enc, enc.Initial());
  Add(bmc, enc, enc.State(0));
  bool bmc_complete = true;
  std::string budget_note;
  int bmc_depth = -1;  // paths up to this length are in `bmc`
  // The budget of the deep search (step 3): checked before every query.
  std::optional<Clock::time_point> deep_start;
  auto over_budget = [&]() { return deep_start && Since(*deep_start) > options_.search_seconds; };
  auto search = [&](int n, bool invariants_only, std::initializer_list<bool> passes) {
    while (bmc_depth < n) {
      ++bmc_depth;
      if (bmc_depth > 0) {
        Add(bmc, enc, enc.Transition(bmc_depth - 1));
        Add(bmc, enc, enc.State(bmc_depth));
      }
    }
    // Parameters at their nominal values first (fewer ties between events, which the simulator
    // breaks by declaration order), then over their ranges; per pass, one query for all
    // candidates, then one per candidate (robust violations first: they replay clear of
    // rounding; then exact ones).
    for (bool pinned : passes) {
      if (pinned && enc.uncertain().empty()) continue;
      z3::expr_vector any(ctx);
      for (Candidate& c : cands) {
        if (!pending(c) || (invariants_only && !c.invariant)) continue;
        // Lemmas need no counterexample of their own beyond the base case.
        if (deep_start && c.goal->result < 0) continue;
        any.push_back(c.invariant ? !enc.Holds(Predicate::Not(c.bad), n, 0.0)
                                  : enc.Holds(c.bad, n, 0.0));
      }
      if (any.empty()) return;
      bmc.push();
      Add(bmc, enc, z3::mk_or(any));
      if (pinned) bmc.add(enc.NominalParameters());
      const auto t_query = Clock::now();
      const z3::check_result r = bmc.check();
      bmc.pop();
      if (std::getenv("HYBRID_CHECK_TIMING")) {
        std::cerr << "bmc depth " << n << (pinned ? " pinned: " : " free: ") << r << " "
                  << Since(t_query) << " s\n";
      }
      if (r == z3::unknown && !pinned) bmc_complete = false;
      if (r == z3::unsat) continue;
      for (Candidate& c : cands) {
        if (!pending(c) || (invariants_only && !c.invariant)) continue;
        if (deep_start && c.goal->result < 0) continue;
        for (double margin : {options_.robust_margin, 0.0}) {
          if (!pending(c) || (!c.invariant && margin > 0) || over_budget()) continue;
          bmc.push();
          Add(bmc, enc,
              c.invariant ? !enc.Holds(Predicate::Not(c.bad), n, margin)
                          : enc.Holds(c.bad, n, 0.0));
          if (pinned) bmc.add(enc.NominalParameters());
          const z3::check_result rc = bmc.check();
          if (rc == z3::sat) {
            c.refuted = c.refuted || c.invariant;
            const z3::model model = bmc.get_model();
            TryTrace(job, enc, model, n, c);
          } else if (rc == z3::unknown && !pinned) {
            bmc_complete = false;
          }
          bmc.pop();
          if (rc == z3::sat) break;
        }
      }
    }
  };
  for (int n = 0; n < options_.max_induction && n <= options_.max_depth; ++n) {
    search(n, true, {true, false});
  }
  const bool base_complete = bmc_complete;

  // 2. k-induction with Houdini over the surviving invariants (and negated reach targets).
  auto open = [&]() {
    for (const Candidate& c : cands) {
      if (!c.decided && c.goal->result >= 0) return true;
    }
    return false;
  };
  for (int k = 1; k <= options_.max_induction && open() && base_complete; ++k) {
    std::vector<Candidate*> set;
    for (Candidate& c : cands) {
      if (c.invariant && !c.refuted && !c.decided) set.push_back(&c);
    }
    // The step query is split on the mode of s_(k-1): one small nonlinear problem per mode is
    // far easier for nlsat than their disjunction. Per mode, all candidates are checked at once;
    // a model names the ones that fail (dropped, Houdini), a timeout splits per candidate.
    std::vector<bool> alive(set.size(), true);
    std::vector<std::optional<z3::expr>> path_from(a.num_modes());
    std::optional<z3::expr> hypotheses;  // of the alive candidates
    bool changed = true;
    while (changed) {
      changed = false;
      hypotheses.reset();
      for (int m = 0; m < a.num_modes(); ++m) {
        auto check = [&](const std::vector<std::size_t>& goals, unsigned resource_limit,
                         std::vector<std::size_t>& failed) {
          z3::solver s = MakeSolver(ctx, resource_limit);
          if (!path_from[m]) {
            z3::expr e = ctx.bool_val(true);
            for (int i = 0; i <= k; ++i) e = e && enc.State(i);
            for (int i = 0; i + 1 < k; ++i) e = e && enc.Transition(i);
            e = e && enc.TransitionFrom(k - 1, ModeId(m));
            path_from[m] = e && enc.TakeDefinitions();
          }
          s.add(*path_from[m]);
          if (!hypotheses) {
            z3::expr e = ctx.bool_val(true);
            for (std::size_t j = 0; j < set.size(); ++j) {
              if (!alive[j]) continue;
              for (int i = 0; i < k; ++i) e = e && !enc.Holds(set[j]->bad, i, 0.0);
            }
            hypotheses = e && enc.TakeDefinitions();
          }
          s.add(*hypotheses);
          z3::expr_vector bad(ctx);
          std::vector<z3::expr> at_k;
          for (std::size_t j : goals) {
            at_k.push_back(enc.Holds(set[j]->bad, k, 0.0));
            bad.push_back(at_k.back());
          }
          Add(s, enc, z3::mk_or(bad));
          const z3::check_result r = s.check();
          if (r == z3::sat) {
            const z3::model model = s.get_model();
            for (std::size_t g = 0; g < goals.size(); ++g) {
              if (model.eval(at_k[g], true).is_true()) failed.push_back(goals[g]);
            }
            if (std::getenv("HYBRID_CHECK_DEBUG")) {
              std::cerr << "induction k=" << k << " from mode " << a.modes()[m].name
                        << " fails for";
              for (std::size_t j : failed) std::cerr << " " << set[j]->goal->property.name;
              std::cerr << ":\n";
              DebugPath(enc, model, k);
            }
            if (failed.empty()) failed = goals;  // cannot tell which: drop all (sound)
          }
          return r;
        };
        std::vector<std::size_t> goals, failed;
        for (std::size_t j = 0; j < set.size(); ++j) {
          if (alive[j]) goals.push_back(j);
        }
        if (goals.empty()) break;
        const auto t_mode = Clock::now();
        z3::check_result r = check(goals, options_.resource_limit / 25, failed);
        if (std::getenv("HYBRID_CHECK_TIMING")) {
          std::cerr << "k=" << k << " mode " << a.modes()[m].name << ": " << r << " "
                    << Since(t_mode) << " s\n";
        }
        (void)t_mode;
        if (r == z3::unknown) {
          // Split per candidate with the full time budget.
          for (std::size_t j : goals) {
            std::vector<std::size_t> f;
            const z3::check_result rj = check({j}, options_.resource_limit / 5, f);
            if (rj == z3::unknown) f.push_back(j);
            for (std::size_t x : f) failed.push_back(x);
          }
        }
        for (std::size_t j : failed) {
          if (alive[j]) {
            alive[j] = false;
            changed = true;
            hypotheses.reset();  // weaker now: modes already passed are checked again
          }
        }
      }
    }
    std::size_t lemmas = 0;
    for (std::size_t j = 0; j < set.size(); ++j) lemmas += alive[j] ? 1 : 0;
    for (std::size_t j = 0; j < set.size(); ++j) {
      if (!alive[j]) continue;
      Candidate& c = *set[j];
      const std::string how = std::to_string(k) + "-induction, together with " +
                              std::to_string(lemmas - 1) + " other invariant(s) as lemmas";
      Decide(c, Verdict::kProved, "proved by " + how);
      c.decided = true;
      c.proved = true;
    }
  }

  // 3. Counterexamples and witnesses for what is still open, up to max_depth steps.
  // Search order: short paths with nominal and with free parameters; then longer paths with
  // nominal parameters (cheap: fewer branches; at most 40% of the budget); then longer paths with
  // every parameter value (the search space grows fast with the depth).
  const Clock::time_point bmc_start = Clock::now();
  deep_start = bmc_start;
  const int shallow = std::min(options_.max_depth, 3);
  struct Pass {
    int from, to;
    std::initializer_list<bool> pinned;
    double budget_fraction;
  };
  const Pass passes[] = {{0, shallow, {true, false}, 1.0},
                         {shallow + 1, options_.max_depth, {true}, 0.4},
                         {shallow + 1, options_.max_depth, {false}, 1.0}};
  int searched = -1;
  for (const Pass& pass : passes) {
    const bool pinned_only = pass.pinned.size() == 1 && *pass.pinned.begin();
    if (pinned_only && enc.uncertain().empty()) continue;  // the next pass covers it
    for (int n = pass.from; n <= pass.to && open(); ++n) {
      if (Since(bmc_start) > options_.search_seconds * pass.budget_fraction) {
        if (pass.budget_fraction < 1.0) break;  // on to the next pass
        bmc_complete = false;
        budget_note =
            "the search budget of " + FormatNumber(options_.search_seconds) + " s ran out" +
            (searched >= 0 ? " after paths of " + std::to_string(searched) + " steps" : "") + "; ";
        break;
      }
      if (enc.uncertain().empty()) {
        search(n, false, {false});
      } else {
        search(n, false, pass.pinned);
      }
      if (!pinned_only) searched = n;
    }
    if (!budget_note.empty()) break;
  }
  for (Candidate& c : cands) {
    if (!c.decided && c.refuted) {
      Decide(c, Verdict::kUnknown,
             "the encoding (an over-approximation) reaches a violation, but no path of at most " +
                 std::to_string(options_.max_depth) + " steps found replays in the simulator");
      c.decided = true;
    }
  }
  // 4. Reach targets without a witness: unreachable if `not P` is inductive relative to the
  //    proved invariants (checked per mode, as above).
  for (Candidate& c : cands) {
    if (c.decided || c.invariant || !base_complete) continue;
    bool inductive = true;
    for (int m = 0; m < a.num_modes() && inductive; ++m) {
      z3::solver s = MakeSolver(ctx, options_.resource_limit);
      z3::expr e = enc.State(0) && enc.State(1) && enc.TransitionFrom(0, ModeId(m)) &&
                   !enc.Holds(c.bad, 0, 0.0) && enc.Holds(c.bad, 1, 0.0);
      for (const Candidate& lemma : cands) {
        if (lemma.invariant && lemma.decided && !lemma.refuted && lemma.proved) {
          e = e && !enc.Holds(lemma.bad, 0, 0.0);
        }
      }
      Add(s, enc, e);
      inductive = s.check() == z3::unsat;
    }
    if (inductive) {
      Decide(c, Verdict::kUnreachable,
             "proved by 1-induction of its negation, with the proved invariants as lemmas");
      c.decided = true;
    }
  }
  for (Candidate& c : cands) {
    if (c.decided) continue;
    std::string why = !budget_note.empty() ? budget_note
                      : bmc_complete       ? ""
                                           : "an SMT query timed out; ";
    const std::string within =
        budget_note.empty() ? " within " + std::to_string(options_.max_depth) + " steps" : "";
    if (c.invariant) {
      why += "not proved by k-induction for k <= " + std::to_string(options_.max_induction) +
             " and no counterexample" + within;
    } else {
      why += "no witness" + within + " that replays, and unreachability not proved by induction";
    }
    Decide(c, Verdict::kUnknown, why);
  }
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

std::vector<CheckResult> PropertyProver::Check(const System& system,
                                               std::span<const Property> properties) const {
  const Clock::time_point start = Clock::now();
  std::vector<CheckResult> results(properties.size());
  const auto components = system.components();
  // Which components write each System slot (continuous variables).
  std::vector<std::vector<int>> owners(system.symbols().size());
  for (std::size_t c = 0; c < components.size(); ++c) {
    for (const VariableInfo& v : components[c].automaton.variables()) {
      owners[components[c].global_slot[v.slot]].push_back(static_cast<int>(c));
    }
  }
  std::vector<Job> jobs(components.size());
  std::optional<Automaton> product;
  Job product_job;
  for (std::size_t i = 0; i < properties.size(); ++i) {
    const Property& p = properties[i];
    results[i].property = p.name;
    results[i].kind = p.kind;
    results[i].method = "prove";
    std::set<int> slots;
    std::set<std::string> modes;
    Collect(p.predicate, slots, modes);
    std::set<int> comps;
    for (int s : slots) {
      const SymbolKind kind = system.symbols()[s].kind;
      if (kind == SymbolKind::kInput) {
        throw std::invalid_argument("PropertyProver::Check: property '" + p.name +
                                    "' reads input '" + system.symbols()[s].name + "'");
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
    if (comps.empty()) comps.insert(0);
    bool alone = comps.size() == 1;
    if (alone) {
      const int c = *comps.begin();
      for (const VariableInfo& v : components[c].automaton.variables()) {
        if (owners[components[c].global_slot[v.slot]].size() > 1) alone = false;
      }
    }
    if (alone) {
      const int c = *comps.begin();
      const Component& comp = components[c];
      std::vector<int> local(system.symbols().size(), -1);
      for (std::size_t s = 0; s < comp.global_slot.size(); ++s) {
        local[comp.global_slot[s]] = static_cast<int>(s);
      }
      Property q = p;
      q.predicate = Remap(
          p.predicate,
          [&](const Expression& e) {
            return e.Substitute(
                [&](const std::string& name, int slot) -> std::optional<Expression> {
                  return Expression::Symbol(name, local.at(slot));
                });
          },
          [&](const std::string& m) {
            auto found = system.FindMode(m);
            return found ? comp.automaton.mode(found->second).name : m;
          });
      bool same = false;
      for (Goal& g : jobs[c].goals) {
        if (g.property.kind == q.kind && g.property.predicate == q.predicate &&
            g.property.horizon == q.horizon) {
          g.also.push_back(static_cast<int>(i));
          same = true;
          break;
        }
      }
      if (!same) jobs[c].goals.push_back({q, static_cast<int>(i), p, {}});
      continue;
    }
    if (!product) {
      try {
        product = system.Product(options_.max_product_modes);
      } catch (const std::invalid_argument& e) {
        results[i].verdict = Verdict::kUnknown;
        results[i].reason = std::string(
                                "the property reads several components and their "
                                "product is too large: ") +
                            e.what();
        continue;
      }
    }
    if (!modes.empty()) {
      results[i].verdict = Verdict::kUnknown;
      results[i].reason = "`in MODE` atoms over several components are not supported";
      continue;
    }
    product_job.goals.push_back({p, static_cast<int>(i), p, {}});
  }
  Engine engine(system, options_, start, results);
  for (std::size_t c = 0; c < components.size(); ++c) {
    Job& job = jobs[c];
    if (job.goals.empty()) continue;
    job.automaton = &components[c].automaton;
    job.to_system = components[c].global_slot;
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
            return e.Substitute(
                [&](const std::string& name, int slot) -> std::optional<Expression> {
                  return Expression::Symbol(name, components[c].global_slot[slot]);
                });
          },
          [&](const std::string& m) {
            auto id = components[c].automaton.FindMode(m);
            return id ? system.QualifiedModeName(static_cast<int>(c), *id) : m;
          });
      job.goals.push_back({lemma, -1, original, {}});
    }
    // Instances of one automaton asked the same questions share the proof: only traces are
    // carried over (renamed) and replayed for this instance.
    int same = -1;
    for (std::size_t c0 = 0; c0 < c && same < 0; ++c0) {
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
      if (equal) same = static_cast<int>(c0);
    }
    if (same < 0) {
      engine.Run(job);
      continue;
    }
    const std::string from = components[same].instance + ".", to = components[c].instance + ".";
    auto rename = [&](const std::string& name) {
      return name.rfind(from, 0) == 0 ? to + name.substr(from.size()) : name;
    };
    for (std::size_t g = 0; g < job.goals.size(); ++g) {
      const int src = jobs[same].goals[g].result;
      if (src < 0 || job.goals[g].result < 0) continue;
      std::vector<int> targets = job.goals[g].also;
      targets.insert(targets.begin(), job.goals[g].result);
      for (int dst : targets) {
        CheckResult r = results[src];
        r.property = results[dst].property;
        r.kind = results[dst].kind;
        if (r.trace) {
          Trace t = *r.trace;
          for (auto& [name, v] : t.parameters) name = rename(name);
          for (auto& [name, v] : t.initial_values) name = rename(name);
          for (InputSignal& in : t.inputs.inputs) {
            const auto slot = system.symbols().Find(rename(system.symbols()[in.slot].name));
            if (slot) in.slot = *slot;
          }
          bool ok = false;
          try {
            ok = ReplayTrace(system, job.goals[g].original, t);
          } catch (const std::exception&) {
          }
          if (ok) {
            r.trace = std::move(t);
          } else {
            r.trace.reset();
            r.verdict = Verdict::kUnknown;
            r.reason = "the trace found for instance " + components[same].instance +
                       " does not replay for " + components[c].instance;
          }
        }
        r.reason += " (the proof for instance " + components[same].instance +
                    ", an instance of the same automaton)";
        r.seconds = Since(start);
        results[dst] = std::move(r);
      }
    }
  }
  if (product && !product_job.goals.empty()) {
    product_job.automaton = &*product;
    for (int s = 0; s < system.symbols().size(); ++s) product_job.to_system.push_back(s);
    engine.Run(product_job);
  }
  return results;
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ReachableModes(const System& system,
                                                                             int component) const {
  const Component& comp = system.components()[component];
  std::vector<Property> queries;
  for (int m = 0; m < comp.automaton.num_modes(); ++m) {
    const std::string name = system.QualifiedModeName(component, ModeId(m));
    queries.push_back({"reach " + name, Property::Kind::kReach, Predicate::InMode(name), {}});
  }
  const std::vector<CheckResult> results = Check(system, queries);
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
