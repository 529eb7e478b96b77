#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "commands/exit_code.h"
#include "hybrid/gripper/hand.h"

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
  bool joint_state = false;  ///< also the ROS description's joints (gripper/robot_frames.h)
  std::string draw;          ///< SVG of the hand at `draw_at`
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

/// The first motor position at which a link of `finger` touches one of its objects (not the
/// palm or another finger; up to the position its contacts were searched to); NaN if none.
double FirstObjectContact(const gripper::GeometricFinger& finger);
/// "contact" if the first object contact `first_contact` (NaN: none) comes at or before the
/// motor position g, "free" if later, "out_of_reach" if there is none.
std::string ContactStatus(double first_contact, double g);

/// One finger of the hand at the end of its closing: the entries of the "fingers" array of
/// `hybrid hand --json`.
struct HandFinger {
  double command = 0.0;                        ///< its motor command
  gripper::FingerConfiguration configuration;  ///< where the closing leaves it
  struct Contact {
    int link = 0;    ///< 1..3
    double g = 0.0;  ///< the motor position of the contact
    std::string by;  ///< "object K" (1-based), "palm" or "finger X"
  };
  std::vector<Contact> contacts;  ///< the contacts that take effect, by link
  double stop = 0.0;  ///< where it stops by itself (phase 4) before its command; +inf: it does not
};
/// HandFinger of finger f (0 = A, 1 = B, 2 = C) of `hand`.
HandFinger HandFingerOf(const gripper::Hand& hand, int f);

/// Where the closing leaves the objects: `status` "contact" (some finger touches an object at
/// its command), "free" (none does: no objects, or a command before the first contact) or
/// "out_of_reach" (the fingers closing all the way, to 255, touch none); `first_contact` the
/// motor position of the first touch of an object (with the commands for "contact", closing
/// all the way for "free"), NaN for none. `spread` is the hand's spread motor position.
struct HandOutcome {
  std::string status;
  double first_contact = 0.0;
};
HandOutcome HandOutcomeOf(const gripper::Hand& hand, double spread);

/// The checked settings of a hand: its objects (parsed), spread motor position and commands.
struct HandSettings {
  std::vector<gripper::Obstacle> objects;
  double spread = 0.0;
  std::array<double, 3> commands = {};
};
/// The settings of `args`, checked as HandReport checks them (OptionError).
HandSettings CheckedHandSettings(const HandArgs& args);
/// Throws OptionError about `argument` unless g is a motor position in [0, 255].
void CheckMotorPosition(const std::string& argument, double g);
/// The objects' descriptions parsed (OptionError about "objects" naming the column).
std::vector<gripper::Obstacle> ParseObjectList(const std::vector<std::string>& texts);
/// One finger closing on its objects at motor position g, as `hybrid finger --g G --object ...`
/// reports it: the configuration at g, the contacts that take effect while closing to 255 and
/// where it stops (closed_form().stop(), +inf: it does not).
HandFinger FingerAt(const gripper::GeometricFinger& finger, double g);

/// The report `hybrid finger --json` writes for `args` (--g, --gob1..3, --object, --requests,
/// --model) without `simulate`, `draw`, `plot` and the batches. Throws as RunFinger.
nlohmann::ordered_json FingerReportJson(const FingerArgs& args);

/// The report `hybrid hand --json` writes for `args` without `simulate` and `draw` (the spread,
/// each finger's final configuration and contacts, the finger touches). Throws as RunHand.
nlohmann::ordered_json HandReport(const HandArgs& args);

}  // namespace hybrid::cli
