#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "hybrid/automaton/system.h"

namespace hybrid::cli {

/// Everything `hybrid info` reports about `s` (read from `file`), as JSON (docs/cli.md): the
/// file and model names, shared variables, every component (variables with units and domains,
/// discrete variables, inputs with bounds, parameters with values, modes with flows and
/// invariants, transitions, initial states, reachable, unreachable and terminal modes, cycles,
/// properties, warnings), the model's properties, its scenario and all warnings.
nlohmann::ordered_json InfoJson(const System& s, const std::string& file);

/// The text form of `hybrid info`: `system` in the model language (PrintSystem: every
/// declaration, units, `within` horizons and the scenario included; parsing it gives an equal
/// System), then InfoJson's report `info` of it as `#` comments (per component its modes, the
/// reachable, unreachable and terminal ones and its cycles; the scenario as `hybrid simulate`
/// options; the warnings). The whole text is a model file.
std::string InfoText(const nlohmann::ordered_json& info, const System& system);

}  // namespace hybrid::cli
