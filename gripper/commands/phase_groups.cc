#include "gripper/commands/phase_groups.h"

#include <array>
#include <optional>
#include <string>

#include "hybrid/gripper/finger_closed_form.h"

namespace hybrid::cli {
namespace {

// The value of the discrete variable `wanted` (itself, or inside an instance: "A.c1") in mode
// `m` of `a`, if it has one.
std::optional<int> ValueOf(const Automaton& a, const Mode& m, const std::string& wanted) {
  for (const auto& [slot, value] : m.discrete_values) {
    const std::string& name = a.symbols()[slot].name;
    if (name == wanted ||
        (name.ends_with("." + wanted) && name.find('.') == name.size() - wanted.size() - 1)) {
      return value;
    }
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

}  // namespace

NamedModeGrouping PhaseGrouping() {
  return {"phase", PhaseGroup, "a finger automaton (discrete variables c1, c2, c3, l1, l2, l3)"};
}

}  // namespace hybrid::cli
