#include "commands/model_file.h"

#include <filesystem>
#include <optional>

#include "commands/command_error.h"
#include "hybrid/spaceex/spaceex_import.h"

namespace hybrid::cli {

System ReadModelArgument(const std::string& model, const std::string& config) {
  if (config.empty()) return spaceex::ReadModelFile(model);
  if (!spaceex::IsSpaceExFile(model)) {
    throw OptionError("config", Arg("config") + " names a SpaceEx configuration, read with a " +
                                    "SpaceEx model (.xml) only, and " + Arg("model") + " '" +
                                    model + "' is not one");
  }
  return spaceex::ReadModelFile(model, std::filesystem::path(config));
}

}  // namespace hybrid::cli
