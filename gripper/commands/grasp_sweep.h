#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "gripper/commands/gripper_command.h"

namespace hybrid::cli {

/// A grasp sweep: the hand (or one finger) with fixed settings closing on its objects moved by
/// each of many offsets (metres, in the objects' plane), one row per offset. Every row is what
/// `hybrid hand --json` (or `hybrid finger --object ... --json`) reports for the objects so
/// moved, as flat arrays; a row whose objects overlap the palm or an open finger is "invalid"
/// (with its message) instead of an error. Arrays are row-major: `theta` is rows x fingers x 3.
struct GraspSweep {
  int fingers = 3;                      ///< 3 for the hand (A, B, C), 1 for one finger
  std::vector<std::string> status;      ///< contact, free, out_of_reach or invalid (HandOutcome)
  std::vector<std::string> message;     ///< why a row is invalid; empty otherwise
  std::vector<double> first_contact;    ///< NaN: none
  std::vector<double> motor;            ///< rows x fingers
  std::vector<double> theta;            ///< rows x fingers x 3, degrees
  std::vector<std::string> phase;       ///< rows x fingers
  std::vector<std::string> mode;        ///< rows x fingers
  std::vector<double> contact_g;        ///< rows x fingers x 3 (links); NaN: no contact
  std::vector<std::string> contact_by;  ///< rows x fingers x 3; empty: no contact
  std::vector<double> stop;             ///< rows x fingers; +inf: does not stop before its command
};

/// Most rows of one sweep (its arrays stay under about 1 GB).
inline constexpr std::size_t kMaxSweepRows = 2000000;

/// The hand of `args` (objects, mode or spread, commands; `simulate` and `draw` ignored) with its
/// objects moved by each offset, on `threads` worker threads (1..64; the rows are split into
/// contiguous blocks, so the result does not depend on the number). Throws OptionError as
/// HandReport does for bad settings, for more than kMaxSweepRows offsets and for a non-finite
/// offset (naming the row).
GraspSweep HandSweep(const HandArgs& args, std::span<const std::array<double, 2>> offsets,
                     int threads);

/// One finger with the report's parameters closing on `objects` (finger frame) moved by each
/// offset, at motor position g: its configuration there, the contacts that take effect up to
/// 255 (as `hybrid finger --g G --object ... --json`), status relative to g.
GraspSweep FingerSweep(const std::vector<std::string>& objects, double g,
                       std::span<const std::array<double, 2>> offsets, int threads);

}  // namespace hybrid::cli
