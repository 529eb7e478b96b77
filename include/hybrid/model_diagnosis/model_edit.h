#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/model_diagnosis/trace_data.h"

namespace hybrid {

/// The kinds of candidate cause `hybrid diagnose MODEL DATA` tries (docs/diagnosis.md, "Any
/// model"): each is an edit of the model with one new number.
enum class EditKind {
  /// A declared parameter `p` takes another value (name `p`).
  kParameter,
  /// The sensor of variable x reads x + x_bias (name `x_bias`).
  kSensorBias,
  /// The sensor of variable x reads x_gain * x (name `x_gain`).
  kSensorGain,
  /// In mode M, x' = M_x_gain * f for the model's flow x' = f (name `M.x_gain`).
  kFlowGain,
  /// The constant side of comparison k of transition T's guard becomes T_threshold (name
  /// `T.threshold`, `T.threshold_k` for k > 0 when the guard has several comparisons).
  kGuardThreshold,
  /// The same for an invariant of mode M (name `M.invariant`, `M.invariant_k`).
  kInvariantThreshold,
  /// Input u is read as u + u_offset everywhere (name `u_offset`).
  kInputOffset,
  /// Urgent transition T takes effect T_delay after its guard holds (name `T.delay`): it leads
  /// to a new mode `T_pending` (the source's flows, a clock `T_clock` from 0, invariant
  /// `T_clock <= T_delay`), left by a new transition `T_done` (guard `T_clock >= T_delay`, T's
  /// resets and label) to T's target.
  kDelay,
};

/// One candidate cause: an edit of the model with one number, its neutral value (the model as
/// given) and the range searched.
struct ModelEdit {
  EditKind kind = EditKind::kParameter;
  /// The name in reports and JSON (`p`, `x_bias`, `on.x_gain`, `switch_on.threshold`).
  std::string name;
  /// The parameter that carries the number in the edited model: a model parameter's own name,
  /// otherwise the name with `.` replaced by `_` (`switch_on_threshold`), with `_2`, `_3`, ...
  /// appended if the model already has that name.
  std::string identifier;
  /// The variable (kSensor*, kFlowGain) or input (kInputOffset) concerned.
  std::string variable;
  /// The mode (kFlowGain, kInvariantThreshold) or transition (kGuardThreshold) concerned.
  std::string owner;
  /// The comparison's index in the guard or invariant (k*Threshold).
  int atom = 0;
  /// The value that leaves the model as given (the threshold's or parameter's value; 0 for a
  /// bias or offset; 1 for a gain).
  double neutral = 0.0;
  /// The range searched.
  double lo = 0.0, hi = 1.0;
  /// Applied to predictions without simulating (sensor bias and gain).
  bool cheap = false;
};

/// The candidate edits of a model and why some were left out.
struct CandidateSet {
  std::vector<ModelEdit> edits;
  std::vector<std::string> notes;
};

/// The candidate causes of `automaton` (one component) for a measured `data` of it, in this
/// order: its free parameters (those defined by a constant; range: the declared one, else the
/// value +-50%, [-1, 1] at 0); per observed variable a sensor bias (+- half the variable's
/// measured range) and gain ([0.8, 1.2]); per mode and variable with a flow, a flow gain ([0.5,
/// 1.5]); per comparison of an urgent transition's guard and of a mode's invariant with one side
/// that reads no variable or input, a threshold (the value of that side +- a quarter of the
/// measured range of the other side's variable, scaled by its coefficient; +- max(1, 25%) when it
/// is not observed); per input, an offset (+- a quarter of its bounds' width); per urgent
/// transition, a delay ([0, a tenth of the longest run's duration]). Guards of lazy
/// transitions are left out with a note (a simulation takes a lazy transition at its source's
/// invariant boundary, so its guard threshold never decides a trace).
CandidateSet CandidateEdits(const Automaton& automaton, const TraceData& data);

/// `automaton` with `edits` applied, each with its value:
/// - kParameter: the parameter is set to the value;
/// - kFlowGain, k*Threshold, kInputOffset: the parameter ModelEdit::identifier is declared with
///   the value and read where the edit says (x' = M_x_gain * (f); the comparison's constant side
///   replaced; every u read as (u + u_offset));
/// - kDelay: as EditKind::kDelay says (at delay 0 the pending mode is entered and left at one
///   instant, so the model's runs are unchanged);
/// - kSensorBias, kSensorGain on x: a variable `x_measured` (name made unique like identifiers)
///   with the parameters x_bias (0 unless given) and x_gain (1 unless given), flow x_gain * f
///   where x has flow f, initial value x_gain * x0 + x_bias and reset x_gain * r + x_bias where x
///   is reset to r: so x_measured = x_gain * x + x_bias along every run.
/// The result simulates as `automaton` when every value is the edit's neutral value (the model
/// `hybrid diagnose` compiles once and sets per run). Throws std::invalid_argument for an edit
/// that does not fit `automaton` (an unknown mode, transition, comparison or name).
Automaton ApplyEdits(const Automaton& automaton,
                     std::span<const std::pair<ModelEdit, double>> edits);

}  // namespace hybrid
