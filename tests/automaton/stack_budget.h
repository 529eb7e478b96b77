#pragma once

// Running code on a small, fixed stack: the check that the recursive walks of the IR fit the stack
// budget its depth limits are chosen for (kMaxExpressionDepth, kMaxTreeDepth in
// include/hybrid/automaton/expression.h), in every build, sanitized ones included.

#include <gtest/gtest.h>
#include <pthread.h>

#include <cstddef>
#include <exception>
#include <functional>

namespace hybrid::testing {

/// The stack every model-handling path must fit in: `ulimit -s 1024`.
inline constexpr std::size_t kOneMebibyte = std::size_t{1} << 20;

/// Runs `f` on a new thread whose stack is `bytes` large and rethrows what `f` throws. Overflowing
/// that stack crashes the test program (a segmentation fault, or AddressSanitizer's stack-overflow
/// report), so a passing call shows that `f` fits in `bytes`.
inline void RunOnStack(std::size_t bytes, const std::function<void()>& f) {
  struct Call {
    const std::function<void()>* f;
    std::exception_ptr error;
  } call{&f, nullptr};
  auto body = [](void* p) -> void* {
    auto* c = static_cast<Call*>(p);
    try {
      (*c->f)();
    } catch (...) {
      c->error = std::current_exception();
    }
    return nullptr;
  };
  pthread_attr_t attr;
  ASSERT_EQ(pthread_attr_init(&attr), 0);
  ASSERT_EQ(pthread_attr_setstacksize(&attr, bytes), 0);
  pthread_t thread;
  ASSERT_EQ(pthread_create(&thread, &attr, body, &call), 0);
  ASSERT_EQ(pthread_join(thread, nullptr), 0);
  pthread_attr_destroy(&attr);
  if (call.error) std::rethrow_exception(call.error);
}

}  // namespace hybrid::testing
