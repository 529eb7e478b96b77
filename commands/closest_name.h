#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace hybrid::cli {

/// The number of single-character insertions, deletions, substitutions and transpositions of
/// adjacent characters that turn `a` into `b` (optimal string alignment distance).
int EditDistance(std::string_view a, std::string_view b);

/// The name of `names` closest to `word` by EditDistance, if it is close enough to be a likely
/// typo: at most max(1, |word| / 3) edits, or `word` a prefix of it (`sim` -> `simulate`). Ties
/// go to the first in `names`. Used to suggest a command for an unknown one.
std::optional<std::string> ClosestName(std::string_view word, std::span<const std::string> names);

}  // namespace hybrid::cli
