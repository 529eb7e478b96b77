#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <queue>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/property.h"
#include "hybrid/flowpipe/flowpipe_reachability.h"
#include "solvers/flowpipe/flowpipe_model.h"
#include "solvers/flowpipe/flowpipe_step.h"

namespace hybrid::flowpipe_internal {

/// The discrete loop of FlowpipeReachability (see its class comment): a worklist of mode entries
/// (a mode and a box, from their earliest time), each let flow step by step, its segments checked
/// against the properties and the guards, its crossings turned into new entries.
class Exploration {
 public:
  /// What the exploration learnt about one property.
  struct Finding {
    bool met = false;       ///< some segment may meet the bad (target) states
    double met_time = 0.0;  ///< the earliest time of such a segment
    std::string met_mode;
    /// Some segment lies wholly in the bad (target) states: strong evidence that the property
    /// is false (not a proof: the segment may hold no real state), so refining is not worth it.
    bool met_wholly = false;
  };

  Exploration(FlowpipeModel& model, std::span<const Property> properties,
              const FlowpipeReachability::Options& options, double time_cap,
              FlowpipeReachability::ReachSet* reach_set);

  /// Explores from `initials` to completion or to the budget.
  void Run(std::vector<FlowpipeModel::Initial> initials);

  const std::vector<Finding>& findings() const { return findings_; }
  /// The earliest time not explored (infinity when complete).
  double frontier() const { return frontier_; }
  std::int64_t steps() const { return steps_; }
  int entries() const { return entries_; }
  /// Why the exploration stopped before its end ("" when complete or cut at the time cap only).
  const std::string& stop_reason() const { return stop_reason_; }

 private:
  // A set entering a mode at time t0: the box, or (when `form` is not empty) the states of the
  // affine forms inside the box.
  struct Entry {
    int mode = -1;
    std::vector<TightInterval> box;
    double t0 = 0.0;
    std::vector<AffineForm> form;
  };
  struct Later {
    bool operator()(const Entry& a, const Entry& b) const { return a.t0 > b.t0; }
  };
  // The states of one jump's guard met by consecutive segments from t0 to t_end: their box,
  // and the start set of the first of them (its forms and a box holding it), from which
  // CrossingForm steps over the whole crossing; `formless` when a segment had no start set.
  struct Crossing {
    bool open = false;
    std::vector<TightInterval> box;
    double t0 = 0.0;
    double t_end = 0.0;
    std::vector<AffineForm> start;
    std::vector<TightInterval> start_known;
    bool formless = false;
  };
  // The start set of a segment: its forms and a box known to hold it (null for a segment that is
  // a box only).
  struct StepStart {
    const std::vector<AffineForm>* x = nullptr;
    const std::vector<TightInterval>* known = nullptr;
  };

  void Explore(const Entry& entry);
  // The entry's forms, or forms of `box` (the entry's box cut by the mode's invariant); nullopt
  // (and the exploration stopped there) when the box is unbounded.
  std::optional<std::vector<AffineForm>> StartForms(const Entry& entry,
                                                    const std::vector<TightInterval>& box);
  // Whether an explored box entry from no later a time holds the entry's box.
  bool AlreadyExplored(const Entry& entry) const;
  // An explored entry from no later a time whose box holds the entry's box (a box entry only,
  // when `boxes_only`), or null.
  const Entry* Covering(const Entry& entry, bool boxes_only) const;
  void Push(Entry entry);
  // Checks a segment of mode `mode` from global time t against the properties, the guards and
  // the reach set; false when the segment holds no state (outside the invariant).
  bool Visit(const Segment& segment, int mode, double t, double t_end,
             std::vector<Crossing>& crossings, std::vector<TightInterval>* hull,
             const StepStart& from);
  void CheckProperties(const Segment& segment, const FlowpipeModel::CompiledMode& mode, double t,
                       double t_end);
  void CloseCrossing(int mode, int jump, Crossing& crossing);
  // Affine forms holding every state of the crossing: empty when none are found (the box
  // alone then holds them), nullopt when the crossing is found to hold no state.
  std::optional<std::vector<AffineForm>> FormOfCrossing(int mode, int jump,
                                                        const Crossing& crossing);
  // A positively invariant box around `box` (the flow from time t on), if one is found.
  bool InvariantBox(int mode, std::vector<TightInterval>& box, double t) const;
  bool MayMeetUrgentGuard(const Segment& segment, const FlowpipeModel::CompiledMode& mode) const;
  bool InsideUrgentGuard(const Segment& segment, const FlowpipeModel::CompiledMode& mode) const;
  void Record(const Segment& segment, const FlowpipeModel::CompiledMode& mode, double t,
              double t_end);
  void StopAt(double t, const std::string& why);
  // Model time from t to the nearest property horizon after it (infinity when none).
  double UntilNextHorizon(double t) const;
  // Whether `segment` may meet the bad states of a property no segment has met so far.
  bool WouldMeetNewly(const Segment& segment, const FlowpipeModel::CompiledMode& mode,
                      double t) const;

  FlowpipeModel& model_;
  std::span<const Property> properties_;
  FlowpipeReachability::Options options_;
  double time_cap_;
  FlowpipeReachability::ReachSet* reach_set_;
  std::vector<Finding> findings_;
  std::priority_queue<Entry, std::vector<Entry>, Later> queue_;
  std::map<int, std::vector<Entry>> explored_;
  double frontier_ = std::numeric_limits<double>::infinity();
  std::int64_t steps_ = 0;
  int entries_ = 0;
  std::string stop_reason_;
  const FlowpipeStep* stepper_ = nullptr;  // the flow of the mode Explore is in
};

}  // namespace hybrid::flowpipe_internal
