#include "solvers/reachability/polyhedral_reachability.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <optional>
#include <sstream>

#include "solvers/reachability/linear_hybrid_system.h"

namespace hybrid {
namespace {

using Kind = LinearConstraint::Kind;
using Conjunction = std::vector<LinearConstraint>;

double ThreadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// A symbolic state: a location, a convex set of states there, and how it was reached.
struct Node {
  std::vector<int> tuple;
  ConvexPolyhedron set;
  int parent = -1;  // -1 for an initial state
  int edge = -1;    // index into the parent location's edges, or of the initial set
};

// What is known about one property during the exploration.
struct Goal {
  const Property* property = nullptr;
  CheckResult* result = nullptr;
  bool decided = false;
  bool met = false;  // the reachable set met its bad (target) states without a replayed trace
  std::string why_no_trace;
};

// The time-elapse successor of `set` in `loc`, kept inside its elapse invariant (and `extra`).
ConvexPolyhedron Flow(const LinearHybridSystem& lhs, const LinearLocation& loc,
                      ConvexPolyhedron set, const Conjunction& extra) {
  for (const LinearConstraint& c : loc.elapse_invariant) set.AddConstraint(c);
  for (const LinearConstraint& c : extra) set.AddConstraint(c);
  if (set.IsEmpty()) return set;
  set.TimeElapse(loc.rates);
  for (const LinearConstraint& c : loc.elapse_invariant) set.AddConstraint(c);
  for (const LinearConstraint& c : extra) set.AddConstraint(c);
  (void)lhs;
  return set;
}

// Builds the linear program of one path (PathProgram::Solve): per flow k the state at its
// start x_k and end y_k, its dwell time and its inputs times the dwell time.
class PathProgram {
 public:
  PathProgram(const LinearHybridSystem& lhs, int flows)
      : d_(lhs.dims()), ni_(static_cast<int>(lhs.inputs().size())), flows_(flows) {}

  int width() const { return flows_ * Stride() + 1; }
  int x(int k) const { return k * Stride(); }
  int y(int k) const { return k * Stride() + d_; }
  int dwell(int k) const { return k * Stride() + 2 * d_; }
  int v(int k) const { return k * Stride() + 2 * d_ + 1; }
  int epsilon() const { return width() - 1; }

  // c applied to the block of dimensions starting at `at`; with `margin`, c + epsilon REL 0.
  void On(const LinearConstraint& c, int at, bool margin = false) {
    LinearConstraint row{Zero(), c.b, c.kind};
    for (int i = 0; i < d_; ++i) row.a[static_cast<size_t>(at + i)] = c.a[static_cast<size_t>(i)];
    if (margin && c.kind != Kind::kEqual) {
      row.a[static_cast<size_t>(epsilon())] = 1.0;
      row.kind = Kind::kLessEqual;
    }
    rows_.push_back(std::move(row));
  }
  void Add(std::vector<std::pair<int, double>> terms, double b, Kind kind) {
    LinearConstraint row{Zero(), b, kind};
    for (const auto& [i, a] : terms) row.a[static_cast<size_t>(i)] += a;
    rows_.push_back(std::move(row));
  }
  std::vector<double> Zero() const {
    return std::vector<double>(static_cast<size_t>(width()), 0.0);
  }
  // Maximises the margin epsilon (at most 1).
  std::optional<std::vector<double>> Solve() {
    Add({{epsilon(), 1.0}}, -1.0, Kind::kLessEqual);
    std::vector<double> objective = Zero();
    objective[static_cast<size_t>(epsilon())] = 1.0;
    return MaximizeLinear(width(), rows_, objective);
  }

 private:
  int Stride() const { return 2 * d_ + 1 + ni_; }
  int d_, ni_, flows_;
  std::vector<LinearConstraint> rows_;
};

class Explorer {
 public:
  Explorer(const System& system, std::vector<Goal> goals, std::optional<double> horizon,
           const PolyhedralReachability::Options& options)
      : system_(system),
        lhs_(system, horizon.has_value()),
        goals_(std::move(goals)),
        options_(options),
        initial_(lhs_.InitialSets()) {
    if (horizon) {
      std::vector<double> a(static_cast<size_t>(lhs_.dims()), 0.0);
      a[static_cast<size_t>(lhs_.clock())] = 1.0;
      horizon_.push_back({a, -*horizon, Kind::kLessEqual});
    }
  }

  // Explores until every goal is decided, the reachable set is complete or a bound is hit;
  // then writes every goal's result.
  void Run() {
    const double start = ThreadCpuSeconds();
    for (int i = 0; i < static_cast<int>(initial_.size()); ++i) {
      const LinearLocation& loc = lhs_.At(initial_[i].tuple);
      ConvexPolyhedron set = initial_[i].set;
      for (const LinearConstraint& c : loc.invariant) set.AddConstraint(c);
      Push({initial_[i].tuple, Flow(lhs_, loc, std::move(set), horizon_), -1, i});
    }
    std::string stopped;
    while (!queue_.empty() && !AllDecided()) {
      if (static_cast<int>(nodes_.size()) > options_.max_states) {
        stopped = "stopped after " + std::to_string(options_.max_states) + " symbolic states";
        break;
      }
      if (ThreadCpuSeconds() - start > options_.cpu_seconds) {
        stopped = "stopped by the CPU-time safety net after " +
                  std::to_string(static_cast<int>(options_.cpu_seconds)) + " s";
        break;
      }
      const int n = queue_.front();
      queue_.pop_front();
      Expand(n);
    }
    Finish(stopped);
  }

 private:
  bool AllDecided() const {
    return std::all_of(goals_.begin(), goals_.end(), [](const Goal& g) { return g.decided; });
  }

  void Expand(int n) {
    const std::vector<int> tuple = nodes_[n].tuple;
    const std::vector<LinearEdge> edges = lhs_.At(tuple).edges;
    for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
      ConvexPolyhedron set = nodes_[n].set;
      for (const LinearConstraint& c : edges[e].guard) set.AddConstraint(c);
      if (set.IsEmpty()) continue;
      set.Assign(edges[e].resets);
      const LinearLocation& target = lhs_.At(edges[e].target);
      for (const LinearConstraint& c : target.invariant) set.AddConstraint(c);
      if (set.IsEmpty()) continue;
      Push({edges[e].target, Flow(lhs_, target, std::move(set), horizon_), n, e});
    }
  }

  // Adds `node` unless it is empty or contained in a state found before at its location; checks
  // the goals on it.
  void Push(Node node) {
    if (node.set.IsEmpty()) return;
    std::vector<int>& here = passed_[node.tuple];
    for (const int i : here) {
      if (nodes_[i].set.Contains(node.set)) return;
    }
    const int index = static_cast<int>(nodes_.size());
    nodes_.push_back(std::move(node));
    here.push_back(index);
    queue_.push_back(index);
    for (Goal& g : goals_) {
      if (!g.decided) CheckGoal(g, index);
    }
  }

  // The bad (target) states of `g` at a location: where an `always` predicate fails, where a
  // `never` or `reach` predicate holds.
  std::vector<Conjunction> Bad(const Goal& g, const LinearLocation& loc) const {
    const bool negated = g.property->kind == Property::Kind::kAlways;
    std::vector<Conjunction> bad = lhs_.States(g.property->predicate, negated, loc);
    for (Conjunction& c : bad) c.insert(c.end(), horizon_.begin(), horizon_.end());
    return bad;
  }

  void CheckGoal(Goal& g, int n) {
    const LinearLocation& loc = lhs_.At(nodes_[n].tuple);
    for (const Conjunction& bad : Bad(g, loc)) {
      ConvexPolyhedron meet = lhs_.Polyhedron(bad);
      if (!meet.Intersects(nodes_[n].set)) continue;
      g.met = true;
      std::optional<Trace> trace = Concretize(n, bad, &g.why_no_trace);
      if (!trace) continue;
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

  std::vector<int> PathOf(int n) const {
    std::vector<int> path;
    for (int i = n; i >= 0; i = nodes_[i].parent) path.push_back(i);
    std::reverse(path.begin(), path.end());
    return path;
  }

  std::optional<Trace> Concretize(int n, const Conjunction& bad, std::string* why);
  void JumpRows(PathProgram& lp, const LinearEdge& edge, int k) const;
  Trace TraceOf(const std::vector<double>& z, const PathProgram& lp, const std::vector<int>& path,
                const LinearHybridSystem::Initial& init);
  void Finish(const std::string& stopped);

  const System& system_;
  LinearHybridSystem lhs_;
  std::vector<Goal> goals_;
  PolyhedralReachability::Options options_;
  std::vector<LinearHybridSystem::Initial> initial_;
  Conjunction horizon_;
  std::vector<Node> nodes_;
  std::map<std::vector<int>, std::vector<int>> passed_;
  std::deque<int> queue_;
};

// The linear program of the path to node n ending in `bad`, solved for the largest margin into
// `bad`; its solution as a Trace (parameters, initial state and values, step inputs).
std::optional<Trace> Explorer::Concretize(int n, const Conjunction& bad, std::string* why) {
  const std::vector<int> path = PathOf(n);
  const int m = static_cast<int>(path.size());
  const int d = lhs_.dims();
  const int ni = static_cast<int>(lhs_.inputs().size());
  PathProgram lp(lhs_, m);
  const LinearHybridSystem::Initial& init = initial_[nodes_[path[0]].edge];
  for (const LinearConstraint& c : init.set.Constraints()) lp.On(c, lp.x(0));
  for (int k = 0; k < m; ++k) {
    const LinearLocation& loc = lhs_.At(nodes_[path[k]].tuple);
    if (!loc.exact_rates) {
      *why = "rates of " + loc.name + " read uncertain parameters (over-approximated)";
      return std::nullopt;
    }
    for (const LinearConstraint& c : loc.elapse_invariant) {
      lp.On(c, lp.x(k));
      lp.On(c, lp.y(k));
    }
    lp.Add({{lp.dwell(k), -1.0}}, 0.0, Kind::kLessEqual);
    for (int i = 0; i < d; ++i) {  // y - x = rate * dwell
      std::vector<std::pair<int, double>> terms = {{lp.y(k) + i, 1.0}, {lp.x(k) + i, -1.0}};
      if (i < lhs_.num_variables()) {
        const AffineMap& rate = loc.input_rates[static_cast<size_t>(i)];
        terms.emplace_back(lp.dwell(k), -rate.b);
        for (int j = 0; j < ni; ++j)
          terms.emplace_back(lp.v(k) + j, -rate.a[static_cast<size_t>(j)]);
      } else if (i == lhs_.clock()) {
        terms.emplace_back(lp.dwell(k), -1.0);
      }
      lp.Add(terms, 0.0, Kind::kEqual);
    }
    for (int j = 0; j < ni; ++j) {  // lo * dwell <= v <= hi * dwell
      const auto [lo, hi] = lhs_.input_bounds()[static_cast<size_t>(j)];
      lp.Add({{lp.v(k) + j, 1.0}, {lp.dwell(k), -hi}}, 0.0, Kind::kLessEqual);
      lp.Add({{lp.v(k) + j, -1.0}, {lp.dwell(k), lo}}, 0.0, Kind::kLessEqual);
    }
    if (k + 1 < m) JumpRows(lp, loc.edges[static_cast<size_t>(nodes_[path[k + 1]].edge)], k);
  }
  for (const LinearConstraint& c : bad) lp.On(c, lp.y(m - 1), true);
  const std::optional<std::vector<double>> z = lp.Solve();
  if (!z || (*z)[static_cast<size_t>(lp.epsilon())] < 1e-9) {
    *why = "the states met lie on the boundary of the property (no run violates it with margin)";
    return std::nullopt;
  }
  return TraceOf(*z, lp, path, init);
}

// Rows of the jump of `edge` after flow k: guard at y_k, x_{k+1} = reset(y_k).
void Explorer::JumpRows(PathProgram& lp, const LinearEdge& edge, int k) const {
  for (const LinearConstraint& c : edge.guard) lp.On(c, lp.y(k));
  for (int i = 0; i < lhs_.dims(); ++i) {
    std::vector<std::pair<int, double>> terms = {{lp.x(k + 1) + i, 1.0}};
    double b = 0.0;
    const auto reset = std::find_if(edge.resets.begin(), edge.resets.end(),
                                    [i](const auto& r) { return r.first == i; });
    if (reset == edge.resets.end()) {
      terms.emplace_back(lp.y(k) + i, -1.0);
    } else {
      for (int j = 0; j < lhs_.dims(); ++j) {
        terms.emplace_back(lp.y(k) + j, -reset->second.a[static_cast<size_t>(j)]);
      }
      b = -reset->second.b;
    }
    lp.Add(terms, b, Kind::kEqual);
  }
}

Trace Explorer::TraceOf(const std::vector<double>& z, const PathProgram& lp,
                        const std::vector<int>& path, const LinearHybridSystem::Initial& init) {
  Trace trace;
  const int m = static_cast<int>(path.size());
  const SymbolTable& symbols = system_.symbols();
  for (int c = 0; c < static_cast<int>(init.init_index.size()); ++c) {
    trace.initial_states.emplace_back(c, init.init_index[static_cast<size_t>(c)]);
  }
  for (int i = 0; i < lhs_.dims(); ++i) {
    if (i == lhs_.clock()) continue;
    const double value = z[static_cast<size_t>(lp.x(0) + i)];
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
    const double dwell = z[static_cast<size_t>(lp.dwell(k))];
    for (size_t j = 0; j < signals.size(); ++j) {
      const auto [lo, hi] = lhs_.input_bounds()[j];
      const double u = dwell > 0 ? std::clamp(z[static_cast<size_t>(lp.v(k)) + j] / dwell, lo, hi)
                                 : std::clamp(0.0, lo, hi);
      auto& points = signals[j].points;
      if (!points.empty() && points.back().first == t) {
        points.back().second = u;  // an instantaneous flow: the next one's value counts
      } else {
        points.emplace_back(t, u);
      }
    }
    t += dwell;
    if (k + 1 < m) {
      const LinearLocation& loc = lhs_.At(nodes_[path[k]].tuple);
      const LinearEdge& edge = loc.edges[static_cast<size_t>(nodes_[path[k + 1]].edge)];
      trace.schedule.push_back({t, edge.name});
    }
  }
  trace.inputs.until = t > 0 ? t : 1e-9;
  trace.inputs.inputs = std::move(signals);
  (void)symbols;
  return trace;
}

// Writes each goal's verdict and reason.
void Explorer::Finish(const std::string& stopped) {
  const bool complete = queue_.empty() && stopped.empty();
  std::ostringstream size;
  size << nodes_.size() << " symbolic states in " << lhs_.num_locations() << " locations";
  for (Goal& g : goals_) {
    if (g.decided) continue;
    CheckResult& r = *g.result;
    r.verdict = Verdict::kUnknown;
    r.trace.reset();
    if (g.met) {
      r.reason = "the reachable set meets the property's states, but no run found replays (" +
                 g.why_no_trace + ")";
    } else if (!complete) {
      r.reason = "reachability " + (stopped.empty() ? std::string("stopped") : stopped) +
                 " before a fixpoint (" + size.str() + ")";
    } else {
      r.verdict =
          g.property->kind == Property::Kind::kReach ? Verdict::kUnreachable : Verdict::kProved;
      r.reason = "fixpoint of exact polyhedral reachability: " + size.str();
    }
  }
}

}  // namespace

bool PolyhedralReachability::Handles(const System& system, const std::vector<Property>& properties,
                                     std::string* why) {
  try {
    LinearHybridSystem lhs(system, false);
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

std::vector<CheckResult> PolyhedralReachability::Check(
    const System& system, const std::vector<Property>& properties) const {
  std::vector<CheckResult> results(properties.size());
  const auto started = std::chrono::steady_clock::now();
  std::map<std::optional<double>, std::vector<int>> by_horizon;
  for (int i = 0; i < static_cast<int>(properties.size()); ++i) {
    results[i].property = properties[i].name;
    results[i].kind = properties[i].kind;
    results[i].method = "reach";
    by_horizon[properties[i].horizon].push_back(i);
  }
  for (const auto& [horizon, which] : by_horizon) {
    std::vector<Goal> goals;
    for (const int i : which) goals.push_back({&properties[i], &results[i], false, false, ""});
    try {
      Explorer(system, std::move(goals), horizon, options_).Run();
    } catch (const std::invalid_argument& e) {
      for (const int i : which) {
        results[i].verdict = Verdict::kUnknown;
        results[i].trace.reset();
        results[i].reason = std::string("not a linear hybrid automaton: ") + e.what();
      }
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (CheckResult& r : results) r.seconds = seconds / static_cast<double>(results.size());
  return results;
}

}  // namespace hybrid
