#include "automaton/stack_thread.h"

#include <unistd.h>

#include <stdexcept>
#include <utility>

namespace hybrid {
namespace {

// The stack size of the StackThread this thread is, or 0.
thread_local std::size_t current_stack_bytes = 0;

}  // namespace

StackThread::StackThread(std::size_t stack_bytes) : stack_bytes_(stack_bytes), owner_(getpid()) {
  pthread_attr_t attr;
  if (pthread_attr_init(&attr) != 0) return;
  running_ = pthread_attr_setstacksize(&attr, stack_bytes) == 0 &&
             pthread_create(&thread_, &attr, &StackThread::Main, this) == 0;
  pthread_attr_destroy(&attr);
}

StackThread::~StackThread() {
  if (!running()) return;
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  pthread_join(thread_, nullptr);
}

void StackThread::Run(const std::function<void()>& task) {
  if (!running()) throw std::logic_error("no thread to run the task on");
  const std::lock_guard one_at_a_time(run_mutex_);
  std::unique_lock lock(mutex_);
  task_ = &task;
  done_ = false;
  error_ = nullptr;
  changed_.notify_all();
  changed_.wait(lock, [this] { return done_; });
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

bool StackThread::running() const { return running_ && owner_ == getpid(); }

std::size_t StackThread::CurrentStackBytes() { return current_stack_bytes; }

void* StackThread::Main(void* self) {
  auto* thread = static_cast<StackThread*>(self);
  current_stack_bytes = thread->stack_bytes_;
  thread->Serve();
  return nullptr;
}

void StackThread::Serve() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || task_ != nullptr; });
    if (task_ == nullptr) return;  // stop_ and nothing left to run
    const std::function<void()>* task = std::exchange(task_, nullptr);
    lock.unlock();
    std::exception_ptr error;
    try {
      (*task)();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    error_ = error;
    done_ = true;
    changed_.notify_all();
  }
}

}  // namespace hybrid
