#pragma once

#include <span>
#include <string>
#include <vector>

#include "hybrid/gripper/finger_closed_form.h"

namespace hybrid::cli {

/// The motor positions of a batch of `hybrid finger` queries from a file (`--queries FILE`):
/// a header line `g`, then one motor position per line in the model language's decimal syntax
/// (blank lines and lines starting with `#` skipped), each in [0, 255]. At most `max_rows`
/// positions. Throws hybrid::ParseError naming the file, row and column of the first bad line
/// (a missing or other header, an extra column, a malformed or out-of-range number, too many
/// rows, no rows, a file that cannot be read).
std::vector<double> ReadMotorPositions(const std::string& path, std::size_t max_rows);

/// The argument `g_range`, START:STOP:COUNT: COUNT >= 1 motor positions evenly spaced from START
/// to STOP inclusive (START + (STOP - START) k / (COUNT - 1), exactly STOP last; START alone for
/// COUNT = 1), both ends in [0, 255], COUNT at most `max_rows`. Throws OptionError about
/// "g_range" for anything else.
std::vector<double> MotorRange(const std::string& spec, std::size_t max_rows);

/// The batch's answers as CSV: a header `g,motor,theta1,theta2,theta3,phase,mode` and one row
/// per position (numbers in the shortest form that reads back exactly; angles in degrees).
std::string BatchCsv(const gripper::FingerClosedForm& closed, std::span<const double> g);

/// The same records as a JSON array of objects with those keys.
std::string BatchJson(const gripper::FingerClosedForm& closed, std::span<const double> g);

}  // namespace hybrid::cli
