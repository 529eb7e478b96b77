#pragma once

// The one internal assertion of the libraries: HYBRID_ASSERT(condition, "what must hold") states
// an invariant the code relies on (an index in range, a state the caller has already checked).
// It is always on (Release too: the checks are cheap next to the numerics they guard). A failed
// assertion is a bug of hybrid, never a bad model or bad input (those are refused with a message
// for the user): it throws InternalError naming the source position and the broken invariant,
// which the program reports as an internal error (exit code 4) and Python as RuntimeError.

#include <stdexcept>
#include <string>

namespace hybrid {

/// A broken internal invariant (HYBRID_ASSERT): a bug, reported with the source position.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace internal {
[[noreturn]] inline void AssertionFailed(const char* condition, const char* what, const char* file,
                                         int line) {
  throw InternalError(std::string("internal error (a bug of hybrid, please report it): ") + what +
                      " [" + condition + " failed at " + file + ":" + std::to_string(line) + "]");
}
}  // namespace internal

}  // namespace hybrid

/// Throws hybrid::InternalError unless `condition` holds; `what` (a string literal) says in words
/// what must hold.
#define HYBRID_ASSERT(condition, what)                                                           \
  do {                                                                                           \
    if (!(condition)) ::hybrid::internal::AssertionFailed(#condition, what, __FILE__, __LINE__); \
  } while (false)
