#pragma once

#include <optional>
#include <vector>

#include "solvers/flowpipe/affine_form.h"
#include "solvers/flowpipe/segment.h"
#include "solvers/flowpipe/taylor_tape.h"

namespace hybrid::flowpipe_internal {

/// One validated Taylor step of a mode's flow (see FlowpipeReachability's class comment): from
/// the start set `x` (affine forms) over [0, h], the segment of the states it passes through and
/// the set at h.
struct StepResult {
  Segment segment;
  std::vector<AffineForm> end;
};

class FlowpipeStep {
 public:
  /// `inputs`: the input box; `order`: the Taylor order K; `protected_symbols`: symbols never
  /// merged by the reduction (the uncertain parameters'); `max_symbols`: symbols kept.
  FlowpipeStep(const TaylorTape& tape, std::vector<TightInterval> inputs, int order,
               std::vector<char> protected_symbols, int max_symbols);

  /// The step of length h (a power of two), or nullopt when no a-priori enclosure was found (the
  /// caller takes a shorter step).
  /// `known` (if not empty) is a box known to hold the start set, intersected with its forms'
  /// ranges (the entry box, or the previous segment's box): the forms' centre-and-radius
  /// representation of a box can exceed it by rounding, and the a-priori enclosure starts from
  /// the tighter box.
  std::optional<StepResult> Take(const std::vector<AffineForm>& x, double h,
                                 const std::vector<TightInterval>& known = {}) const;

  /// A step length for the start set `box`: the power of two nearest below 0.2 / |df/dx|,
  /// within [2^-14, 2^-1].
  double SuggestedStep(const std::vector<TightInterval>& box) const;

 private:
  std::optional<std::vector<TightInterval>> Apriori(const std::vector<TightInterval>& box,
                                                    double h) const;
  std::vector<double> InputDeviation(const std::vector<TightInterval>& apriori, double h) const;
  void Reduce(std::vector<AffineForm>& x) const;

  const TaylorTape& tape_;
  std::vector<TightInterval> inputs_;
  std::vector<AffineForm> input_centres_;
  std::vector<TightInterval> input_centre_boxes_;
  int order_;
  std::vector<char> protected_;
  int max_symbols_;
};

}  // namespace hybrid::flowpipe_internal
