#pragma once

// rapidcheck generators shared by the property tests: random expressions over a fixed symbol
// layout and random (valid) automata.

#include <rapidcheck.h>

#include <ostream>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/interval.h"

namespace hybrid {

/// rapidcheck printers (found by argument-dependent lookup) so that counterexamples show the
/// model-language text instead of "<???>".
void showValue(const Expression& e, std::ostream& os);
void showValue(const Interval& x, std::ostream& os);
void showValue(const Automaton& a, std::ostream& os);

}  // namespace hybrid

namespace hybrid::testing {

/// Symbols available to generated expressions: slot i is named kSymbolNames[i].
inline const std::vector<std::string> kSymbolNames = {"x", "y", "z", "w"};

/// A random expression of depth at most `depth` over kSymbolNames (slots 0..3), using every
/// operation of the IR. Constants are non-negative, as the parser produces them (a negative
/// literal is a negation, which Expression::Unary folds).
rc::Gen<Expression> GenExpression(int depth = 4);

/// A random expression using only operations that are smooth everywhere on the reals
/// (+, -, *, sin, cos, exp of bounded arguments, integer powers), for derivative checks.
rc::Gen<Expression> GenSmoothExpression(int depth = 4);

/// A random valid automaton: variables, discrete variables, inputs, parameters (some with a
/// range of values), modes with flows and invariants, transitions with guards, resets, labels
/// and urgency, initial states, properties and a scenario.
rc::Gen<Automaton> GenAutomaton();

/// A random non-negative finite constant as GenExpression uses them: small integers, decimals
/// that are not exact in binary, dyadic fractions and a few extreme magnitudes.
rc::Gen<double> GenConstant();

/// A uniform integer in [lo, hi), whatever rapidcheck's size (rc::gen::inRange scales its range
/// with the size, so the first cases of a property would all draw `lo`); shrinks towards lo.
rc::Gen<int> GenInt(int lo, int hi);

/// A double in [lo, hi] on a grid of 2^20 + 1 values including both ends, whatever rapidcheck's
/// size; shrinks towards lo.
rc::Gen<double> GenReal(double lo, double hi);

/// A random interval with bounds in about [-`scale`, `scale`] (sometimes degenerate).
rc::Gen<Interval> GenInterval(double scale = 10.0);

/// A random point of `x` (its bounds, its midpoint or a point inside); `x` must be bounded.
rc::Gen<double> GenPointIn(const Interval& x);

}  // namespace hybrid::testing
