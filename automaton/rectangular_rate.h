#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/expression.h"

namespace hybrid {

/// Rectangular rates: the flow `x' in [lo, hi];` lets the derivative of x take any value in
/// [lo, hi] at any time (lo and hi constant expressions over parameters, lo <= hi).
///
/// Representation: the flow x' = (lo + hi)/2 + (hi - lo)/2 * w, where w in [-1, 1] is the *rate
/// input* of x, an input named `x'` that the automaton declares right after x (RateInputName).
/// No model can declare that name (a prime is not part of a name), so it never meets a model's
/// names. Every solver then treats a rectangular rate as it treats bounded inputs: the
/// simulator applies w = 0 (the midpoint rate) unless a signal for `x'` is given, and a replayed
/// trace gives one step value of w per segment; the provers cover every piecewise-constant w,
/// which reaches the same states as any measurable rate in [lo, hi] inside convex invariants
/// (a rectangular trajectory's end point is reached by a straight line, the mean rate).

/// The name of the rate input of variable `variable`: `variable` followed by a prime ("x'").
std::string RateInputName(std::string_view variable);

/// Whether `name` is a rate input's name (it ends with a prime).
bool IsRateInputName(std::string_view name);

/// The flow (lo + hi)/2 + (hi - lo)/2 * w for `rate` = [lo, hi] and the rate input `w` (a
/// symbol whose name IsRateInputName).
Expression RectangularFlow(const Range& rate, const Expression& w);

/// The range [lo, hi] of a flow built by RectangularFlow (the exact shape, whatever w's slot), or
/// nullopt for any other flow.
std::optional<Range> AsRectangularFlow(const Expression& flow);

/// Declares the rate input of the continuous variable named `variable` in `a` (bounds [-1, 1],
/// no unit), unless it is declared already; returns its
/// slot. Throws std::invalid_argument if `variable` is not a continuous variable of `a`.
int DeclareRateInput(Automaton& a, std::string_view variable);

}  // namespace hybrid
