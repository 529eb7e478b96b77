#include "gripper/commands/finger_batch.h"

#include <fstream>
#include <sstream>

#include "automaton/number_syntax.h"
#include "commands/command_error.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/parser.h"

namespace hybrid::cli {
namespace {

// `text` without leading and trailing blanks (spaces, tabs, a carriage return).
std::string Trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

// A motor position read from `cell`, or why not (empty when it is one).
std::string MotorError(const std::string& cell, double& value) {
  const NumberRead<double> r = ReadDecimal(cell);
  if (!r.ok()) return NumberErrorMessage(cell, r.error);
  if (!(r.value >= 0.0 && r.value <= 255.0)) {
    return "motor position " + cell + " is outside [0, 255]";
  }
  value = r.value;
  return "";
}

}  // namespace

std::vector<double> ReadMotorPositions(const std::string& path, std::size_t max_rows) {
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, 0, "cannot open the queries file");
  std::string line;
  int row = 0;
  bool header = false;
  std::vector<double> out;
  while (std::getline(in, line)) {
    ++row;
    const std::string cell = Trimmed(line);
    if (cell.empty() || cell[0] == '#') continue;
    if (!header) {
      if (cell != "g") throw ParseError(path, row, 1, "the header must be 'g' (one column)");
      header = true;
      continue;
    }
    if (const auto comma = line.find(','); comma != std::string::npos) {
      throw ParseError(path, row, static_cast<int>(comma) + 1,
                       "one column expected (g), found a comma");
    }
    if (out.size() == max_rows) {
      throw ParseError(path, row, 1, "more than " + std::to_string(max_rows) + " queries");
    }
    double value = 0.0;
    if (const std::string why = MotorError(cell, value); !why.empty()) {
      throw ParseError(path, row, static_cast<int>(line.find(cell[0])) + 1,
                       why + " (CSV row " + std::to_string(row) + ", column 1)");
    }
    out.push_back(value);
  }
  if (in.bad()) throw ParseError(path, row, 0, "read error");
  if (!header) throw ParseError(path, row, 1, "no header 'g'");
  if (out.empty()) throw ParseError(path, row, 1, "no queries after the header");
  return out;
}

std::vector<double> MotorRange(const std::string& spec, std::size_t max_rows) {
  const auto first = spec.find(':');
  const auto second = first == std::string::npos ? first : spec.find(':', first + 1);
  if (second == std::string::npos || spec.find(':', second + 1) != std::string::npos) {
    throw OptionError("g_range", Arg("g_range") + " '" + spec + "': expected START:STOP:COUNT");
  }
  double ends[2] = {0.0, 0.0};
  const std::string parts[2] = {spec.substr(0, first), spec.substr(first + 1, second - first - 1)};
  for (int i = 0; i < 2; ++i) {
    if (const std::string why = MotorError(parts[i], ends[i]); !why.empty()) {
      throw OptionError("g_range",
                        Arg("g_range") + ": " + (i == 0 ? "START" : "STOP") + ": " + why);
    }
  }
  const std::string count_text = spec.substr(second + 1);
  const NumberRead<std::uint64_t> count = ReadUnsigned(count_text, max_rows);
  if (!count.ok() || count.value == 0) {
    throw OptionError("g_range", Arg("g_range") + ": COUNT must be a whole number in [1, " +
                                     std::to_string(max_rows) + "] (got '" + count_text + "')");
  }
  std::vector<double> out(count.value, ends[0]);
  for (std::size_t k = 1; k < out.size(); ++k) {
    out[k] = ends[0] +
             (ends[1] - ends[0]) * static_cast<double>(k) / static_cast<double>(out.size() - 1);
  }
  if (out.size() > 1) out.back() = ends[1];
  return out;
}

std::string BatchCsv(const gripper::FingerClosedForm& closed, std::span<const double> g) {
  std::ostringstream out;
  out << "g,motor,theta1,theta2,theta3,phase,mode\n";
  for (const double x : g) {
    const gripper::FingerConfiguration q = closed.At(x);
    out << FormatNumber(x) << ',' << FormatNumber(q.motor) << ',' << FormatNumber(q.theta[0]) << ','
        << FormatNumber(q.theta[1]) << ',' << FormatNumber(q.theta[2]) << ','
        << gripper::PhaseName(q.phase) << ',' << gripper::FingerModeName(q) << '\n';
  }
  return out.str();
}

std::string BatchJson(const gripper::FingerClosedForm& closed, std::span<const double> g) {
  // Written row by row (not through a JSON document) so that memory stays proportional to the
  // text; every value is a finite number or a plain string (no character needs escaping).
  std::ostringstream out;
  out << "[";
  for (std::size_t k = 0; k < g.size(); ++k) {
    const gripper::FingerConfiguration q = closed.At(g[k]);
    out << (k ? ",\n" : "\n") << "  {\"g\": " << FormatNumber(g[k])
        << ", \"motor\": " << FormatNumber(q.motor) << ", \"theta1\": " << FormatNumber(q.theta[0])
        << ", \"theta2\": " << FormatNumber(q.theta[1])
        << ", \"theta3\": " << FormatNumber(q.theta[2]) << ", \"phase\": \""
        << gripper::PhaseName(q.phase) << "\", \"mode\": \"" << gripper::FingerModeName(q) << "\"}";
  }
  out << "\n]\n";
  return out.str();
}

}  // namespace hybrid::cli
