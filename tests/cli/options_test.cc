// Tests of the numeric options of the command line (cli/options.h), in process: values in the
// decimal syntax reach their targets (double, int, std::uint64_t, optional, lists); empty values,
// hexadecimal, doubled signs, trailing text, integers out of their type's range and negative
// unsigned values are refused by CLI11 with a ValidationError naming the option.

#include "cli/options.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace hybrid::cli {
namespace {

// Parses `args` (without the program name) with `app`; returns the error message, "" if none.
std::string Parse(CLI::App& app, std::vector<std::string> args) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

struct Targets {
  double x = 1.5;
  int n = 3;
  std::uint64_t seed = 1;
  std::optional<double> g;
  std::vector<double> at;
};

// An app with one option of each kind bound to `t`.
void AddOptions(CLI::App& app, Targets& t) {
  AddNumberOption(&app, "--x", &t.x, "a double");
  AddNumberOption(&app, "-n,--count", &t.n, "an int");
  AddNumberOption(&app, "--seed", &t.seed, "an unsigned");
  AddNumberOption(&app, "--g", &t.g, "an optional double");
  AddNumberListOption(&app, "--at", &t.at, "a list");
}

TEST(NumberOptions, ValuesReachTheirTargets) {
  CLI::App app;
  Targets t;
  AddOptions(app, t);
  EXPECT_EQ(Parse(app, {"--x", "-2.5e-1", "--count", "+010", "--seed", "18446744073709551615",
                        "--g", ".5", "--at", "0,+30,1e2", "--at", "255"}),
            "");
  EXPECT_EQ(t.x, -0.25);
  EXPECT_EQ(t.n, 10);  // decimal: a leading 0 is not octal
  EXPECT_EQ(t.seed, std::numeric_limits<std::uint64_t>::max());
  ASSERT_TRUE(t.g.has_value());
  EXPECT_EQ(*t.g, 0.5);
  EXPECT_EQ(t.at, (std::vector<double>{0.0, 30.0, 100.0, 255.0}));
}

TEST(NumberOptions, UntouchedWithoutTheOption) {
  CLI::App app;
  Targets t;
  AddOptions(app, t);
  EXPECT_EQ(Parse(app, {}), "");
  EXPECT_EQ(t.x, 1.5);
  EXPECT_EQ(t.n, 3);
  EXPECT_FALSE(t.g.has_value());
  EXPECT_TRUE(t.at.empty());
}

TEST(NumberOptions, MalformedValuesAreRefusedNamingTheOption) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  for (const Case& c : std::vector<Case>{
           {{"--x", ""}, "--x: empty: a number is required"},
           {{"--x", "0x10"}, "--x: '0x10' is not a decimal number"},
           {{"--x", "+-1"}, "--x: '+-1' is not a decimal number"},
           {{"--x", "1e999"}, "--x: '1e999' is out of range"},
           {{"--x", "nan"}, "--x: 'nan' is not a decimal number"},
           {{"--x", "1.5abc"}, "--x: '1.5abc' is not a decimal number"},
           {{"--count", ""}, "--count: empty"},
           {{"-n", "1.5"}, "--count: '1.5' is not an integer"},
           {{"--count", "0x10"}, "--count: '0x10' is not a decimal number"},
           {{"--count", "2147483648"},
            "--count: '2147483648' is out of range [-2147483648, "
            "2147483647]"},
           {{"--count", "-2147483649"}, "--count: '-2147483649' is out of range"},
           {{"--seed", "-1"}, "--seed: '-1' is negative; a number >= 0 is required"},
           {{"--seed", "18446744073709551616"}, "--seed: '18446744073709551616' is out of range"},
           {{"--g", ""}, "--g: empty"},
           {{"--at", ""}, "--at: empty"},
           {{"--at", "1,,2"}, "--at: empty"},
           {{"--at", "1,2,"}, "--at: empty"},
           {{"--at", "1,0x2"}, "--at: '0x2' is not a decimal number"},
       }) {
    CLI::App app;
    Targets t;
    AddOptions(app, t);
    const std::string error = Parse(app, c.args);
    EXPECT_EQ(error.rfind(c.message, 0), 0u) << c.args[0] << " '" << c.args[1] << "': " << error;
  }
}

TEST(NumberOptions, ExtremeIntegersOfTheType) {
  CLI::App app;
  Targets t;
  AddOptions(app, t);
  EXPECT_EQ(Parse(app, {"--count", "-2147483648"}), "");
  EXPECT_EQ(t.n, std::numeric_limits<int>::min());
}

}  // namespace
}  // namespace hybrid::cli
