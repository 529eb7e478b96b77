#pragma once

#include <pthread.h>
#include <time.h>

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace hybrid {

/// Calls an action once a thread has used a given amount of CPU time: the safety net of the
/// solver queries (PropertyProver), which interrupts a Z3 query where Z3's own resource count
/// does not grow with its work. CPU time of the querying thread, not wall-clock time: other
/// processes on the machine, which delay the query but do not add to its CPU time, cannot change
/// where it fires (the machine's speed still can).
///
/// A watcher thread of its own waits while nothing is armed, and while armed sleeps no longer
/// than the CPU time left (CPU time cannot pass faster than wall-clock time), so it costs no CPU
/// time of note.
class CpuWatchdog {
 public:
  /// `action` is called on the watcher thread when an armed limit is reached (for Z3, the
  /// context's interrupt(), which is safe to call from another thread, also once the query
  /// it was meant for has just returned).
  explicit CpuWatchdog(std::function<void()> action);
  ~CpuWatchdog();

  CpuWatchdog(const CpuWatchdog&) = delete;
  CpuWatchdog& operator=(const CpuWatchdog&) = delete;

  /// From now until Disarm(): calls the action once the calling thread has used `cpu_seconds`
  /// more CPU time. Precondition: not armed.
  void Arm(double cpu_seconds);

  /// Stops watching; returns whether the action was called since Arm(). After it returns, the
  /// action is not running and will not be called.
  bool Disarm();

 private:
  void Watch();

  std::function<void()> action_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool armed_ = false;
  bool fired_ = false;
  bool stop_ = false;
  clockid_t clock_{};      // the CPU clock of the thread that armed
  double deadline_ = 0.0;  // in seconds of that clock
  std::thread watcher_;    // last: started once the fields above exist
};

/// The CPU time `clock` has counted, in seconds.
double CpuSeconds(clockid_t clock);

}  // namespace hybrid
