#include "hybrid/gripper/finger_parameters.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hybrid::gripper {
namespace {

// The value of parameter `name` of `finger` in `environment`, or nullopt if it has none.
std::optional<double> ParameterValue(const Automaton& finger,
                                     const std::vector<double>& environment,
                                     const std::string& name) {
  const std::optional<int> slot = finger.symbols().Find(name);
  if (!slot || finger.symbols()[*slot].kind != SymbolKind::kParameter) return std::nullopt;
  return environment.at(static_cast<std::size_t>(*slot));
}

}  // namespace

FingerParameters FingerParametersOf(const Automaton& finger) {
  const std::vector<double> environment = finger.ParameterEnvironment();
  FingerParameters p;
  for (int j = 0; j < 3; ++j) {
    for (const bool upper : {false, true}) {
      const std::string name = "theta" + std::to_string(j + 1) + (upper ? "_max" : "_min");
      const std::optional<double> value = ParameterValue(finger, environment, name);
      if (!value) {
        throw std::invalid_argument("automaton '" + finger.name() + "' has no parameter '" + name +
                                    "' (not a finger model like spec/finger.ha)");
      }
      (upper ? p.theta_max : p.theta_min)[j] = *value;
    }
  }
  if (const auto f = ParameterValue(finger, environment, "theta3_fraction")) {
    p.theta3_fraction = *f;
  }
  return p;
}

}  // namespace hybrid::gripper
