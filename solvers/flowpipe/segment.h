#pragma once

#include <vector>

#include "solvers/flowpipe/affine_form.h"
#include "solvers/flowpipe/tight_interval.h"

namespace hybrid::flowpipe_internal {

/// An enclosure of every state a mode's flow passes through in one time step [t, t + h]:
///   x(t + s) in sum_k s^k series[k] + remainder,  s in [0, h],
/// where series[k] are the Taylor coefficients of the solution as affine forms over the step's
/// start set (series[0] is that set), and `remainder` (containing 0) holds the Lagrange remainder
/// and the effect of time-varying inputs. `box` encloses the same states per component (the
/// intersection of that bound with the a-priori enclosure of the step). A segment of one
/// coefficient and h = 0 is a set at one instant; a segment with no series is a box only (a
/// positively invariant box that holds the rest of a mode's flow).
struct Segment {
  std::vector<std::vector<AffineForm>> series;
  std::vector<TightInterval> remainder;
  double h = 0.0;
  std::vector<TightInterval> box;

  /// An enclosure of sum_i a[i] x_i over the segment (a[i] = 0 skipped); sound, and tighter than
  /// the box when the state's components are correlated.
  TightInterval LinearBound(const std::vector<double>& a) const;
  /// The box of the series bound (per component LinearBound of the unit vector) intersected with
  /// `apriori` (an enclosure of the same states).
  void ComputeBox(const std::vector<TightInterval>& apriori);
  /// The part of the segment over s in [lo, hi] (0 <= lo <= hi <= h, hi - lo exact in floating
  /// point, as for ends that are multiples of a power of two), re-centred at lo: its
  /// series are x(lo + u) = sum_j u^j sum_{k >= j} C(k, j) lo^(k - j) series[k] (coefficients as
  /// intervals, so the forms stay enclosures), u in [0, hi - lo]; the remainder, which holds for
  /// every s in [0, h], is kept; its box is the new series bound within this one's box.
  Segment Restricted(double lo, double hi) const;
};

}  // namespace hybrid::flowpipe_internal
