// Tests of StackThread (automaton/stack_thread.h): the stack it promises, one thread reused,
// exceptions carried back, callers from several threads served one at a time.

#include "automaton/stack_thread.h"

#include <gtest/gtest.h>
#include <pthread.h>

#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

namespace hybrid {
namespace {

constexpr std::size_t kBytes = std::size_t{32} << 20;

// The stack size of the calling thread, as the system reports it.
std::size_t OwnStackBytes() {
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) != 0) return 0;
  std::size_t bytes = 0;
  pthread_attr_getstacksize(&attr, &bytes);
  pthread_attr_destroy(&attr);
  return bytes;
}

TEST(StackThread, RunsTasksOnAThreadWithTheRequestedStack) {
  StackThread thread(kBytes);
  ASSERT_TRUE(thread.running());
  EXPECT_EQ(StackThread::CurrentStackBytes(), 0U);
  std::size_t seen = 0, reported = 0;
  std::thread::id id;
  thread.Run([&] {
    seen = OwnStackBytes();
    reported = StackThread::CurrentStackBytes();
    id = std::this_thread::get_id();
  });
  EXPECT_GE(seen, kBytes);
  EXPECT_EQ(reported, kBytes);
  EXPECT_NE(id, std::this_thread::get_id());
}

TEST(StackThread, ReusesOneThread) {
  StackThread thread(kBytes);
  std::vector<std::thread::id> ids(5);
  for (auto& id : ids) thread.Run([&] { id = std::this_thread::get_id(); });
  for (const auto& id : ids) EXPECT_EQ(id, ids.front());
}

TEST(StackThread, RethrowsWhatTheTaskThrowsAndKeepsServing) {
  StackThread thread(kBytes);
  try {
    thread.Run([] { throw std::runtime_error("from the task"); });
    FAIL() << "nothing thrown";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "from the task");
  }
  int value = 0;
  thread.Run([&] { value = 7; });
  EXPECT_EQ(value, 7);
}

TEST(StackThread, SerialisesCallersFromSeveralThreads) {
  StackThread thread(kBytes);
  int counter = 0;  // not atomic: only the tasks touch it, one at a time
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c) {
    callers.emplace_back([&] {
      for (int i = 0; i < 200; ++i) thread.Run([&] { counter = counter + 1; });
    });
  }
  for (auto& caller : callers) caller.join();
  EXPECT_EQ(counter, 800);
}

TEST(StackThread, DestroyedIdleOrAfterWork) {
  { StackThread idle(kBytes); }
  StackThread used(kBytes);
  used.Run([] {});
  SUCCEED();  // the destructors returned (a hang would time the test out)
}

}  // namespace
}  // namespace hybrid
