#include "hybrid/reachability/polyhedral_reachability.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "solvers/reachability/exploration_steps.h"
#include "solvers/reachability/group_product.h"
#include "solvers/reachability/hull_exploration.h"
#include "solvers/reachability/linear_hybrid_system.h"
#include "solvers/reachability/reach_meter.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;
using Conjunction = std::vector<LinearConstraint>;

using Meter = ReachMeter;

// A symbolic state: a location, a convex set of states there, and how it was reached.
struct Node {
  std::vector<int> tuple;
  ConvexPolyhedron set;
  int parent = -1;        // -1 for an initial state
  int edge = -1;          // index into the parent location's edges, or of the initial set
  Box box = {};           // BoxOf(set), once pushed
  bool subsumed = false;  // contained in a state pushed after it at its location
};

// What is known about one property during the exploration.
struct Goal {
  const Property* property = nullptr;
  CheckResult* result = nullptr;
  bool decided = false;
  bool met = false;  // the reachable set met its bad (target) states without a replayed trace
  std::string why_no_trace;
  int concretizations = 0;   // runs sought for it (at most kMaxConcretizations)
  bool met_exactly = false;  // met at a state whose path's rates are exact (not widened)
};

// Most runs sought per goal: each walks its path backwards with polyhedra, so a goal met by many
// symbolic states whose runs do not replay would otherwise cost a pre-image walk per state.
constexpr int kMaxConcretizations = 32;

// `p` with `count` unconstrained dimensions added after its own.
ConvexPolyhedron Lifted(ConvexPolyhedron p, int count) {
  p.AddDimensions(count);
  return p;
}

// The unit vector e_i of R^n.
std::vector<double> Unit(int n, int i) {
  std::vector<double> e(static_cast<size_t>(n), 0.0);
  e[static_cast<size_t>(i)] = 1.0;
  return e;
}

// A concrete run along a path, as Explorer::Concretize picks it: the values of the dimensions at
// the start, and per flow its dwell time and the value of each input.
struct PathRun {
  std::vector<double> start;
  std::vector<double> dwell;
  std::vector<std::vector<double>> inputs;
};

// A part (conjunction) of a goal's bad states at one location, and its polyhedron.
struct BadPart {
  Conjunction constraints;
  ConvexPolyhedron set;
};

class Explorer {
 public:
  using Stop = PolyhedralReachability::Usage::Stop;

  // Explores `system` for `goals` (none: the whole reachable set); `read`: the System slots the
  // properties checked read (live everywhere).
  Explorer(const System& system, std::vector<Goal> goals, std::optional<double> horizon,
           const std::vector<int>& read, const PolyhedralReachability::Options& options,
           Meter& meter)
      : system_(system),
        lhs_(system, horizon.has_value(), read),
        goals_(std::move(goals)),
        options_(options),
        meter_(meter),
        initial_(lhs_.InitialSets()),
        horizon_set_(ConvexPolyhedron::Universe(lhs_.dims())) {
    if (horizon) {
      horizon_.push_back({Unit(lhs_.dims(), lhs_.clock()), -*horizon, Kind::kLessEqual});
      horizon_set_ = lhs_.Polyhedron(horizon_);
    }
  }

  // Explores until every goal is decided, the reachable set is complete or a bound is hit; then
  // writes every goal's result and returns why it stopped early.
  PolyhedralReachability::Usage::Stop Run() {
    Start();
    const Stop stop = Resume();
    Finish(stop);
    return stop;
  }

  // Pushes the initial states (call once, before Resume).
  void Start() {
    for (int i = 0; i < static_cast<int>(initial_.size()); ++i) {
      const LinearLocation& loc = Enter(initial_[i].tuple);
      ConvexPolyhedron set = Forgetting(loc, initial_[i].set, meter_);
      set.Intersect(loc.invariant_set);
      meter_.Op(set);
      Push({initial_[i].tuple, Flow(loc, std::move(set), Horizon(), meter_), -1, i});
    }
  }

  // Explores until every goal is decided, the reachable set is complete or a bound is hit
  // (checked before each expansion: the deterministic budget's share or slice, the state bound,
  // the CPU-time safety net), and returns that bound (kNone if none). After a slice's end, a
  // later Resume goes on where this one stopped.
  Stop Resume() {
    while (!queue_.empty() && !AllDecided()) {
      const Stop stop = Bound(true);
      if (stop != Stop::kNone) return stop;
      const int n = queue_.front();
      queue_.pop_front();
      if (!nodes_[n].subsumed) Expand(n);
      if (options_.progress && ++expanded_ % 64 == 0) {
        options_.progress(static_cast<int>(nodes_.size()), static_cast<int>(queue_.size()));
      }
    }
    return Stop::kNone;
  }

  // Whether the reachable set is complete (nothing left to expand).
  bool complete() const { return queue_.empty(); }

  // Whether every goal is decided (never, without goals: the whole reachable set is sought).
  bool AllDecided() const {
    return !goals_.empty() &&
           std::all_of(goals_.begin(), goals_.end(), [](const Goal& g) { return g.decided; });
  }
  // Goal g's property, as decided elsewhere to hold (`proved`; `unreachable` for `reach`), for
  // `reason`.
  void Holds(int g, const std::string& reason) {
    Goal& goal = goals_[static_cast<size_t>(g)];
    CheckResult r = *goal.result;
    r.verdict =
        goal.property->kind == Property::Kind::kReach ? Verdict::kUnreachable : Verdict::kProved;
    r.trace.reset();
    r.reason = reason;
    Decide(g, std::move(r));
  }
  // Goal g's result, decided elsewhere (by another engine, or by the product of the interaction
  // groups): the exploration no longer seeks it.
  void Decide(int g, CheckResult result) {
    Goal& goal = goals_[static_cast<size_t>(g)];
    *goal.result = std::move(result);
    goal.decided = true;
  }
  bool decided(int g) const { return goals_[static_cast<size_t>(g)].decided; }
  const Property& property(int g) const { return *goals_[static_cast<size_t>(g)].property; }
  int num_goals() const { return static_cast<int>(goals_.size()); }

  // Writes every undecided goal's result after the exploration stopped (at `stop`, or kNone).
  void Finish(Stop stop);

  // Symbolic states stored.
  long long states() const { return static_cast<long long>(nodes_.size()); }
  const LinearHybridSystem& lhs() const { return lhs_; }
  // The states found, by location: those no later state at their location contains (after a
  // complete Run, their union is the reachable set).
  std::map<std::vector<int>, std::vector<const ConvexPolyhedron*>> Found() const {
    std::map<std::vector<int>, std::vector<const ConvexPolyhedron*>> out;
    for (const auto& [tuple, indices] : passed_) {
      if (indices.empty()) continue;
      for (const int i : indices) out[tuple].push_back(&nodes_[static_cast<size_t>(i)].set);
    }
    return out;
  }

 private:
  // The bound the exploration has reached, if any (deterministic ones first, so that the safety
  // net is named only when it alone stops the exploration); with `slice`, the end of the
  // meter's slice counts (kBudget) too.
  Stop Bound(bool slice = false) const {
    if (slice ? meter_.Exhausted() : meter_.ShareExhausted()) return Stop::kBudget;
    if (options_.max_states > 0 && static_cast<int>(nodes_.size()) > options_.max_states) {
      return Stop::kStateBound;
    }
    return meter_.OutOfTime() ? Stop::kSafetyNet : Stop::kNone;
  }

  // The location `tuple`; the first time, its construction is charged.
  const LinearLocation& Enter(const std::vector<int>& tuple) {
    const int before = lhs_.num_locations();
    const LinearLocation& loc = lhs_.At(tuple);
    if (lhs_.num_locations() == before) return loc;
    meter_.Location();
    return loc;
  }

  // The horizon's states, or null without a horizon.
  const ConvexPolyhedron* Horizon() const { return horizon_.empty() ? nullptr : &horizon_set_; }

  // Pushes the successors of node n through each edge of its location (locations live in a
  // std::map, so references to them stay valid while others are added; nodes_ does not).
  void Expand(int n) {
    const LinearLocation& loc = lhs_.At(nodes_[n].tuple);
    for (int e = 0; e < static_cast<int>(loc.edges.size()); ++e) {
      const LinearEdge& edge = loc.edges[static_cast<size_t>(e)];
      meter_.Boxes(1);
      if (CertainlyMisses(nodes_[n].box, edge.guard)) continue;
      std::optional<ConvexPolyhedron> jumped = Jump(edge, nodes_[n].set, meter_);
      if (!jumped) continue;
      const LinearLocation& target = Enter(edge.target);
      std::optional<ConvexPolyhedron> entered = Entering(target, std::move(*jumped), meter_);
      if (!entered) continue;
      ConvexPolyhedron& set = *entered;
      // Where time elapse is exact (Flow), a state found before contains the flow of every set
      // of entry states it contains: such an entry set is dropped before its flow is computed.
      if (target.elapse_invariant.size() == target.invariant.size() &&
          Covered(edge.target, set, BoxOf(set))) {
        continue;
      }
      Push({edge.target, Flow(target, std::move(set), Horizon(), meter_), n, e});
    }
  }

  // Adds `node` unless it is empty or contained in a state found before at its location (their
  // bounding boxes rule most out cheaply); checks the goals on it. The states found before that
  // `node` contains no longer count at the location (`node` covers them), and those not yet
  // expanded never will be: `node`'s successors contain theirs.
  void Push(Node node) {
    meter_.Op(node.set, 2);  // the emptiness test and the bounding box
    if (node.set.IsEmpty()) return;
    node.box = BoxOf(node.set);
    if (Covered(node.tuple, node.set, node.box)) return;
    std::vector<int>& here = passed_[node.tuple];
    meter_.Boxes(here.size());
    std::erase_if(here, [&](int i) {
      if (!MayContain(node.box, nodes_[i].box)) return false;
      meter_.Op(node.set, nodes_[i].set);
      if (!node.set.Contains(nodes_[i].set)) return false;
      nodes_[i].subsumed = true;
      return true;
    });
    const int index = static_cast<int>(nodes_.size());
    nodes_.push_back(std::move(node));
    here.push_back(index);
    queue_.push_back(index);
    for (int g = 0; g < static_cast<int>(goals_.size()); ++g) {
      if (!goals_[g].decided) CheckGoal(g, index);
    }
  }

  // Whether `set` (with bounding box `box`) lies inside a state found before at `tuple`.
  bool Covered(const std::vector<int>& tuple, const ConvexPolyhedron& set, const Box& box) {
    std::uint64_t compared = 0;
    bool covered = false;
    for (const int i : passed_[tuple]) {
      ++compared;
      if (!MayContain(nodes_[i].box, box)) continue;
      meter_.Op(nodes_[i].set, set);
      if (nodes_[i].set.Contains(set)) {
        covered = true;
        break;
      }
    }
    meter_.Boxes(compared);
    return covered;
  }

  // The bad (target) states of goal g at `loc`: where an `always` predicate fails, where a
  // `never` or `reach` predicate holds; within the horizon. Computed once per goal and location.
  const std::vector<BadPart>& Bad(int g, const LinearLocation& loc) {
    auto [it, added] = bad_.try_emplace({g, &loc});
    if (!added) return it->second;
    const Property& property = *goals_[g].property;
    const bool negated = property.kind == Property::Kind::kAlways;
    for (Conjunction& c : lhs_.States(property.predicate, negated, loc)) {
      c.insert(c.end(), horizon_.begin(), horizon_.end());
      ConvexPolyhedron set = lhs_.Polyhedron(c);
      meter_.Op(set, 2);
      if (!set.IsEmpty()) it->second.push_back({std::move(c), std::move(set)});
    }
    return it->second;
  }

  void CheckGoal(int index, int n) {
    Goal& g = goals_[index];
    const LinearLocation& loc = lhs_.At(nodes_[n].tuple);
    const std::vector<BadPart>& parts = Bad(index, loc);
    std::vector<const ConvexPolyhedron*> sets;
    for (const BadPart& bad : parts) {
      meter_.Op(bad.set, nodes_[n].set);
      sets.push_back(&bad.set);
    }
    const std::vector<bool> meets = nodes_[n].set.IntersectsEach(sets);
    for (std::size_t k = 0; k < parts.size(); ++k) {
      if (!meets[k]) continue;
      const BadPart& bad = parts[k];
      g.met = true;
      g.met_exactly = g.met_exactly || ExactAlong(n);
      if (g.concretizations >= kMaxConcretizations) continue;
      if (Bound() != Stop::kNone) continue;  // no run is sought past a bound
      ++g.concretizations;
      std::optional<Trace> trace = Concretize(n, bad.constraints, &g.why_no_trace);
      if (!trace) continue;
      meter_.Replay(PathOf(n).size());
      CheckResult& r = *g.result;
      r.verdict =
          g.property->kind == Property::Kind::kReach ? Verdict::kReachable : Verdict::kViolated;
      r.trace = std::move(trace);
      r.reason.clear();
      ConfirmTrace(system_, *g.property, r);
      if (r.verdict != Verdict::kUnknown) {
        r.reason = "a path of " + std::to_string(PathOf(n).size()) +
                   " symbolic states reaches it; the simulator replayed its run";
        g.decided = true;
        return;
      }
      g.why_no_trace = r.reason;
    }
  }

  // Whether the rates of every location on the path to node n are exact (no uncertain
  // parameter's range in place of its value).
  bool ExactAlong(int n) {
    for (const int k : PathOf(n)) {
      if (!LocationOf(k).exact_rates) return false;
    }
    return true;
  }

  std::vector<int> PathOf(int n) const {
    std::vector<int> path;
    for (int i = n; i >= 0; i = nodes_[i].parent) path.push_back(i);
    std::reverse(path.begin(), path.end());
    return path;
  }

  const LinearLocation& LocationOf(int node) { return lhs_.At(nodes_[node].tuple); }
  // The edge by which node path[k + 1] was reached from path[k].
  const LinearEdge& EdgeAfter(const std::vector<int>& path, int k) {
    return LocationOf(path[k]).edges[static_cast<size_t>(nodes_[path[k + 1]].edge)];
  }

  std::optional<Trace> Concretize(int n, const Conjunction& bad, std::string* why);
  ConvexPolyhedron Backward(const std::vector<int>& path, const Conjunction& bad,
                            std::vector<ConvexPolyhedron>& ends);
  ConvexPolyhedron LiftedRates(const LinearLocation& loc) const;
  PathRun Forward(const std::vector<int>& path, const ConvexPolyhedron& start,
                  const std::vector<ConvexPolyhedron>& ends);
  Trace TraceOf(const PathRun& run, const std::vector<int>& path,
                const LinearHybridSystem::Initial& init);
  std::string StopText(Stop stop) const;

  const System& system_;
  LinearHybridSystem lhs_;
  std::vector<Goal> goals_;
  PolyhedralReachability::Options options_;
  Meter& meter_;
  long long expanded_ = 0;  // states expanded (for the progress callback)
  std::vector<LinearHybridSystem::Initial> initial_;
  Conjunction horizon_;
  ConvexPolyhedron horizon_set_;
  std::vector<Node> nodes_;
  std::map<std::vector<int>, std::vector<int>> passed_;
  std::deque<int> queue_;
  std::map<std::pair<int, const LinearLocation*>, std::vector<BadPart>> bad_;
};

// A run along the path to node n that ends in `bad` with the largest margin (at most 1) into its
// inequalities, as a Trace (parameters, initial state and values, step inputs, jump schedule);
// nullopt with the reason in `why` if there is none with a positive margin (or rates along the
// path are over-approximated). Exact: the states from which the rest of the path reaches `bad`
// are propagated backward (Backward), the margin dimension maximised over the start, and the run
// picked forward flow by flow inside those sets (Forward).
std::optional<Trace> Explorer::Concretize(int n, const Conjunction& bad, std::string* why) {
  const std::vector<int> path = PathOf(n);
  for (const int k : path) {
    const LinearLocation& loc = LocationOf(k);
    if (!loc.exact_rates) {
      *why = "rates of " + loc.name + " read uncertain parameters (over-approximated)";
      return std::nullopt;
    }
  }
  std::vector<ConvexPolyhedron> ends;
  ConvexPolyhedron start = Backward(path, bad, ends);
  const std::vector<double> margin = Unit(lhs_.dims() + 1, lhs_.dims());
  const std::optional<double> best = start.Supremum(margin);
  meter_.Op(start, 2);
  if (!best || *best < 1e-9) {
    *why = "the states met lie on the boundary of the property (no run violates it with margin)";
    return std::nullopt;
  }
  // The margin is the largest, or half the supremum where a strict inequality keeps it from
  // being reached (smaller margins are possible too: they only weaken `bad`).
  if (!start.RestrictToMaximum(margin)) {
    start.AddConstraint({margin, -*best / 2, Kind::kEqual});
  }
  const PathRun run = Forward(path, start, ends);
  return TraceOf(run, path, initial_[static_cast<size_t>(nodes_[path[0]].edge)]);
}

// Backward along `path` from `bad`, over the dimensions and a margin e (the last dimension,
// 0 <= e <= 1, constant): ends[k] becomes the states at the end of flow k from which the rest of
// the path reaches `bad` with every inequality of it held with margin e; returns those at the
// start of the first flow within the initial set.
ConvexPolyhedron Explorer::Backward(const std::vector<int>& path, const Conjunction& bad,
                                    std::vector<ConvexPolyhedron>& ends) {
  const int d = lhs_.dims();
  const int m = static_cast<int>(path.size());
  ConvexPolyhedron set = ConvexPolyhedron::Universe(d + 1);
  for (const LinearConstraint& c : bad) {
    LinearConstraint lifted = c;
    lifted.a.push_back(c.kind == Kind::kEqual ? 0.0 : 1.0);  // c + e <= 0
    if (c.kind != Kind::kEqual) lifted.kind = Kind::kLessEqual;
    set.AddConstraint(lifted);
  }
  set.AddConstraint({Unit(d + 1, d), -1.0, Kind::kLessEqual});
  std::vector<double> below = Unit(d + 1, d);
  below[static_cast<size_t>(d)] = -1.0;
  set.AddConstraint({below, 0.0, Kind::kLessEqual});
  ends.assign(static_cast<size_t>(m), ConvexPolyhedron::Empty(d + 1));
  for (int k = m - 1; k >= 0; --k) {
    const LinearLocation& loc = LocationOf(path[k]);
    const ConvexPolyhedron inside = Lifted(loc.elapse_set, 1);
    set.Intersect(inside);
    ends[static_cast<size_t>(k)] = set;
    ConvexPolyhedron rates = Lifted(loc.rates, 1);
    rates.AddConstraint({Unit(d + 1, d), 0.0, Kind::kEqual});
    set.TimeElapseBackward(rates);
    set.Intersect(inside);
    meter_.Op(set, 6);
    if (k == 0) break;
    const LinearEdge& edge = EdgeAfter(path, k - 1);
    set.AssignPreimage(edge.resets);
    set.Intersect(Lifted(edge.guard_set, 1));
    meter_.Op(set, 3);
  }
  set.Intersect(Lifted(initial_[static_cast<size_t>(nodes_[path[0]].edge)].set, 1));
  meter_.Op(set, 2);
  return set;
}

// The rates of `loc` over (dimensions, margin e, dwell t, v): e' = 0, t' = 1, and per input k
// v_k' = u_k within its bounds, each variable's rate c + B u (LinearLocation::input_rates), so
// that after a flow t is its duration and v_k / t the constant value of input k.
ConvexPolyhedron Explorer::LiftedRates(const LinearLocation& loc) const {
  const int d = lhs_.dims();
  const int ni = static_cast<int>(lhs_.inputs().size());
  const int width = d + 2 + ni;
  ConvexPolyhedron r = ConvexPolyhedron::Universe(width);
  for (int i = 0; i < d; ++i) {
    LinearConstraint row{Unit(width, i), 0.0, Kind::kEqual};
    if (i < lhs_.num_variables()) {
      const AffineMap& rate = loc.input_rates[static_cast<size_t>(i)];
      row.b = -rate.b;
      for (int k = 0; k < ni; ++k) row.a[static_cast<size_t>(d + 2 + k)] = -rate.a[k];
    } else if (i == lhs_.clock()) {
      row.b = -1.0;
    }
    r.AddConstraint(row);
  }
  r.AddConstraint({Unit(width, d), 0.0, Kind::kEqual});
  r.AddConstraint({Unit(width, d + 1), -1.0, Kind::kEqual});
  for (int k = 0; k < ni; ++k) {
    const auto [lo, hi] = lhs_.input_bounds()[static_cast<size_t>(k)];
    std::vector<double> below = Unit(width, d + 2 + k);
    below[static_cast<size_t>(d + 2 + k)] = -1.0;
    r.AddConstraint({Unit(width, d + 2 + k), -hi, Kind::kLessEqual});
    r.AddConstraint({below, lo, Kind::kLessEqual});
  }
  return r;
}

// Picks the run forward from a point of `start` (Backward's, with the margin fixed): for each
// flow the end point is a central point of the states that flow reaches from the current one
// (one constant input value) within ends[k], then the jump's resets give the next start. Every
// point is exact (a one-point polyhedron), so each choice is possible by construction.
PathRun Explorer::Forward(const std::vector<int>& path, const ConvexPolyhedron& start,
                          const std::vector<ConvexPolyhedron>& ends) {
  const int d = lhs_.dims();
  const int ni = static_cast<int>(lhs_.inputs().size());
  const int m = static_cast<int>(path.size());
  PathRun run;
  ConvexPolyhedron point = start.CentralPoint();
  run.start = point.PointCoordinates();
  run.start.resize(static_cast<size_t>(d));
  for (int k = 0; k < m; ++k) {
    ConvexPolyhedron flow = Lifted(point, 1 + ni);
    for (int i = d + 1; i < d + 2 + ni; ++i)
      flow.AddConstraint({Unit(d + 2 + ni, i), 0.0, Kind::kEqual});
    flow.TimeElapse(LiftedRates(LocationOf(path[k])));
    flow.Intersect(Lifted(ends[static_cast<size_t>(k)], 1 + ni));
    point = flow.CentralPoint();
    meter_.Op(flow, 6);
    const std::vector<double> x = point.PointCoordinates();
    const double dwell = x[static_cast<size_t>(d + 1)];
    run.dwell.push_back(dwell);
    std::vector<double> inputs;
    for (int j = 0; j < ni; ++j) {
      const auto [lo, hi] = lhs_.input_bounds()[static_cast<size_t>(j)];
      const double v = x[static_cast<size_t>(d + 2 + j)];
      inputs.push_back(dwell > 0 ? std::clamp(v / dwell, lo, hi) : std::clamp(0.0, lo, hi));
    }
    run.inputs.push_back(std::move(inputs));
    point.KeepDimensions(d + 1);
    if (k + 1 < m) point.Assign(EdgeAfter(path, k).resets);
  }
  return run;
}

Trace Explorer::TraceOf(const PathRun& run, const std::vector<int>& path,
                        const LinearHybridSystem::Initial& init) {
  Trace trace;
  const int m = static_cast<int>(path.size());
  for (int c = 0; c < static_cast<int>(init.init_index.size()); ++c) {
    trace.initial_states.emplace_back(c, init.init_index[static_cast<size_t>(c)]);
  }
  for (int i = 0; i < lhs_.dims(); ++i) {
    if (i == lhs_.clock()) continue;
    const double value = run.start[static_cast<size_t>(i)];
    const std::string& name = lhs_.names()[static_cast<size_t>(i)];
    if (i < lhs_.num_variables()) {
      trace.initial_values.emplace_back(name, value);
    } else {
      trace.parameters.emplace_back(name, value);
    }
  }
  double t = 0.0;
  std::vector<InputSignal> signals(lhs_.inputs().size());
  for (size_t j = 0; j < signals.size(); ++j) {
    signals[j].slot = lhs_.inputs()[j];
    signals[j].shape = InputSignal::Shape::kStep;
  }
  for (int k = 0; k < m; ++k) {
    for (size_t j = 0; j < signals.size(); ++j) {
      const double u = run.inputs[static_cast<size_t>(k)][j];
      auto& points = signals[j].points;
      if (!points.empty() && points.back().first == t) {
        points.back().second = u;  // an instantaneous flow: the next one's value counts
      } else {
        points.emplace_back(t, u);
      }
    }
    t += run.dwell[static_cast<size_t>(k)];
    if (k + 1 < m) {
      const LinearEdge& edge = EdgeAfter(path, k);
      ScheduledJump jump{t, edge.name, {}};
      for (const auto& [c, id] : edge.participants) jump.transitions.emplace_back(c, id.value());
      trace.schedule.push_back(std::move(jump));
    }
  }
  trace.inputs.until = t > 0 ? t : 1e-9;
  trace.inputs.inputs = std::move(signals);
  return trace;
}

// How an exploration that stopped early says why (in "reachability stopped ... before a
// fixpoint").
std::string Explorer::StopText(Stop stop) const {
  std::ostringstream out;
  switch (stop) {
    case Stop::kBudget:
      out << "by its deterministic budget (";
      if (meter_.share() < meter_.total()) {
        out << "this exploration's share, " << meter_.share() << " of ";
      }
      out << meter_.total() << " reach units = " << options_.budget << " budget seconds)";
      break;
    case Stop::kStateBound:
      out << "after " << options_.max_states << " symbolic states (its state bound)";
      break;
    case Stop::kSafetyNet:
      out << "by the CPU-time safety net (" << meter_.cpu_seconds()
          << " s of CPU time), not by its deterministic budget,";
      break;
    case Stop::kNone:
      break;
  }
  return out.str();
}

// Writes each goal's verdict and reason.
void Explorer::Finish(Stop stop) {
  const bool complete = queue_.empty();  // else a bound stopped it
  std::ostringstream size;
  size << nodes_.size() << " symbolic states in " << lhs_.num_locations() << " locations";
  // A goal met but left without a run sought met it after a bound was reached.
  const Stop bound = stop != Stop::kNone ? stop : Bound();
  const std::string stopped = "reachability stopped " + StopText(bound);
  const std::string caveat =
      bound == Stop::kSafetyNet ? ": this verdict may differ on another machine" : "";
  for (Goal& g : goals_) {
    if (g.decided) continue;
    CheckResult& r = *g.result;
    r.verdict = Verdict::kUnknown;
    r.trace.reset();
    r.states_met = g.met_exactly;
    if (g.met && g.concretizations == 0) {
      r.reason = "the reachable set meets the property's states, but " + stopped +
                 " before a run reaching them was sought (" + size.str() + ")" + caveat;
    } else if (g.met) {
      r.reason = "the reachable set meets the property's states, but no run found replays (" +
                 g.why_no_trace +
                 (g.concretizations >= kMaxConcretizations
                      ? "; runs sought along the first " + std::to_string(kMaxConcretizations) +
                            " paths that meet them"
                      : std::string()) +
                 ")";
    } else if (!complete) {
      r.reason = stopped + " before a fixpoint (" + size.str() + ")" + caveat;
    } else {
      r.verdict =
          g.property->kind == Property::Kind::kReach ? Verdict::kUnreachable : Verdict::kProved;
      r.reason = "fixpoint of exact polyhedral reachability: " + size.str();
    }
  }
}

// The interaction groups' turns beside the exact exploration: the exact exploration first
// explores Options::group_turn_units reach units, then the groups explore alone
// 1/kGroupTurnDivisor of that, then each slice doubles; so where the groups do not help, they
// cost at most that fraction of the exact exploration's work, and where they do (NAV4: two 9-cell
// maps, whose product the exact exploration does not exhaust), they are done after about
// kGroupTurnDivisor times their own work.
constexpr std::uint64_t kGroupTurnDivisor = 32;

// The interaction groups of a System (System::InteractionGroups) explored alone, a slice at a
// time, and what the product of their reachable sets (GroupProduct) proves. Inactive for a System
// of one group.
class GroupTurns {
 public:
  // `read`: the System slots the properties read (live in every group).
  GroupTurns(const System& system, const std::vector<int>& read,
             const PolyhedralReachability::Options& options, Meter& meter)
      : meter_(meter) {
    std::map<int, std::vector<int>> by_group;
    const std::vector<int> group_of = system.InteractionGroups();
    for (int c = 0; c < static_cast<int>(group_of.size()); ++c) by_group[group_of[c]].push_back(c);
    if (by_group.size() < 2) return;
    full_ = std::make_unique<LinearHybridSystem>(system, false, read);
    for (auto& [representative, comps] : by_group) {
      auto alone = std::make_unique<System>(system.Restricted(comps));
      std::vector<int> read_alone;  // the slots of `read` the group has, in its own numbering
      for (const int s : read) {
        if (const auto found = alone->symbols().Find(system.symbols()[s].name)) {
          read_alone.push_back(*found);
        }
      }
      PolyhedralReachability::Options quiet = options;  // no progress report, no pause
      quiet.progress = nullptr;
      quiet.pause = nullptr;
      explorers_.push_back(std::make_unique<Explorer>(*alone, std::vector<Goal>{}, std::nullopt,
                                                      read_alone, quiet, meter));
      alone_.push_back(std::move(alone));
      components_.push_back(std::move(comps));
    }
  }

  bool active() const { return !explorers_.empty() && !done_; }
  void Stop() { done_ = true; }
  long long states() const {
    long long n = 0;
    for (const auto& e : explorers_) n += e->states();
    return n;
  }

  // Explores the groups on for at most `units` reach units (none: within the share); then, once
  // every group is complete, asks the product about each goal of `exact` still open, within
  // `units` more, and decides those it proves. Returns once the units are used (to be called
  // again) or every goal has its answer from the product.
  void Turn(Explorer& exact, const std::vector<Property>& properties, const std::vector<int>& which,
            std::optional<std::uint64_t> units) {
    const auto slice = [&] {
      if (units) {
        meter_.SetSlice(*units);
      } else {
        meter_.ClearSlice();
      }
    };
    slice();
    started_.resize(explorers_.size(), false);
    for (std::size_t k = 0; k < explorers_.size(); ++k) {
      if (!started_[k]) explorers_[k]->Start();
      started_[k] = true;
      if (explorers_[k]->complete()) continue;
      if (explorers_[k]->Resume() != PolyhedralReachability::Usage::Stop::kNone) {
        return;  // a bound: the next turn goes on
      }
    }
    slice();  // the product's own turn
    if (!product_) product_ = std::make_unique<GroupProduct>(*full_, Groups(), meter_);
    if (product_->empty()) {  // a group without runs: nothing to prove here
      done_ = true;
      return;
    }
    settled_.resize(which.size(), false);
    for (std::size_t g = 0; g < which.size(); ++g) {
      if (settled_[g] || exact.decided(static_cast<int>(g))) continue;
      const std::optional<bool> meets = product_->Meets(properties[which[g]]);
      if (!meets) return;  // past the slice: asked again next turn
      settled_[g] = true;
      if (*meets) continue;
      std::ostringstream reason;
      reason << "fixpoint of exact polyhedral reachability of each of its " << explorers_.size()
             << " interaction groups alone (" << states()
             << " symbolic states in all), whose product misses the property's states";
      exact.Holds(static_cast<int>(g), reason.str());
    }
    done_ = true;
  }

 private:
  // Each group's reachable states, in the dimensions of the whole system.
  std::vector<GroupProduct::Group> Groups() {
    std::vector<GroupProduct::Group> out;
    const std::vector<std::string>& names = full_->names();
    for (std::size_t k = 0; k < explorers_.size(); ++k) {
      std::vector<int> to;  // each dimension of the group's view in the whole system's (by name)
      for (const std::string& name : explorers_[k]->lhs().names()) {
        to.push_back(static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin()));
      }
      GroupProduct::Group group{components_[k], {}};
      for (const auto& [tuple, sets] : explorers_[k]->Found()) {
        std::vector<ConvexPolyhedron>& here = group.states[tuple];
        for (const ConvexPolyhedron* set : sets) {
          here.push_back(set->Embedded(full_->dims(), to));
          meter_.Op(here.back());
        }
      }
      out.push_back(std::move(group));
    }
    return out;
  }

  std::unique_ptr<LinearHybridSystem> full_;  // the whole system's view (several groups only)
  Meter& meter_;
  std::vector<std::unique_ptr<System>> alone_;
  std::vector<std::vector<int>> components_;
  std::vector<std::unique_ptr<Explorer>> explorers_;
  std::unique_ptr<GroupProduct> product_;
  std::vector<bool> settled_;  // per goal: the product has answered
  std::vector<bool> started_;  // per group: its initial states pushed
  bool done_ = false;
};

// Reachability on convex hulls (HullExploration) beside the exact exploration: its first turn
// before the exact exploration (Options::hull_units, at most 1/kHullFirstTurnDivisor of the
// share, so that a small budget leaves the exact exploration most of it), then as many units as
// each of the exact exploration's turns (1/kHullTurnDivisor of them), until its fixpoint proves
// what its hulls miss or it is abandoned: hulls that have not met every property are the likelier
// proof (fischer_6's mutual exclusion is proved on them at 5.2 billion units in all, about half
// of them the hulls', which a quarter of the turns did not give within the default budget).
constexpr std::uint64_t kHullFirstTurnDivisor = 4;
constexpr std::uint64_t kHullTurnDivisor = 1;
// The hulls' widening, the coarsest first: the growths of a class before its hull is widened
// (HullExploration's growths_before_widening). Where widened hulls meet the bad states of a
// property still open (at their fixpoint or before), the exploration starts again, from the
// next turn on, with the next, later widening: finer hulls, which cost more (the proof of
// DISC03's all_sending took 61, 69 and 75 million reach units at 3, 4 and 5), and may prove what
// the first lost. Hulls that met them before any widening would meet them again at any later
// one. At 2, FISCS05's first hulls meet the bad states of its mutual exclusion, which they prove
// at 3.
constexpr std::array<int, 2> kWideningLadder = {3, 32};
// The later widenings' turns: 1/kLaterLevelDivisor of the first's (they seldom prove what the
// first did not, and where the hulls meet the bad states at every widening, as TTEthernet's do,
// they cost that much more).
constexpr std::uint64_t kLaterLevelDivisor = 4;

class HullTurns {
 public:
  HullTurns(const System& system, const std::vector<const Property*>& observed,
            const std::vector<int>& read, const PolyhedralReachability::Options& options,
            Meter& meter)
      : system_(system), observed_(observed), read_(read), options_(options), meter_(meter) {
    Start();
  }

  bool active() const { return !done_; }

  // Explores on for at most `units` reach units; at a fixpoint, every goal of `exact` still
  // open whose bad states the hulls miss holds, and the next widening of kWideningLadder starts
  // for those left open.
  void Turn(Explorer& exact, std::uint64_t units) {
    meter_.SetSlice(level_ == 0 ? units : std::max<std::uint64_t>(units / kLaterLevelDivisor, 1));
    while (!done_) {
      const HullExploration::Status status = Resume(exact);
      if (status == HullExploration::Status::kOpen) break;
      if (status == HullExploration::Status::kFixpoint) ProveMissed(exact);
      if (exact.AllDecided() || hull_->too_long() || !hull_->widened() ||
          level_ + 1 >= kWideningLadder.size()) {
        done_ = true;
      } else {
        ++level_;  // from the next turn on, so that it takes no more than its share of them
        try {
          Start();
        } catch (const std::invalid_argument&) {
          done_ = true;
        }
        break;
      }
    }
    meter_.ClearSlice();
  }
  long long states() const { return classes_ + hull_->classes(); }

 private:
  void Start() {
    if (hull_) classes_ += hull_->classes();
    hull_ = std::make_unique<HullExploration>(system_, observed_, read_, meter_, options_.progress,
                                              kWideningLadder[level_]);
  }
  HullExploration::Status Resume(const Explorer& exact) {
    std::vector<bool> settled;
    for (int g = 0; g < exact.num_goals(); ++g) settled.push_back(exact.decided(g));
    try {
      return hull_->Resume(settled);
    } catch (const std::invalid_argument&) {
      done_ = true;  // outside the class: the exact exploration alone says why
      return HullExploration::Status::kAbandoned;
    }
  }
  void ProveMissed(Explorer& exact) {
    for (int g = 0; g < exact.num_goals(); ++g) {
      if (exact.decided(g) || !hull_->Misses(g)) continue;
      std::ostringstream reason;
      reason << "fixpoint of polyhedral reachability on convex hulls (" << hull_->classes()
             << " hulls in " << hull_->locations()
             << " locations, an over-approximation), which misses the property's states";
      exact.Holds(g, reason.str());
    }
  }

  const System& system_;
  std::vector<const Property*> observed_;
  std::vector<int> read_;
  const PolyhedralReachability::Options& options_;
  Meter& meter_;
  std::unique_ptr<HullExploration> hull_;
  std::size_t level_ = 0;
  long long classes_ = 0;  // those of the explorations before hull_
  bool done_ = false;
};

// Explores `system` for properties `which` (all with `horizon`); writes their results and returns
// why the exploration stopped early (kNone if it did not).
PolyhedralReachability::Usage::Stop ExploreBounded(const System& system,
                                                   const std::vector<Property>& properties,
                                                   const std::vector<int>& which, double horizon,
                                                   std::vector<CheckResult>& results,
                                                   const PolyhedralReachability::Options& options,
                                                   Meter& meter,
                                                   PolyhedralReachability::Usage& used) {
  std::vector<const Property*> observed;
  std::vector<Goal> goals;
  for (const int i : which) {
    observed.push_back(&properties[i]);
    goals.push_back({&properties[i], &results[i], false, false, ""});
  }
  Explorer explorer(system, std::move(goals), horizon, LinearHybridSystem::ReadSlots(observed),
                    options, meter);
  const PolyhedralReachability::Usage::Stop stop = explorer.Run();
  used.states += explorer.states();
  return stop;
}

// The pause of Options::pause: the goals of `exact` still open go to `options.pause`, and each
// definite result it returns decides its goal.
void Pause(const System& system, Explorer& exact, const PolyhedralReachability::Options& options) {
  std::vector<int> open;
  std::vector<Property> asked;
  for (int g = 0; g < exact.num_goals(); ++g) {
    if (exact.decided(g)) continue;
    open.push_back(g);
    asked.push_back(exact.property(g));
  }
  if (open.empty()) return;
  std::vector<CheckResult> answers = options.pause(system, asked);
  for (std::size_t k = 0; k < open.size() && k < answers.size(); ++k) {
    if (answers[k].verdict != Verdict::kUnknown) exact.Decide(open[k], std::move(answers[k]));
  }
}

// The explorations beside the exact one for properties without a horizon: the interaction
// groups' (GroupTurns) and the hulls' (HullTurns), each when it applies.
struct SideTurns {
  std::optional<GroupTurns> groups;
  std::optional<HullTurns> hull;

  bool active() const { return (groups && groups->active()) || (hull && hull->active()); }
  long long states() const { return (groups ? groups->states() : 0) + (hull ? hull->states() : 0); }
  // One turn each, after the exact exploration's turn of `slice` units.
  void Turn(Explorer& exact, const std::vector<Property>& properties, const std::vector<int>& which,
            std::uint64_t slice) {
    if (hull && hull->active() && !exact.AllDecided()) {
      hull->Turn(exact, std::max<std::uint64_t>(slice / kHullTurnDivisor, 1));
    }
    if (groups && groups->active() && !exact.AllDecided()) {
      try {
        groups->Turn(exact, properties, which,
                     std::max<std::uint64_t>(slice / kGroupTurnDivisor, 1));
      } catch (const std::invalid_argument&) {
        groups->Stop();
      }
    }
  }
};

// Sets up the side explorations for `system` in `side` (each left out where it does not apply)
// and takes their first turns: the hulls' of Options::hull_units, the groups' to their fixpoint
// where Options::group_turn_units is 0.
void FirstTurns(const System& system, const std::vector<Property>& properties,
                const std::vector<int>& which, const std::vector<const Property*>& observed,
                const std::vector<int>& read, const PolyhedralReachability::Options& options,
                Meter& meter, Explorer& exact, SideTurns& side) {
  try {
    side.groups.emplace(system, read, options, meter);
  } catch (const std::invalid_argument&) {
    // A group outside the class: the exact exploration alone says why.
  }
  if (options.hull_units > 0 && !exact.AllDecided()) {
    try {
      side.hull.emplace(system, observed, read, options, meter);
      side.hull->Turn(exact, std::min(options.hull_units, meter.share() / kHullFirstTurnDivisor));
    } catch (const std::invalid_argument&) {
      side.hull.reset();
    }
  }
  if (options.group_turn_units == 0 && side.groups && side.groups->active() &&
      !exact.AllDecided()) {
    try {
      side.groups->Turn(exact, properties, which, std::nullopt);
    } catch (const std::invalid_argument&) {
      side.groups->Stop();
    }
  }
}

// Explores `system` for properties `which` (none with a horizon), taking turns with the
// interaction groups explored alone (GroupTurns) where it has several and with the hulls
// (HullTurns); writes their results and returns why the exploration stopped early (kNone if it
// did not).
PolyhedralReachability::Usage::Stop ExploreUnbounded(
    const System& system, const std::vector<Property>& properties, const std::vector<int>& which,
    std::vector<CheckResult>& results, const PolyhedralReachability::Options& options, Meter& meter,
    PolyhedralReachability::Usage& used) {
  using Stop = PolyhedralReachability::Usage::Stop;
  std::vector<const Property*> observed;
  std::vector<Goal> goals;
  for (const int i : which) {
    observed.push_back(&properties[i]);
    goals.push_back({&properties[i], &results[i], false, false, ""});
  }
  const std::vector<int> read = LinearHybridSystem::ReadSlots(observed);
  Explorer exact(system, std::move(goals), std::nullopt, read, options, meter);
  exact.Start();
  // The pause counts the side explorations' first turns too: where the hulls' first turn ends
  // without a proof, the other engine answers before the exact exploration goes on.
  const std::uint64_t pause_at =
      meter.used() + std::min(options.pause_units, UINT64_MAX / 2 - meter.used());
  SideTurns side;
  FirstTurns(system, properties, which, observed, read, options, meter, exact, side);
  bool paused = !options.pause;
  std::uint64_t slice = std::max<std::uint64_t>(options.group_turn_units, 1);
  std::uint64_t next_turn = meter.used() + slice;
  Stop stop = Stop::kNone;
  while (!exact.AllDecided()) {
    // Explore up to the next side turn or the pause, whichever comes first.
    const bool turns = side.active();
    std::uint64_t until = turns ? next_turn : UINT64_MAX;
    if (!paused) until = std::min(until, pause_at);
    if (until == UINT64_MAX) {
      meter.ClearSlice();
    } else {
      meter.SetSlice(until - std::min(until, meter.used()));
    }
    stop = exact.Resume();
    if (stop != Stop::kBudget || meter.ShareExhausted() || until == UINT64_MAX) break;
    if (!paused && meter.used() >= pause_at) {
      paused = true;
      meter.ClearSlice();
      Pause(system, exact, options);
    }
    if (turns && meter.used() >= next_turn) {
      side.Turn(exact, properties, which, slice);
      slice = std::min(slice, UINT64_MAX / 8) * 2;
      next_turn = meter.used() + slice;
    }
  }
  if (exact.AllDecided()) stop = Stop::kNone;
  meter.ClearSlice();
  exact.Finish(stop);
  used.states += exact.states() + side.states();
  return stop;
}

}  // namespace

bool PolyhedralReachability::Handles(const System& system, const std::vector<Property>& properties,
                                     std::string* why) {
  try {
    std::vector<const Property*> observed;
    for (const Property& p : properties) observed.push_back(&p);
    LinearHybridSystem lhs(system, false, observed);
    const std::vector<LinearHybridSystem::Initial> initial = lhs.InitialSets();
    if (initial.empty()) {
      *why = "no initial state";
      return false;
    }
    for (int c = 0; c < static_cast<int>(system.components().size()); ++c) {
      for (int m = 0; m < system.components()[c].automaton.num_modes(); ++m) {
        std::vector<int> tuple = initial.front().tuple;
        tuple[static_cast<size_t>(c)] = m;
        const LinearLocation& loc = lhs.At(tuple);
        for (const Property& p : properties) lhs.States(p.predicate, false, loc);
      }
    }
    return true;
  } catch (const std::invalid_argument& e) {
    *why = e.what();
    return false;
  }
}

std::vector<CheckResult> PolyhedralReachability::Check(const System& system,
                                                       const std::vector<Property>& properties,
                                                       Usage* usage) const {
  if (!(options_.budget > 0) || !(options_.budget <= 1e6)) {
    throw std::invalid_argument("the reachability budget must be in (0, 1e6] budget seconds");
  }
  std::vector<CheckResult> results(properties.size());
  const auto started = std::chrono::steady_clock::now();
  std::map<std::optional<double>, std::vector<int>> by_horizon;
  for (int i = 0; i < static_cast<int>(properties.size()); ++i) {
    results[i].property = properties[i].name;
    results[i].kind = properties[i].kind;
    results[i].method = "reach";
    by_horizon[properties[i].horizon].push_back(i);
  }
  Meter meter(
      static_cast<std::uint64_t>(
          std::llround(options_.budget * static_cast<double>(kReachUnitsPerBudgetSecond))),
      options_.cpu_seconds > 0 ? options_.cpu_seconds : std::max(60.0, 10.0 * options_.budget));
  Usage used;
  int parts = static_cast<int>(by_horizon.size());
  for (const auto& [horizon, which] : by_horizon) {
    meter.ShareAmong(parts--);
    try {
      const Usage::Stop stop =
          horizon
              ? ExploreBounded(system, properties, which, *horizon, results, options_, meter, used)
              : ExploreUnbounded(system, properties, which, results, options_, meter, used);
      used.stop = std::max(used.stop, stop);  // the enumerators are in that order
    } catch (const std::invalid_argument& e) {
      for (const int i : which) {
        // A verdict decided before (a replayed run, the groups' product, the pause) stands.
        if (results[i].verdict != Verdict::kUnknown) continue;
        results[i].verdict = Verdict::kUnknown;
        results[i].trace.reset();
        results[i].reason = std::string("not a linear hybrid automaton: ") + e.what();
      }
    }
  }
  used.units_total = meter.total();
  used.units_used = meter.used();
  if (usage) *usage = used;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (CheckResult& r : results) r.seconds = seconds / static_cast<double>(results.size());
  return results;
}

}  // namespace hybrid
