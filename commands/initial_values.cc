#include "commands/initial_values.h"

#include <cmath>
#include <optional>
#include <stdexcept>

#include "commands/closest_name.h"
#include "commands/command_error.h"

namespace hybrid::cli {
namespace {

// The System names of the continuous variables of `system`.
std::vector<std::string> VariableNames(const System& system) {
  std::vector<std::string> names;
  for (const int slot : system.symbols().SlotsOfKind(SymbolKind::kVariable)) {
    names.push_back(system.symbols()[slot].name);
  }
  return names;
}

// Why `name` is not a continuous variable of `system`: what it is instead, or the variables it
// may have meant.
ArgumentMessage NotAVariable(const std::string& name, const System& system) {
  const ArgumentMessage start = Arg("init") + ": '" + name + "' is ";
  if (const std::optional<int> slot = system.symbols().Find(name)) {
    const SymbolKind kind = system.symbols()[*slot].kind;
    const std::string kind_name(KindName(kind));
    const ArgumentMessage what =
        start + (kind_name[0] == 'i' ? "an " : "a ") + kind_name + ", not a continuous variable";
    if (kind == SymbolKind::kParameter) return what + " (set it with " + Arg("parameters") + ")";
    if (kind == SymbolKind::kInput) return what + " (drive it with " + Arg("inputs") + ")";
    return what + " (its value is the mode's)";
  }
  const std::vector<std::string> names = VariableNames(system);
  std::vector<std::string> qualified;  // `x` for `A.x` in a composed system
  for (const std::string& n : names) {
    if (n.size() > name.size() && n.ends_with("." + name)) qualified.push_back("'" + n + "'");
  }
  std::string hint;
  if (!qualified.empty()) {
    hint = "; did you mean " + qualified[0];
    for (std::size_t i = 1; i < qualified.size(); ++i) {
      hint += (i + 1 == qualified.size() ? " or " : ", ") + qualified[i];
    }
    hint += "? (a composed system's names are qualified by the instance)";
  } else if (const std::optional<std::string> close = ClosestName(name, names)) {
    hint = "; did you mean '" + *close + "'?";
  } else {
    hint = " (variables:";
    for (std::size_t i = 0; i < names.size() && i < 12; ++i) hint += " " + names[i];
    hint += names.empty() ? " none)" : names.size() > 12 ? " ...)" : ")";
  }
  return start + "not a continuous variable of the model" + hint;
}

// Throws OptionError when `value` lies outside the declared domain of variable `name` in a
// component of `system` that declares it.
void CheckDomain(const std::string& name, double value, const System& system) {
  for (const Component& c : system.components()) {
    const Automaton& a = c.automaton;
    const std::optional<int> slot = a.symbols().Find(name);
    if (!slot || a.symbols()[*slot].kind != SymbolKind::kVariable) continue;
    for (const VariableInfo& v : a.variables()) {
      if (v.slot != *slot || !v.domain) continue;
      const double lo = a.EvaluateConstant(v.domain->lo, "the domain of '" + name + "'");
      const double hi = a.EvaluateConstant(v.domain->hi, "the domain of '" + name + "'");
      if (value < lo || value > hi) {
        throw OptionError("init", Arg("init") + " " + name + ": " + FormatNumber(value) +
                                      " lies outside the declared domain [" + FormatNumber(lo) +
                                      ", " + FormatNumber(hi) + "] of '" + name + "'");
      }
    }
  }
}

}  // namespace

std::vector<InitialValueSetting> ParseInitialValues(const std::vector<std::string>& specs) {
  std::vector<InitialValueSetting> values;
  for (const std::string& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError("init", Arg("init") + " '" + spec + "': expected NAME=VALUE");
    }
    const std::string name = spec.substr(0, eq);
    values.emplace_back(name, OptionNumber("init", spec.substr(eq + 1), name));
  }
  return values;
}

void SetInitialValues(const std::vector<InitialValueSetting>& values, System& system) {
  for (const auto& [name, value] : values) {
    const std::optional<int> slot = system.symbols().Find(name);
    if (!slot || system.symbols()[*slot].kind != SymbolKind::kVariable) {
      throw OptionError("init", NotAVariable(name, system));
    }
    if (!std::isfinite(value)) {
      throw OptionError("init", Arg("init") + " " + name + ": the value must be finite (got " +
                                    FormatNumber(value) + ")");
    }
    CheckDomain(name, value, system);
    try {
      system.SetInitialValue(name, value);
    } catch (const std::invalid_argument& e) {
      throw OptionError("init", Arg("init") + " " + name + ": " + e.what());
    }
  }
}

}  // namespace hybrid::cli
