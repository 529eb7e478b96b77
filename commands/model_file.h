#pragma once

#include <string>

#include "hybrid/automaton/system.h"

namespace hybrid::cli {

/// The model a command reads from its argument `model` (a model-language file, or a SpaceEx
/// model `.xml` with its configuration: docs/spaceex.md), with the SpaceEx configuration named by
/// the argument `config` in place of the `.cfg` next to the model when `config` is not empty.
/// Throws OptionError (commands/command_error.h; exit 2) about `config` when it is given with a
/// model that is not a SpaceEx model, and hybrid::ParseError (FILE:LINE:COL, line 0 for a file
/// that cannot be read) for a bad model or configuration.
System ReadModelArgument(const std::string& model, const std::string& config);

}  // namespace hybrid::cli
