// libFuzzer harness: numeric options of the `hybrid` command line as CLI11 parses them
// (AddNumberOption, AddNumberListOption and OptionNumber in cli/options.h). The input is a
// command line, one argument per line (no NUL bytes), given to an app with options of every kind
// the tool uses (a double, an int, an unsigned seed, an optional double, a list of numbers,
// strings, a flag). Every command line either throws CLI::ParseError or sets each given number
// option to the value of one of its argument texts that is a number in the documented syntax (read
// independently, tests/fuzz/number_oracle.h): never a value from an empty, hexadecimal,
// doubled-sign or other non-number text, never a negative seed. OptionNumber on each argument
// accepts exactly the decimal texts with a finite value (else OptionError naming the argument).

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cli/options.h"
#include "tests/fuzz/fuzz_utilities.h"
#include "tests/fuzz/number_oracle.h"

namespace {

using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers

constexpr size_t kMaxArguments = 64;

// The texts an option's value may come from: each argument, and its part after the first '='
// (`--until=5`) or after a short option's letter (`-s7`), each also split at commas (list options).
std::vector<std::string> Candidates(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  auto add_pieces = [&](const std::string& text) {
    out.push_back(text);
    size_t begin = 0;
    for (size_t comma = text.find(','); comma != std::string::npos; comma = text.find(',', begin)) {
      out.push_back(text.substr(begin, comma - begin));
      begin = comma + 1;
    }
    if (begin > 0) out.push_back(text.substr(begin));
  };
  for (const std::string& a : args) {
    add_pieces(a);
    if (const size_t eq = a.find('='); eq != std::string::npos) add_pieces(a.substr(eq + 1));
    if (a.size() > 2 && a[0] == '-' && a[1] != '-') add_pieces(a.substr(2));  // `-s7`
  }
  return out;
}

bool SameDouble(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Whether `value` is the value of a candidate in the decimal syntax.
bool FromSomeDecimal(double value, const std::vector<std::string>& candidates) {
  for (const std::string& c : candidates) {
    if (!ClassifyNumber(c).decimal) continue;
    const double v = StrtodValue(c);
    if (std::isfinite(v) && SameDouble(v, value)) return true;
  }
  return false;
}

// Whether `value` is the value of a candidate that is an integer text.
bool FromSomeInteger(__int128 value, const std::vector<std::string>& candidates) {
  for (const std::string& c : candidates) {
    if (ClassifyNumber(c).integer && IntegerValue(c) == value) return true;
  }
  return false;
}

void CheckOptionNumber(const std::string& text) {
  const OracleNumber n = ClassifyNumber(text);
  const double expected = n.decimal ? StrtodValue(text) : 0.0;
  const bool valid =
      n.decimal && std::isfinite(expected) && !(expected == 0.0 && n.nonzero_mantissa);
  try {
    const double v = hybrid::cli::OptionNumber("parameters", text, "a");
    if (!valid || !SameDouble(v, expected)) FuzzFail("OptionNumber accepts '" + text + "'");
  } catch (const hybrid::cli::OptionError& e) {
    if (valid) FuzzFail("OptionNumber refuses '" + text + "': " + e.what());
    if (e.argument() != "parameters" || std::string(e.what()).rfind("parameters a: ", 0) != 0) {
      FuzzFail(std::string("OptionNumber's message does not name the argument: ") + e.what());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args;
  const std::string_view text = AsText(data, size);
  if (Contains(text, std::string_view("\0", 1))) return -1;  // an argument cannot hold NUL
  for (size_t begin = 0; begin <= text.size() && args.size() < kMaxArguments;) {
    const size_t end = std::min(text.find('\n', begin), text.size());
    args.emplace_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  for (const std::string& a : args) CheckOptionNumber(a);

  CLI::App app{"fuzzed", "hybrid"};
  double until = 120.0;
  int depth = 20;
  std::uint64_t seed = 1;
  std::optional<double> g;
  std::vector<double> at;
  std::vector<std::string> inputs;
  std::string model;
  bool json = false;
  app.add_option("MODEL", model, "Model file");
  auto* until_option = hybrid::cli::AddNumberOption(&app, "--until", &until, "Horizon");
  auto* depth_option = hybrid::cli::AddNumberOption(&app, "--depth", &depth, "Depth");
  auto* seed_option = hybrid::cli::AddNumberOption(&app, "-s,--seed", &seed, "Seed");
  auto* g_option = hybrid::cli::AddNumberOption(&app, "--g", &g, "Motor position");
  auto* at_option = hybrid::cli::AddNumberListOption(&app, "--at", &at, "Positions");
  app.add_option("--input", inputs, "Signals");
  app.add_flag("--json", json, "JSON");

  std::vector<const char*> argv = {"hybrid"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
    return 0;  // refused: exit code 2 in the tool
  }
  const std::vector<std::string> candidates = Candidates(args);
  if (until_option->count() > 0 && !FromSomeDecimal(until, candidates)) {
    FuzzFail("--until set to " + std::to_string(until) + " from no number");
  }
  if (depth_option->count() > 0 && !FromSomeInteger(depth, candidates)) {
    FuzzFail("--depth set to " + std::to_string(depth) + " from no integer");
  }
  if (seed_option->count() > 0 && !FromSomeInteger(seed, candidates)) {
    FuzzFail("--seed set to " + std::to_string(seed) + " from no non-negative integer");
  }
  if (g_option->count() > 0 && (!g || !FromSomeDecimal(*g, candidates))) {
    FuzzFail("--g set from no number");
  }
  if (at_option->count() > 0) {
    for (double v : at) {
      if (!FromSomeDecimal(v, candidates)) FuzzFail("--at holds a value from no number");
    }
  }
  return 0;
}
