#pragma once

// The initial values of one run (`hybrid simulate --init x=V`, `hybrid check --init`,
// Model.simulate(init=...)): resolved in the IR, as a copy of the model with those values in its
// initial states (System::SetInitialValue), so that the simulator and every checking engine read
// the same start.

#include <string>
#include <utility>
#include <vector>

#include "hybrid/automaton/system.h"

namespace hybrid::cli {

/// A continuous variable's name (a System name: `A.x` in a composed system, or a shared or
/// unqualified `x`) and the value it starts at.
using InitialValueSetting = std::pair<std::string, double>;

/// The entries of the argument `init`, each `NAME=VALUE` with VALUE in the decimal syntax of
/// automaton/number_syntax.h. Throws OptionError (commands/command_error.h) about `init` for an
/// entry without `=` or a name, or a value that is not a decimal number.
std::vector<InitialValueSetting> ParseInitialValues(const std::vector<std::string>& specs);

/// Gives each variable of `values`, in order (a later value of a variable replaces an earlier
/// one), the point value in every initial state of every component of `system` that declares it
/// (System::SetInitialValue). Throws OptionError about `init` (exit 2 on the command line,
/// ValueError in Python) for a name that is not a continuous variable of `system` (naming a close
/// one if there is one, or saying what kind of name it is), a value that is not finite, or a
/// value outside the variable's declared domain (`var x in [lo, hi]`, evaluated with the
/// parameters `system` has); the values before the failing one are then set, so callers set them
/// in a copy of their model.
void SetInitialValues(const std::vector<InitialValueSetting>& values, System& system);

}  // namespace hybrid::cli
