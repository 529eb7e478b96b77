#pragma once

// Internal to hybrid::verification: includes Z3's C++ API, which no public header exposes.

#include <z3++.h>

#include <optional>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/trace.h"
#include "solvers/verification/proof_job.h"
#include "solvers/verification/smt_encoding.h"

namespace hybrid {

/// Turns a path of the SMT encoding of a job's automaton (a model of a bounded path) into a
/// Trace of the System for the simulator to replay: the values of the uncertain parameters,
/// which `init` declaration each component of the job starts from and the values the path gives
/// the variables that declaration sets in a box, and a piecewise-constant input schedule:
/// one step piece per flow segment of positive duration (the segment's constant input), at a
/// jump the values its guard reads from the jump's instant, then a short tail (1e-6 of the
/// path's duration, at least 1e-6) with the last input held, so that events due exactly at the
/// end of the path happen. Trace::inputs.until is the path's duration plus that tail.
class TraceBuilder {
 public:
  /// A builder for paths of `encoding`, whose automaton is `job`'s automaton, in `system`; all
  /// three are borrowed and must outlive the builder.
  TraceBuilder(const System& system, const ProofJob& job, SmtEncoding& encoding);

  /// The trace of `path`, the path of a model of the encoding's states s_0 .. s_n and
  /// transitions as SmtEncoding::ReadPath(model, n) reads it, or nullopt when s_0 is in no
  /// initial state.
  std::optional<Trace> Build(const z3::model& model,
                             const std::vector<SmtEncoding::PathStep>& path);

 private:
  // Which `init` declaration each component of the job starts from (trace.initial_states), for
  // the job automaton's initial state `start`.
  void AddInitialStates(int start, Trace& trace) const;
  // Adds to `trace` the values s0 gives the variables that initial state `start` sets in a box.
  void AddInitialValues(int start, const SmtEncoding::PathStep& s0, Trace& trace) const;
  // Adds to `trace` the input schedule of `path` (class comment).
  void AddInputSchedule(const std::vector<SmtEncoding::PathStep>& path, int depth,
                        Trace& trace) const;
  // Sets in `current` the inputs that the guard of `jump`'s transition reads to the jump's
  // values; whether any changed.
  bool GuardInputs(const SmtEncoding::PathStep& jump, std::vector<double>& current) const;

  const System& system_;
  const ProofJob& job_;
  SmtEncoding& enc_;
  const Automaton& a_;
};

}  // namespace hybrid
