#pragma once

#include <pthread.h>
#include <sys/types.h>

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>

namespace hybrid {

/// A thread of its own with a stack of a chosen size, which runs tasks for its callers one at a
/// time: for code whose recursion depth is bounded, but by more than a caller's stack may allow
/// (the model parser). The thread is made once and reused; making one per task costs a thread
/// creation each time and, under AddressSanitizer, memory kept for every thread ever made.
///
/// Run() may be called from any thread; calls are serialised. A task that calls Run() of the
/// StackThread it runs on would wait for itself: check CurrentStackBytes() first and call
/// directly when the stack it runs on is large enough.
class StackThread {
 public:
  /// Starts the thread with a stack of `stack_bytes` bytes (only the pages touched are
  /// committed). If the system cannot make it, running() is false.
  explicit StackThread(std::size_t stack_bytes);

  /// Stops the thread and waits for it to end.
  ~StackThread();

  StackThread(const StackThread&) = delete;
  StackThread& operator=(const StackThread&) = delete;

  /// Whether the thread runs: it was made, and this is the process that made it (a child made
  /// by fork() has no copy of it).
  [[nodiscard]] bool running() const;

  /// Runs `task` on the thread and waits for it; rethrows here what it threw there.
  /// Precondition: running().
  void Run(const std::function<void()>& task);

  /// The stack size of the StackThread the caller runs on, or 0 if it runs on none.
  [[nodiscard]] static std::size_t CurrentStackBytes();

 private:
  static void* Main(void* self);
  void Serve();

  const std::size_t stack_bytes_;
  std::mutex run_mutex_;  // one Run() at a time
  std::mutex mutex_;      // guards the fields below
  std::condition_variable changed_;
  const std::function<void()>* task_ = nullptr;  // the task to run, or null
  std::exception_ptr error_;                     // what the last task threw
  bool done_ = false;                            // the last task has returned
  bool stop_ = false;                            // the destructor asks the thread to end
  bool running_ = false;
  pid_t owner_;  // the process that made the thread
  pthread_t thread_{};
};

}  // namespace hybrid
