#pragma once

// Messages of the `hybrid` command line speak of the model, the data and the options, never of
// C++ functions: the prefixes that lower layers put in front of their exception messages
// ("System::SetParameter: ", "Simulator::Run: ", "GeometricFinger: ", ...) are removed before a
// message is shown, and messages of exceptions that name C++ types ("std::bad_alloc",
// "vector::_M_realloc_insert", "[json.exception...]") are never shown.

#include <array>
#include <cctype>
#include <string>
#include <string_view>

namespace hybrid::cli {

namespace user_message_detail {

inline bool IsIdentifierChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

// Whether `at` starts a segment of the message: its start, or after ": ", "(" or "; ".
inline bool StartsSegment(const std::string& s, std::size_t at) {
  if (at == 0) return true;
  if (s[at - 1] == '(') return true;
  return at >= 2 && (s.compare(at - 2, 2, ": ") == 0 || s.compare(at - 2, 2, "; ") == 0);
}

}  // namespace user_message_detail

/// `what` without C++ API prefixes: every "Name::name: " (any qualified name followed by ": ")
/// and every "Class: " of the classes and functions that prefix their messages (Hand,
/// GeometricFinger, Obstacle, Synthesize, ...) at the start of a segment of the message (its
/// start, or after ": ", "; " or "(").
inline std::string UserMessage(std::string_view what) {
  using user_message_detail::IsIdentifierChar;
  std::string s(what);
  // Qualified names: "A::B: ", "A::B::C: ".
  for (std::size_t at = s.find("::"); at != std::string::npos; at = s.find("::", at)) {
    std::size_t begin = at;
    while (begin > 0 && IsIdentifierChar(s[begin - 1])) --begin;
    std::size_t end = at;
    while (end + 1 < s.size() && s.compare(end, 2, "::") == 0) {
      end += 2;
      while (end < s.size() && IsIdentifierChar(s[end])) ++end;
    }
    if (begin < at && s.compare(end, 2, ": ") == 0) {
      s.erase(begin, end + 2 - begin);
      at = begin;
    } else {
      at = end > at ? end : at + 2;
    }
  }
  static constexpr std::array<std::string_view, 12> kPrefixes = {"Hand: ",
                                                                 "GeometricFinger: ",
                                                                 "Obstacle: ",
                                                                 "Synthesize: ",
                                                                 "Diagnose: ",
                                                                 "WriteMeasuredData: ",
                                                                 "FingerPredictor: ",
                                                                 "CleanOutliers: ",
                                                                 "Simulator: ",
                                                                 "System: ",
                                                                 "Automaton: ",
                                                                 "DiagnosisReportFiles: "};
  for (bool changed = true; changed;) {
    changed = false;
    for (const std::string_view prefix : kPrefixes) {
      for (std::size_t at = s.find(prefix); at != std::string::npos; at = s.find(prefix, at + 1)) {
        if (!user_message_detail::StartsSegment(s, at)) continue;
        s.erase(at, prefix.size());
        changed = true;
        break;
      }
    }
  }
  return s;
}

/// Whether `what` (the message of an unexpected exception) names C++ internals and must not be
/// shown: "std::...", "...::_M_...", "basic_string...", "bad_alloc", nlohmann's "[json.exception".
inline bool NamesCppInternals(std::string_view what) {
  for (const std::string_view marker :
       {"std::", "::", "_M_", "basic_string", "bad_alloc", "bad_array", "bad_function", "bad_cast",
        "bad_any", "bad_optional", "bad_variant", "[json.exception", "vector", "__"}) {
    if (what.find(marker) != std::string_view::npos) return true;
  }
  return what.empty();
}

}  // namespace hybrid::cli
