#include "tools/mode_groups.h"

#include <array>
#include <optional>
#include <sstream>
#include <vector>

#include "gripper/finger_closed_form.h"
#include "tools/options.h"

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

// The finger phase of mode `m`, or "" if `a` lacks one of c1..c3, l1..l3.
std::string PhaseGroup(const Automaton& a, const Mode& m) {
  std::array<int, 3> c{}, l{};
  for (int i = 0; i < 3; ++i) {
    const auto ci = ValueOf(a, m, "c" + std::to_string(i + 1));
    const auto li = ValueOf(a, m, "l" + std::to_string(i + 1));
    if (!ci || !li) return "";
    c[i] = *ci;
    l[i] = *li;
  }
  return "phase " + gripper::PhaseName(gripper::PhaseOfState(c, l));
}

std::vector<std::string> SplitNames(const std::string& spec) {
  std::vector<std::string> names;
  std::stringstream in(spec);
  for (std::string name; std::getline(in, name, ',');) {
    if (name.empty()) throw UsageError("--group-by '" + spec + "': an empty variable name");
    names.push_back(name);
  }
  if (names.empty()) throw UsageError("--group-by: expected 'phase' or discrete variables");
  return names;
}

// Whether some mode of some component is grouped by `group`.
bool GroupsSomething(const System& system,
                     const std::function<std::string(const Automaton&, const Mode&)>& group) {
  for (const Component& c : system.components()) {
    for (const Mode& m : c.automaton.modes()) {
      if (!group(c.automaton, m).empty()) return true;
    }
  }
  return false;
}

}  // namespace

std::function<std::string(const Automaton&, const Mode&)> ModeGroups(const std::string& spec,
                                                                     const System& system) {
  if (spec == "phase") {
    if (!GroupsSomething(system, PhaseGroup)) {
      throw UsageError(
          "--group-by phase needs a finger automaton (discrete variables c1, c2, c3, l1, l2, l3)");
    }
    return PhaseGroup;
  }
  const std::vector<std::string> names = SplitNames(spec);
  for (const std::string& name : names) {
    const auto has = [&](const Automaton& a, const Mode& m) {
      return ValueOf(a, m, name) ? std::string("x") : std::string();
    };
    if (!GroupsSomething(system, has)) {
      throw UsageError("--group-by: '" + name + "' is not a discrete variable of the model");
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
