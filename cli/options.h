#pragma once

// Option values of the `hybrid` command line: numbers in the one decimal syntax of
// automaton/number_syntax.h (docs/cli.md, "Numbers"), refused with the option's name.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "automaton/number_syntax.h"
#include "commands/command_error.h"

namespace hybrid::cli {

namespace options_detail {

// The shortest text that reads back as `v`.
inline std::string Shortest(double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
  return ec == std::errc() ? std::string(buffer, end) : std::string();
}

// `text` as a T (double, or an integer type whose whole range is accepted); throws
// CLI::ValidationError naming `option`.
template <typename T>
T Convert(const std::string& option, const std::string& text) {
  if constexpr (std::is_floating_point_v<T>) {
    const NumberRead<double> r = ReadDecimal(text);
    if (!r.ok()) throw CLI::ValidationError(option, NumberErrorMessage(text, r.error));
    return r.value;
  } else if constexpr (std::is_unsigned_v<T>) {
    constexpr auto hi = static_cast<std::uint64_t>(std::numeric_limits<T>::max());
    const NumberRead<std::uint64_t> r = ReadUnsigned(text, hi);
    if (!r.ok()) {
      throw CLI::ValidationError(
          option, NumberErrorMessage(text, r.error, "[0, " + std::to_string(hi) + "]"));
    }
    return static_cast<T>(r.value);
  } else {
    static_assert(std::is_integral_v<T> && std::is_signed_v<T>);
    constexpr auto lo = static_cast<std::int64_t>(std::numeric_limits<T>::min());
    constexpr auto hi = static_cast<std::int64_t>(std::numeric_limits<T>::max());
    const NumberRead<std::int64_t> r = ReadInteger(text, lo, hi);
    if (!r.ok()) {
      throw CLI::ValidationError(
          option, NumberErrorMessage(text, r.error,
                                     "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]"));
    }
    return static_cast<T>(r.value);
  }
}

// The name messages give an option declared as `names` ("-o,--out" -> "--out").
inline std::string DisplayName(const std::string& names) {
  std::string first, chosen;
  std::size_t begin = 0;
  while (begin <= names.size()) {
    const std::size_t comma = std::min(names.find(',', begin), names.size());
    const std::string piece = names.substr(begin, comma - begin);
    if (first.empty()) first = piece;
    if (chosen.empty() && piece.rfind("--", 0) == 0) chosen = piece;
    begin = comma + 1;
  }
  return chosen.empty() ? first : chosen;
}

template <typename T>
std::string TypeName() {
  return std::is_floating_point_v<T> ? "NUMBER" : "INTEGER";
}

template <typename T>
std::string DefaultText(const T& v) {
  if constexpr (std::is_floating_point_v<T>) {
    return Shortest(v);
  } else {
    return std::to_string(v);
  }
}

}  // namespace options_detail

/// Adds option `name` (e.g. "--depth" or "-o,--out"; the first long name is used in messages)
/// to `app`, taking one number into `*target` (double, or an integer type: int, std::uint64_t,
/// ...) in the decimal syntax of automaton/number_syntax.h; an integer must be a sign and digits
/// within the range of T (an unsigned one not negative). Anything else (empty, hexadecimal, a
/// doubled sign, "inf", "nan", trailing text) is refused by CLI11 with exit code 2 and the
/// message "--NAME: ...". The current value of `*target` is shown as the default.
template <typename T>
CLI::Option* AddNumberOption(CLI::App* app, const std::string& name, T* target,
                             const std::string& description) {
  CLI::Option* option = app->add_option(
      name,
      [target, shown = options_detail::DisplayName(name)](const CLI::results_t& results) {
        *target = options_detail::Convert<T>(shown, results.front());
        return true;
      },
      description);
  option->type_name(options_detail::TypeName<T>());
  option->default_str(options_detail::DefaultText(*target));
  return option;
}

/// As AddNumberOption, for an optional number: `*target` is set when the option is given.
template <typename T>
CLI::Option* AddNumberOption(CLI::App* app, const std::string& name, std::optional<T>* target,
                             const std::string& description) {
  CLI::Option* option = app->add_option(
      name,
      [target, shown = options_detail::DisplayName(name)](const CLI::results_t& results) {
        *target = options_detail::Convert<T>(shown, results.front());
        return true;
      },
      description);
  option->type_name(options_detail::TypeName<T>());
  return option;
}

/// Adds option `name` taking a list of numbers: comma-separated (`--at 0,30,70`), repeated
/// (`--at 0 --at 30`) or both; every element must be a number in the decimal syntax (an empty
/// element, as in "1,,2" or "", is refused). `*target` receives them in order.
inline CLI::Option* AddNumberListOption(CLI::App* app, const std::string& name,
                                        std::vector<double>* target,
                                        const std::string& description) {
  CLI::Option* option = app->add_option(
      name,
      [target, shown = options_detail::DisplayName(name)](const CLI::results_t& results) {
        target->clear();
        for (const std::string& result : results) {
          std::size_t begin = 0;
          while (true) {
            const std::size_t comma = result.find(',', begin);
            const std::string element =
                result.substr(begin, comma == std::string::npos ? comma : comma - begin);
            target->push_back(options_detail::Convert<double>(shown, element));
            if (comma == std::string::npos) break;
            begin = comma + 1;
          }
        }
        return true;
      },
      description);
  option->type_name("NUMBER[,NUMBER...]");
  option->expected(CLI::detail::expected_max_vector_size);
  option->allow_extra_args(false);
  return option;
}

}  // namespace hybrid::cli
