#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/automaton/system.h"
#include "solvers/reachability/convex_polyhedron.h"
#include "solvers/reachability/linear_hybrid_system.h"
#include "solvers/reachability/reach_meter.h"

namespace hybrid {

/// Reachability on convex hulls: an over-approximation of a System's reachable set, for proving
/// properties without a horizon (PolyhedralReachability's hull turns; PHAVer's convex-hull
/// option, with the states split as below).
///
/// The states are kept as one polyhedron per *class*: a location together with the values of
/// the variables that stay constant there (rate 0 in the location) and that the states entering
/// it fix to one value each (a lock's owner, a flag, a counter): so states that a model with
/// discrete locations would keep apart stay apart, and the rest of a location's states are
/// merged. For each class, E is the convex hull of every set of entry states found for it (after
/// the jump's reset, the dead variables forgotten, inside the invariant) and F = Flow(E) (time
/// elapse within the invariant: every state a run reaches from E by letting time pass lies in F).
/// A new entry set contained in E is dropped; else E grows to the hull of both and the class is
/// queued to be expanded again: F is computed again and every edge taken from it. The queue
/// takes the classes in the order they were found (the oldest first), so that a class upstream
/// has grown before those downstream are expanded again from it. Once the class has been queued
/// again for a growth `growths_before_widening` times (growths while it waits in the queue count
/// once: they make one more expansion), E is widened (H79, a bigger set) at every growth, so the
/// exploration ends.
///
/// Soundness: every reachable state lies in some F. By induction on runs: an initial state lies
/// in the E of its class, and its time successors in F; a state reached by a jump from a state of
/// some F lies in the entry set that expansion of F computed, so in the E of its class, and its
/// time successors in that class's F. E keeps containing every entry set added to it: a hull,
/// a constraint hull and a widening contain both sets, and the intersection with the invariant
/// that follows the last two removes only states outside it, where no entry set lies. So at
/// the fixpoint (nothing left to expand), a property whose bad states no F meets holds. The
/// polyhedra are PPL's, with exact rational coefficients; only the choice of classes reads
/// doubles (ConvexPolyhedron::Bounds), and any choice of classes is sound. A bad state met
/// proves nothing (it may lie in the hull only); such a property is left to the exact
/// exploration.
class HullExploration {
 public:
  /// Where the exploration stands.
  enum class Status {
    kOpen,       ///< stopped at the end of the meter's slice or share: Resume goes on
    kFixpoint,   ///< complete: Misses tells which properties hold
    kAbandoned,  ///< no property left that it could prove, or coefficients past kMaxBits
  };

  /// What the hull's work is charged, as a multiple of the reach units its operations count
  /// (ReachMeter::Op): a hull's vertices and facets outnumber those of the exact exploration's
  /// polyhedra, and the conversions between them cost more per byte, so that a reach unit of the
  /// hull took 5 to 8 times the CPU time of one of the exact exploration (fiscs04, fiscs05,
  /// disc_2, nav4, tte_7 against fischer_5 and fiscs05 explored exactly).
  static constexpr std::uint64_t kCostFactor = 5;
  /// A convex hull with more than this many facets per dimension is replaced by the constraint
  /// hull of the same two sets (ConvexPolyhedron::ConstraintHull: bigger, but its facets are
  /// among theirs): the conversions between facets and vertices, which every operation on the
  /// hull needs, grow with both counts.
  static constexpr int kMaxFacetsPerDimension = 3;
  /// The exploration stops (kAbandoned) once a hull's constraints need integer coefficients longer
  /// than this many bits: hulls whose vertices converge to a limit take ever longer coefficients.
  static constexpr std::size_t kMaxBits = 256;

  /// Explores `system` for `properties` (none with a horizon; `read`: the System slots they read,
  /// LinearHybridSystem::ReadSlots), charging `meter`. Throws std::invalid_argument where the
  /// system is outside the linear class (as the exact exploration does).
  /// `progress` (if set) is called every 64 expansions with the classes kept and those queued.
  /// A class is widened once it has been queued again for growths more than
  /// `growths_before_widening` times (taken as at least 1).
  HullExploration(const System& system, std::vector<const Property*> properties,
                  const std::vector<int>& read, ReachMeter& meter,
                  std::function<void(int classes, int queued)> progress,
                  int growths_before_widening);

  /// Explores until the meter's slice (or share) ends, the fixpoint, or nothing is left to prove:
  /// `settled[i]` says property i no longer needs the hull (decided by another exploration).
  /// Throws std::invalid_argument for a location outside the class.
  Status Resume(const std::vector<bool>& settled);

  /// After kFixpoint: whether property i's bad (target) states lie outside every class's
  /// states, so that it holds (`proved`; `unreachable` for `reach`).
  bool Misses(int i) const { return !met_[static_cast<std::size_t>(i)]; }
  /// Whether the exploration stopped on a coefficient past kMaxBits (kAbandoned).
  bool too_long() const { return too_long_; }
  /// Whether some class has been widened. Until then the exploration is the same for every
  /// `growths_before_widening` at least as large as this one's.
  bool widened() const { return widened_; }
  /// The classes (polyhedra kept) and the locations they lie in.
  long long classes() const { return static_cast<long long>(classes_.size()); }
  int locations() const { return lhs_.num_locations(); }

 private:
  using Key = std::pair<std::vector<int>, std::vector<std::pair<int, double>>>;
  struct Class {
    ConvexPolyhedron entry;
    ConvexPolyhedron flowed = ConvexPolyhedron::Universe(0);
    int growths = 0;  // the times E grew while the class was not queued
    long long order = 0;
    bool queued = false;
  };

  void Start();
  const LinearLocation& Enter(const std::vector<int>& tuple);
  const std::vector<int>& ConstantDims(const LinearLocation& loc);
  void Add(const std::vector<int>& tuple, ConvexPolyhedron set);
  void Expand(const Key& key, const Class& c);
  void CheckProperties(const LinearLocation& loc, const ConvexPolyhedron& states);
  bool NothingToProve(const std::vector<bool>& settled) const;

  LinearHybridSystem lhs_;
  std::vector<const Property*> properties_;
  ReachMeter& meter_;
  std::function<void(int, int)> progress_;
  int growths_before_widening_;
  long long expanded_ = 0;
  bool started_ = false;
  bool abandoned_ = false;
  bool too_long_ = false;
  bool widened_ = false;
  std::vector<bool> met_;
  std::map<Key, Class> classes_;
  std::map<long long, std::map<Key, Class>::iterator> queue_;
  std::map<const LinearLocation*, std::vector<int>> constant_dims_;
  std::map<std::pair<std::size_t, const LinearLocation*>, std::vector<ConvexPolyhedron>> bad_;
};

}  // namespace hybrid
