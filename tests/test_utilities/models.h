#pragma once

// Small hand-written models and model-text helpers shared by the simulation tests
// (tests/solvers/simulation/simulator_test.cc, tests/commands/simulate_command_test.cc).

#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace hybrid::testing {

/// The text of a bundled model, e.g. SpecText("thermostat") reads spec/thermostat.ha.
inline std::string SpecText(const std::string& name) {
  const std::string path = std::string(HYBRID_SOURCE_DIR) + "/spec/" + name + ".ha";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// `text` with the definition of parameter `name` (`param NAME [unit] = ...;`) replaced by
/// `value`. Throws std::invalid_argument if the model does not declare exactly one such
/// parameter, so that a renamed parameter breaks the test instead of silently keeping its value.
inline std::string WithParameter(const std::string& text, const std::string& name,
                                 const std::string& value) {
  const std::regex re("(param\\s+" + name + "\\s*(\\[[^\\]]*\\])?\\s*=\\s*)[^;]*;");
  const auto count =
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator());
  if (count != 1) throw std::invalid_argument("WithParameter: no single parameter '" + name + "'");
  std::smatch match;
  std::regex_search(text, match, re);
  return match.prefix().str() + match[1].str() + value + ";" + match.suffix().str();
}

/// `text` with the one occurrence of `from` replaced by `to` (throws std::invalid_argument
/// unless `from` occurs exactly once).
inline std::string ReplaceOnce(const std::string& text, const std::string& from,
                               const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
    throw std::invalid_argument("ReplaceOnce: '" + from + "' does not occur exactly once");
  }
  return text.substr(0, at) + to + text.substr(at + from.size());
}

/// A clock that runs into its invariant `x <= 1` at t = 1 with no transition to take: the run
/// stops there with status invariant_violated.
inline constexpr std::string_view kInvariantViolationModel = R"(
automaton stuck {
  var x;
  mode run {
    x' = 1;
    inv x <= 1;
  }
  init run { x = 0; }
  scenario { until 5; }
}
)";

/// Two modes whose guards both hold at x = 1 with nothing changing x: after the first jump at
/// t = 1 the other guard fires at the same instant, for ever (event iteration does not settle).
inline constexpr std::string_view kPingPongModel = R"(
automaton ping_pong {
  var x;
  mode ping { x' = 1; }
  mode pong { x' = 1; }
  transition to_pong: ping -> pong { guard x >= 1; }
  transition to_ping: pong -> ping { guard x >= 1; }
  init ping { x = 0; }
  scenario { until 3; }
}
)";

/// A clock x and a guard on the input u in [0, 1]: `go` fires when u reaches 1/2.
inline constexpr std::string_view kInputGuardModel = R"(
automaton input_guard {
  var x;
  input u in [0, 1];
  mode wait { x' = 1; }
  mode done { x' = 1; }
  transition go: wait -> done { guard u >= 0.5; }
  init wait { x = 0; }
  scenario {
    until 10;
    u = step(0: 0, 4: 1);
  }
}
)";

}  // namespace hybrid::testing
