#pragma once

#include <string>

#include "hybrid/automaton/automaton.h"
#include "hybrid/automaton/system.h"

namespace hybrid {

/// Writes `automaton` in the model language. Parsing the result (ParseAutomaton) gives an
/// automaton equal to `automaton` (operator==): declarations come in slot order, expressions with
/// the fewest parentheses that keep their tree, numbers in shortest round-trip form.
/// Precondition: every name is an identifier of the language (true for parsed automata; not for
/// System::Product results or renamed components, whose names contain '.').
std::string PrintAutomaton(const Automaton& automaton);

/// The right-hand side of a flow as written after `x'`: " in [lo, hi]" for a rectangular rate
/// (AsRectangularFlow), " = EXPRESSION" otherwise.
std::string FlowText(const Expression& flow);

/// An input signal as the language writes it (a scenario's right-hand side, and what `hybrid
/// simulate --input NAME=SIGNAL` and ParseSignal read back): a number for a constant, else
/// "step(t0: v0, t1: v1, ...)" or "linear(...)", numbers in shortest round-trip form.
std::string SignalText(const InputSignal& signal);

/// Writes `system`: each distinct automaton it instantiates (as declared, before renaming), then
/// the `system` block. For a system made by System::Of, writes the automaton alone. Parsing the
/// result (ParseModel) gives an equal System.
std::string PrintSystem(const System& system);

}  // namespace hybrid
