#pragma once

// The program's names of the commands' arguments: the only place that turns the API names the
// command libraries speak of ("until", "group_by", "parameters": commands/argument_message.h) into
// flags ("--until", "--group-by", "--set") and positional arguments ("MODEL").

#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "commands/argument_message.h"

namespace hybrid::cli {

/// How the command line of `command` ("simulate", "finger", ...) names the argument `argument`
/// (its API name): the positional MODEL of info, dot, import, simulate and check and DATA of
/// diagnose; "-o" for the output of dot and import, "-o/--output" for finger's; the flags spelled
/// apart from their API names (parameters: --set, inputs: --input, properties: --property,
/// objects: --object, effects: --effect, draw_at: --at); every other argument as "--" and its
/// name with '_' written '-' ("out_model" -> "--out-model", "g_a" -> "--g-a").
inline std::string FlagName(std::string_view command, std::string_view argument) {
  struct Name {
    std::string_view commands;  // space-separated; empty: every command
    std::string_view argument;
    std::string_view shown;
  };
  static constexpr std::array<Name, 10> kNames = {{
      {"info dot import simulate check", "model", "MODEL"},
      {"diagnose", "data", "DATA"},
      {"dot import", "output", "-o"},
      {"finger", "output", "-o/--output"},
      {"", "parameters", "--set"},
      {"", "inputs", "--input"},
      {"", "properties", "--property"},
      {"", "objects", "--object"},
      {"", "effects", "--effect"},
      {"", "draw_at", "--at"},
  }};
  const auto names_command = [command](std::string_view list) {
    if (list.empty()) return true;
    for (std::size_t begin = 0; begin <= list.size();) {
      const std::size_t end = std::min(list.find(' ', begin), list.size());
      if (list.substr(begin, end - begin) == command) return true;
      begin = end + 1;
    }
    return false;
  };
  for (const Name& n : kNames) {
    if (n.argument == argument && names_command(n.commands)) return std::string(n.shown);
  }
  std::string flag = "--" + std::string(argument);
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

/// `message` as the command line of `command` writes it: every argument by its FlagName.
inline std::string CommandLineText(std::string_view command, const ArgumentMessage& message) {
  return message.Render(
      [command](const std::string& argument) { return FlagName(command, argument); });
}

}  // namespace hybrid::cli
