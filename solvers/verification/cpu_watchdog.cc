#include "solvers/verification/cpu_watchdog.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

namespace hybrid {

double CpuSeconds(clockid_t clock) {
  timespec t{};
  if (clock_gettime(clock, &t) != 0) return 0.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

CpuWatchdog::CpuWatchdog(std::function<void()> action)
    : action_(std::move(action)), watcher_([this] { Watch(); }) {}

CpuWatchdog::~CpuWatchdog() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  watcher_.join();
}

void CpuWatchdog::Arm(double cpu_seconds) {
  clockid_t clock{};
  // The process's CPU clock (which counts this thread's time too) if the thread's is unavailable.
  if (pthread_getcpuclockid(pthread_self(), &clock) != 0) clock = CLOCK_PROCESS_CPUTIME_ID;
  const double now = CpuSeconds(clock);
  {
    const std::lock_guard lock(mutex_);
    if (armed_) throw std::logic_error("the CPU-time watchdog is armed twice");
    clock_ = clock;
    deadline_ = now + std::max(0.0, cpu_seconds);
    armed_ = true;
    fired_ = false;
  }
  changed_.notify_all();
}

bool CpuWatchdog::Disarm() {
  const std::lock_guard lock(mutex_);  // the action runs under this lock: it has finished
  armed_ = false;
  return std::exchange(fired_, false);
}

void CpuWatchdog::Watch() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    if (!armed_) {
      changed_.wait(lock);
      continue;
    }
    const double left = deadline_ - CpuSeconds(clock_);
    if (left <= 0.0) {
      action_();
      fired_ = true;
      armed_ = false;
      continue;
    }
    // The armed thread cannot use more CPU time than the wall-clock time that passes.
    changed_.wait_for(lock, std::chrono::duration<double>(left));
  }
}

}  // namespace hybrid
