#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "commands/exit_code.h"

namespace hybrid::cli {

/// The motor command `finger` and `hand` use when none is given: 255, fully closing.
inline constexpr double kDefaultMotorCommand = 255.0;

/// Options of `hybrid finger` (see docs/cli.md); the fields' names are the arguments' API names
/// that messages refer to (commands/argument_message.h), `gob` as "gob1", "gob2", "gob3".
struct FingerArgs {
  std::optional<double>
      g;  ///< commanded motor position (kDefaultMotorCommand if nothing else asked)
  std::vector<double> requests;              ///< --requests: a history of position requests
  std::array<std::optional<double>, 3> gob;  ///< --gob1..3 when given
  std::vector<std::string> objects;          ///< --object descriptions (finger frame)
  bool json = false;
  std::string draw;             ///< SVG of the finger at `draw_at`
  std::vector<double> draw_at;  ///< motor positions of the drawing's panels
  std::string plot;             ///< SVG plot of theta1..3 against g
  std::string data;             ///< measured runs to overlay on --plot
  bool simulate = false;        ///< also simulate the automaton and compare
  std::string model;            ///< the finger automaton for --simulate
  std::string queries;          ///< --queries: a file of motor positions (batch)
  std::string g_range;          ///< --g-range START:STOP:COUNT (batch)
  std::string output;           ///< -o/--output: where a batch's answers go ("-": stdout)
};

/// Options of `hybrid hand`; the fields' names are the arguments' API names (as for FingerArgs).
struct HandArgs {
  std::vector<std::string> objects;     ///< --object descriptions (palm x-y plane)
  std::string mode = "basic";           ///< operating mode (sets the spread)
  std::optional<double> spread;         ///< spread motor position (overrides the mode's)
  double g = kDefaultMotorCommand;      ///< one motor command for all fingers
  std::optional<double> g_a, g_b, g_c;  ///< per-finger commands (override g)
  bool json = false;
  std::string draw;  ///< SVG of the hand at `draw_at`
  std::vector<double> draw_at;
  bool simulate = false;  ///< also simulate the composed automata
  std::string model;      ///< spec/hand.ha (its finger and spread automata)
};

/// `hybrid finger` and `hybrid hand`. Return the exit code (kOk, or kSimulationFailed when
/// `simulate` disagrees with the closed form or does not complete). Throw OptionError
/// (commands/command_error.h, exit 2) for bad argument values (a motor position outside
/// [0, 255], a malformed object: the message gives the column), arguments that do not go
/// together, and outputs that name one file or the `model` read to simulate; InputError for
/// objects the gripper cannot hold and a model that is not the finger (exit 1);
/// hybrid::ParseError for a bad model; OutputError when a file cannot be written (checked first
/// for a missing directory; the files are written all or nothing).
ExitCode RunFinger(const FingerArgs& args);
ExitCode RunHand(const HandArgs& args);

/// The report `hybrid hand --json` writes for `args` without `simulate` and `draw` (the spread,
/// each finger's final configuration and contacts, the finger touches). Throws as RunHand.
nlohmann::ordered_json HandReport(const HandArgs& args);

}  // namespace hybrid::cli
