#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/system.h"

namespace hybrid::spaceex {

/// Where a line of a translation comes from: a position in the SpaceEx model or configuration.
struct Origin {
  std::string file;
  int line = 0;
  int column = 0;
};

/// A SpaceEx model translated into the model language (docs/spaceex.md).
struct Translation {
  /// The model in the model language.
  std::string text;
  /// The origin of each line of `text` (index 0 is line 1).
  std::vector<Origin> origins;
  /// What the translation changed or left out, one sentence each, for the user.
  std::vector<std::string> notes;

  /// Parses `text` (ParseModel) as file `name`; a ParseError in it is reported at the origin of
  /// its line, so that messages point into the SpaceEx files.
  System Parse(const std::string& name) const;
};

/// Translates SpaceEx XML `xml` (named `xml_file` in messages) and, unless `cfg_file` is empty,
/// the configuration text `cfg`: the component named by the option `system` (default: the last
/// one) becomes an automaton (a base component) or a system of instances (a network: one
/// automaton per base component, or per instance where instances differ in constants or initial
/// states); `initially` gives initial states, `forbidden` the property `never` of that set, and a
/// positive `time-horizon` T the horizon of both the default run (`scenario { until T; }`) and
/// that property (`within T`), so that simulation and every checking engine read one bound (a
/// negative `time-horizon`, SpaceEx's -1, sets none).
/// Throws ParseError naming the file, line and column of malformed XML or configuration, of a
/// construct the translation does not support (nested networks, disjunctive initial sets, flows
/// that leave a variable unconstrained, ...), of a `time-horizon` that is not a non-zero number,
/// of an attribute the import does not know or a
/// boolean attribute that is not true, false, 1 or 0 (in any case), or of a name that is not
/// declared. Names that `forbidden` reads are declared by the components they belong to, also
/// when nothing else reads them. Messages and notes escape the control characters they quote
/// (EscapedForMessage, automaton/quoted_text.h).
Translation TranslateSpaceEx(std::string_view xml, const std::string& xml_file,
                             std::string_view cfg, const std::string& cfg_file);

/// Reads `xml` and its configuration (`cfg`, or else the file next to `xml` with the extension
/// `.cfg`) and translates them. Throws ParseError (line 0) for a file that cannot be read, as
/// TranslateSpaceEx for errors in them, and, when `cfg` is not given and there is no `.cfg` next
/// to `xml`, a ParseError naming the file looked for (line 0; malformed XML is reported first):
/// without a configuration the model has no initial states and its constants no values.
Translation ImportSpaceExFile(const std::filesystem::path& xml,
                              const std::optional<std::filesystem::path>& cfg = std::nullopt);

/// The configuration ImportSpaceExFile reads for `xml` when none is given: the file next to it
/// with the extension `.cfg`, if it exists.
std::optional<std::filesystem::path> DefaultConfigFile(const std::filesystem::path& xml);

/// True if `path` names a SpaceEx model (its extension is `.xml`, in any case).
bool IsSpaceExFile(const std::filesystem::path& path);

/// Reads a model of either language: a SpaceEx model (IsSpaceExFile) through ImportSpaceExFile
/// with the configuration `config` (default: the `.cfg` next to it), anything else with
/// ParseModelFile. Throws std::invalid_argument when `config` is given for a file that is not a
/// SpaceEx model (only SpaceEx models have a configuration).
System ReadModelFile(const std::filesystem::path& path,
                     const std::optional<std::filesystem::path>& config = std::nullopt);

}  // namespace hybrid::spaceex
