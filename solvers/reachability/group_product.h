#pragma once

#include <map>
#include <optional>
#include <vector>

#include "hybrid/automaton/property.h"
#include "solvers/reachability/convex_polyhedron.h"
#include "solvers/reachability/linear_hybrid_system.h"
#include "solvers/reachability/reach_meter.h"

namespace hybrid {

/// The product of the reachable sets of a System's interaction groups (System::InteractionGroups),
/// each group explored alone: an over-approximation of the System's reachable set, for proving.
///
/// Groups share no variable and no synchronisation label, so a step of the System is a step of
/// one group and time elapses in every group at once: every run of the System projects onto a run
/// of each group alone, and every reachable state s of the System satisfies, for every group G,
/// (modes of G in s, values of G's variables and of the uncertain parameters in s) in Reach(G).
/// So Reach(System) lies in { s : that holds for every G } (what runs of two groups have in
/// common, the time and the parameters' values, is kept only as far as each group's own set
/// relates them to its variables: an over-approximation). A property whose bad states this
/// product misses holds on the System; one whose bad states it meets is left to the exact
/// exploration, which decides it and finds its run.
class GroupProduct {
 public:
  /// The reachable states of one group explored alone (at its fixpoint): by the modes of its
  /// components (in `components` order), the polyhedra found there, each over the dimensions of
  /// the System's LinearHybridSystem (ConvexPolyhedron::Embedded; the other groups' variables
  /// unconstrained).
  struct Group {
    std::vector<int> components;
    std::map<std::vector<int>, std::vector<ConvexPolyhedron>> states;
  };

  /// `full`: the view of the whole System (no clock) whose dimensions the groups' polyhedra are
  /// over; `groups` cover every component once. `full` and `meter` must outlive this object.
  GroupProduct(LinearHybridSystem& full, std::vector<Group> groups, ReachMeter& meter);

  /// Whether some state of the product meets the bad states of `property` (which has no horizon):
  /// where an `always` predicate fails, where a `never` or `reach` predicate holds. false: the
  /// property holds on the System (proved; unreachable for `reach`). Only the groups the
  /// property reads (a mode of one of their components, one of their variables) are combined:
  /// leaving a group's constraints out only enlarges the product. Every operation is charged to
  /// the meter; nullopt once its share is used or its safety net has passed, or its slice where
  /// states are combined (ReachMeter::Exhausted). Throws
  /// LinearHybridSystem::NotLinearError if the property is not linear.
  std::optional<bool> Meets(const Property& property);
  /// Whether some group has no state at all (no run: Meets answers nullopt, leaving the
  /// properties to the exact exploration).
  bool empty() const { return start_.empty(); }

 private:
  // Whether some combination of the states of groups `read[k..]` at `locations[k..]`, with `set`
  // (bad states already cut by the earlier groups' states), is non-empty; nullopt past a bound.
  std::optional<bool> Combine(const std::vector<int>& read,
                              const std::vector<const std::vector<ConvexPolyhedron>*>& at,
                              std::size_t k, const ConvexPolyhedron& set);
  // The groups `property` reads, as indices into groups_.
  std::vector<int> GroupsRead(const Property& property) const;
  bool OverBound() const { return meter_.Exhausted() || meter_.OutOfTime(); }

  LinearHybridSystem& full_;
  std::vector<Group> groups_;
  ReachMeter& meter_;
  std::vector<int> start_;  // a full tuple: each group's first location
};

}  // namespace hybrid
