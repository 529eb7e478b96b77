// Tests of CpuWatchdog (solvers/verification/cpu_watchdog.h): it counts the armed thread's CPU
// time, not wall-clock time (the property that makes the prover's safety net independent of the
// machine's load), and it stops a real Z3 query without spoiling its context.

#include "solvers/verification/cpu_watchdog.h"

#include <gtest/gtest.h>
#include <z3++.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

namespace hybrid {
namespace {

double ThreadCpuSeconds() { return CpuSeconds(CLOCK_THREAD_CPUTIME_ID); }

TEST(CpuWatchdog, FiresOnceTheArmedThreadHasUsedItsCpuTime) {
  std::atomic<bool> fired{false};
  CpuWatchdog watchdog([&] { fired = true; });
  const double start = ThreadCpuSeconds();
  watchdog.Arm(0.2);
  volatile double sink = 0.0;
  while (!fired && ThreadCpuSeconds() - start < 20.0) sink = sink + 1.0;  // burn CPU time
  EXPECT_TRUE(watchdog.Disarm());
  EXPECT_TRUE(fired);
  EXPECT_GE(ThreadCpuSeconds() - start, 0.2);
}

// A wall-clock limit would fire here: the armed thread waits 0.6 s but uses almost no CPU time,
// as a query does while other processes hold the machine's cores.
TEST(CpuWatchdog, TimeTheThreadDoesNotRunDoesNotCount) {
  std::atomic<int> calls{0};
  CpuWatchdog watchdog([&] { ++calls; });
  watchdog.Arm(0.1);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_FALSE(watchdog.Disarm());
  EXPECT_EQ(calls, 0);
}

TEST(CpuWatchdog, CanBeArmedAgainAfterFiringOrNot) {
  std::atomic<int> calls{0};
  CpuWatchdog watchdog([&] { ++calls; });
  watchdog.Arm(0.0);  // fires at once
  for (int i = 0; i < 2000 && calls == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(watchdog.Disarm());
  watchdog.Arm(100.0);
  EXPECT_FALSE(watchdog.Disarm());
  EXPECT_EQ(calls, 1);
  EXPECT_THROW(
      {
        watchdog.Arm(1.0);
        watchdog.Arm(1.0);
      },
      std::logic_error);
  watchdog.Disarm();
}

// The pigeonhole principle for n + 1 pigeons and n holes: unsatisfiable, and hard for a CDCL
// solver (exponential resolution proofs), so that a small n keeps Z3 busy for long.
void AddPigeonhole(z3::context& ctx, z3::solver& s, int n) {
  auto var = [&](int p, int h) {
    return ctx.bool_const(("p" + std::to_string(p) + "h" + std::to_string(h)).c_str());
  };
  for (int p = 0; p <= n; ++p) {
    z3::expr_vector some(ctx);
    for (int h = 0; h < n; ++h) some.push_back(var(p, h));
    s.add(z3::mk_or(some));
  }
  for (int h = 0; h < n; ++h) {
    for (int p = 0; p <= n; ++p) {
      for (int q = p + 1; q <= n; ++q) s.add(!var(p, h) || !var(q, h));
    }
  }
}

TEST(CpuWatchdog, StopsAZ3QueryAndTheContextStaysUsable) {
  z3::context ctx;
  CpuWatchdog watchdog([&] { ctx.interrupt(); });
  z3::solver hard(ctx);
  AddPigeonhole(ctx, hard, 14);
  watchdog.Arm(0.5);
  const z3::check_result r = hard.check();
  const bool stopped = watchdog.Disarm();
  EXPECT_EQ(r, z3::unknown);
  EXPECT_TRUE(stopped);
  // An interrupt that comes after a query, or between queries, leaves later queries alone.
  ctx.interrupt();
  z3::solver easy(ctx);
  const z3::expr x = ctx.real_const("x");
  easy.add(x > 1 && x < 2);
  EXPECT_EQ(easy.check(), z3::sat);
}

}  // namespace
}  // namespace hybrid
