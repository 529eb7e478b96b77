#include "commands/mode_groups.h"

#include <optional>
#include <sstream>
#include <vector>

#include "commands/command_error.h"

namespace hybrid::cli {
namespace {

// Whether the symbol `name` is `wanted` itself or `wanted` inside an instance ("A.c1").
bool NameMatches(const std::string& name, const std::string& wanted) {
  return name == wanted || (name.size() > wanted.size() && name.ends_with("." + wanted) &&
                            name.find('.') == name.size() - wanted.size() - 1);
}

// The value of the discrete variable `wanted` in mode `m` of `a`, if it has one.
std::optional<int> ValueOf(const Automaton& a, const Mode& m, const std::string& wanted) {
  for (const auto& [slot, value] : m.discrete_values) {
    if (NameMatches(a.symbols()[slot].name, wanted)) return value;
  }
  return std::nullopt;
}

std::vector<std::string> SplitNames(const std::string& spec) {
  std::vector<std::string> names;
  std::stringstream in(spec);
  for (std::string name; std::getline(in, name, ',');) {
    if (name.empty()) {
      throw OptionError("group_by", Arg("group_by") + " '" + spec + "': an empty variable name");
    }
    names.push_back(name);
  }
  if (names.empty()) {
    throw OptionError("group_by",
                      Arg("group_by") + ": expected a grouping name or discrete variables");
  }
  return names;
}

// Whether some mode of some component is grouped by `group`.
bool GroupsSomething(const System& system, const ModeGrouping& group) {
  for (const Component& c : system.components()) {
    for (const Mode& m : c.automaton.modes()) {
      if (!group(c.automaton, m).empty()) return true;
    }
  }
  return false;
}

}  // namespace

ModeGrouping ModeGroups(const std::string& spec, const System& system,
                        const std::vector<NamedModeGrouping>& named) {
  for (const NamedModeGrouping& grouping : named) {
    if (spec != grouping.name) continue;
    if (!GroupsSomething(system, grouping.group)) {
      throw OptionError("group_by", Arg("group_by") + " " + spec + " needs " + grouping.needs);
    }
    return grouping.group;
  }
  const std::vector<std::string> names = SplitNames(spec);
  for (const std::string& name : names) {
    const auto has = [&](const Automaton& a, const Mode& m) {
      return ValueOf(a, m, name) ? std::string("x") : std::string();
    };
    if (!GroupsSomething(system, has)) {
      throw OptionError(
          "group_by", Arg("group_by") + ": '" + name + "' is not a discrete variable of the model");
    }
  }
  return [names](const Automaton& a, const Mode& m) {
    std::string label;
    for (const std::string& name : names) {
      if (const auto v = ValueOf(a, m, name)) {
        label += (label.empty() ? "" : ", ") + name + "=" + std::to_string(*v);
      }
    }
    return label;
  };
}

}  // namespace hybrid::cli
