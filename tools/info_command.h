#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "automaton/system.h"

namespace hybrid::cli {

/// Everything `hybrid info` reports about `s` (read from `file`), as JSON (docs/cli.md): the
/// file and model names, shared variables, every component (variables with units and domains,
/// discrete variables, inputs with bounds, parameters with values, modes with flows and
/// invariants, transitions, initial states, reachable, unreachable and terminal modes, cycles,
/// properties, warnings), the model's properties, its scenario and all warnings.
nlohmann::ordered_json InfoJson(const System& s, const std::string& file);

/// The text form of InfoJson's report, as `hybrid info` prints it.
std::string InfoText(const nlohmann::ordered_json& info);

}  // namespace hybrid::cli
