#pragma once

// Internal to hybrid::verification.

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/checking/check_result.h"
#include "solvers/verification/proof_job.h"

namespace hybrid {

/// Where the proof of one job serves for another that asks the same questions of an automaton
/// equal up to names: instances of one automaton (ForInstance), or products of such instances
/// bound alike (ForProducts). It maps the first job's System names to the second's (a prefix
/// `A.` becomes `B.`) and component indices likewise, and copies results across (CopyResults):
/// a verdict without a trace as it is, one with a trace only if the renamed trace replays for
/// the second job (else `unknown`), each reason saying whose proof it is.
class SharedProof {
 public:
  /// Component `same`'s proof for component `c` (an instance of the same automaton, asked the
  /// same questions: ProofPlan decides that).
  static SharedProof ForInstance(const System& system, int same, int c);

  /// How the proof for the product of components `a` serves for that of `b`, or nullopt: a[i]
  /// and b[i] must be named instances of one automaton (as set), bound alike up to the instance
  /// names. Whether the two jobs ask the same questions is the caller's to check.
  static std::optional<SharedProof> ForProducts(const System& system, const std::vector<int>& a,
                                                const std::vector<int>& b);

  /// Copies the results of job `from` (decided) to job `to`, which asks the same questions in
  /// the same order (the results `to`'s goals name, CheckResult::seconds measured from
  /// `start`): each trace renamed and replayed for `to` (one that does not replay leaves the
  /// property `unknown`), each reason followed by "(the proof for SOURCE, WHY)".
  void CopyResults(const System& system, const ProofJob& from, const ProofJob& to,
                   std::chrono::steady_clock::time_point start,
                   std::vector<CheckResult>& results) const;

  /// `name` (a System name of the source) as named for the target.
  std::string Rename(const std::string& name) const { return rename_(name); }
  /// How the source is named in reasons: "instance A", "instances A, ctlA".
  const std::string& source() const { return source_; }
  const std::string& target() const { return target_; }

 private:
  SharedProof() = default;
  // The trace of the source's result renamed for the target.
  Trace Renamed(const System& system, const Trace& trace) const;

  std::function<std::string(const std::string&)> rename_;
  std::map<int, int> component_;  // source component -> target component
  std::string source_;            // "instance A", "instances A, ctlA"
  std::string target_;
  std::string why_;  // ", an instance of the same automaton"
};

}  // namespace hybrid
