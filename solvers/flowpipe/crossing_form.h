#pragma once

#include <optional>
#include <vector>

#include "solvers/flowpipe/affine_form.h"
#include "solvers/flowpipe/flowpipe_model.h"
#include "solvers/flowpipe/segment.h"

namespace hybrid::flowpipe_internal {

/// The set a jump's guard cuts out of a flowpipe, as affine forms that keep the correlations a
/// box loses (Exploration::CrossingForm).
///
/// A segment x(s) = sum_k s^k series[k] + remainder, s in [0, h], becomes forms over its symbols
/// and one more, the time symbol e (s = h/2 + (h/2) e): the polynomial in s is evaluated by
/// Horner's rule in affine arithmetic, so its non-affine part joins the error terms. That set
/// has one dimension more than the crossing states, which lie on the guard. When the crossing
/// states satisfy r(x) in [rho_lo, rho_hi] for an atom r of the guard or the source invariant
/// (a guard `r >= 0` with the invariant `r <= 0` pins r to 0), the time symbol is eliminated:
/// with g = r(forms) = g0 + gs.e_s + gt e + [-err, err], every crossing state has
///   e = (rho - g0 - gs.e_s - d) / gt  for some rho in [rho_lo, rho_hi], |d| <= err,
/// which is affine in the other symbols plus an interval, here a fresh symbol in e's place; put
/// into the forms it leaves a set of the crossing's own dimension (Le Guernic and Girard's
/// intersection with a hyperplane, in affine arithmetic). The identity holds at each crossing
/// state's own time, so no form is read outside the segment's step.
class CrossingForm {
 public:
  /// `model` compiles the atoms; `env` is the source mode's environment.
  CrossingForm(const FlowpipeModel& model, const std::vector<TightInterval>& env)
      : model_(model), env_(env) {}

  /// The part of `segment` in which a state may meet `atoms` (a conjunction: guard and
  /// invariant), found in two rounds of kWindowPieces pieces of time (the second over the first's
  /// window), as Segment::Restricted; nullopt when no piece may (Flow*'s domain contraction, on
  /// the time variable only). Fewer states in time leave a smaller time symbol to eliminate.
  std::optional<Segment> Window(const Segment& segment, const std::vector<Residual>& atoms) const;

  /// The states of `segment` (with h > 0) as forms over its symbols and the time symbol, whose
  /// index is set in `time_symbol`.
  static std::vector<AffineForm> OfSegment(const Segment& segment, int& time_symbol);

  /// The forms `y` with the time symbol eliminated through the atom of `atoms` (affine, with its
  /// range over the crossing bounded on both sides) that leaves the smallest forms; `y` itself
  /// when no atom makes them smaller. `box` holds the crossing states.
  std::vector<AffineForm> OnGuard(const std::vector<AffineForm>& y, int time_symbol,
                                  const std::vector<Residual>& atoms,
                                  const std::vector<TightInterval>& box) const;

 private:
  // The range of atom k over the crossing states: its relation's, that of every atom of the same
  // residual, and its value over `box`.
  TightInterval AtomRange(const std::vector<Residual>& atoms, std::size_t k,
                          const std::vector<TightInterval>& box) const;

  const FlowpipeModel& model_;
  const std::vector<TightInterval>& env_;
};

}  // namespace hybrid::flowpipe_internal
