// Tests of Zeno detection (solvers/simulation/zeno_detection.h): geometric shrinking, repeating
// cycles, chattering and accumulation over the last events, and the report of an event iteration
// that does not settle.

#include "solvers/simulation/zeno_detection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "automaton/internal_assert.h"

namespace hybrid {
namespace {

// Events at `times`, the i-th taking the transitions names[i % names.size()].
std::vector<EventRecord> Events(const std::vector<double>& times,
                                const std::vector<std::vector<std::string>>& names) {
  std::vector<EventRecord> events;
  for (size_t i = 0; i < times.size(); ++i) {
    EventRecord e;
    e.time = times[i];
    e.transitions = names[i % names.size()];
    events.push_back(e);
  }
  return events;
}

// Times of a bouncing ball: intervals d, d r, d r^2, ... from t0.
std::vector<double> Geometric(double t0, double d, double r, int n) {
  std::vector<double> times = {t0};
  for (int i = 1; i < n; ++i) {
    times.push_back(times.back() + d);
    d *= r;
  }
  return times;
}

TEST(ZenoDetectionTest, ShrinkGeometrically) {
  double r = -1.0;
  EXPECT_TRUE(ShrinkGeometrically({1.0, 0.5, 0.25}, &r));
  EXPECT_DOUBLE_EQ(r, 0.5);
  EXPECT_FALSE(ShrinkGeometrically({1.0, 1.0, 1.0}, &r));  // r = 1 does not shrink
  EXPECT_DOUBLE_EQ(r, 1.0);
  EXPECT_FALSE(ShrinkGeometrically({1.0, 0.5, 0.4}, &r));  // not one ratio
  r = -1.0;
  EXPECT_FALSE(ShrinkGeometrically({1.0, 0.0, 0.0}, &r));  // not all positive: r left alone
  EXPECT_EQ(r, -1.0);
  EXPECT_THROW(ShrinkGeometrically({1.0}, &r), InternalError);
}

TEST(ZenoDetectionTest, RepeatingCyclesAndNames) {
  EXPECT_EQ(RepeatingCycle({"a", "b", "a", "b"}), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(RepeatingCycle({"a", "a", "a"}), (std::vector<std::string>{"a"}));
  EXPECT_EQ(RepeatingCycle({"b", "a", "b", "a", "b"}), (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(RepeatingCycle({"a", "b", "c"}).empty());
  EXPECT_TRUE(RepeatingCycle({}).empty());
  const auto events = Events({0.0, 1.0, 2.0}, {{"A.t"}, {"A.u", "B.v"}});
  EXPECT_EQ(LastTransitionNames(events, 2), (std::vector<std::string>{"A.u+B.v", "A.t"}));
  EXPECT_TRUE(LastTransitionNames(events, 0).empty());
  EXPECT_THROW(LastTransitionNames(events, 4), InternalError);
}

TEST(ZenoDetectionTest, FewEventsAreNeverZeno) {
  SimulationOptions options;
  EXPECT_FALSE(DetectZeno(Events(std::vector<double>(9, 1.0), {{"t"}}), options));
  EXPECT_TRUE(DetectZeno(Events(std::vector<double>(10, 1.0), {{"t"}}), options));
  options.zeno_events = 0;  // at least 4 events are looked at
  EXPECT_FALSE(DetectZeno(Events(std::vector<double>(3, 1.0), {{"t"}}), options));
  EXPECT_TRUE(DetectZeno(Events(std::vector<double>(4, 1.0), {{"t"}}), options));
}

TEST(ZenoDetectionTest, Chattering) {
  SimulationOptions options;
  const auto z = DetectZeno(Events(std::vector<double>(10, 5.0), {{"on"}, {"off"}}), options);
  ASSERT_TRUE(z);
  EXPECT_EQ(z->report.cycle, (std::vector<std::string>{"on", "off"}));
  EXPECT_EQ(z->report.accumulation_time, 5.0);  // not geometric: the last time
  EXPECT_EQ(z->message, "10 events within 0 time units before t = 5; events accumulate near t = 5");
  // Within the window (1e-6 * max(1, |t|)) or not.
  EXPECT_TRUE(DetectZeno(Events(Geometric(5.0, 1e-7, 1.0, 10), {{"on"}, {"off"}}), options));
  EXPECT_FALSE(DetectZeno(Events(Geometric(5.0, 1e-5, 1.0, 10), {{"on"}, {"off"}}), options));
}

TEST(ZenoDetectionTest, AccumulationNeedsACycleNearItsLimit) {
  SimulationOptions options;
  // A bouncing ball: intervals 1e-3 * 0.5^i; remaining time d_last * r / (1 - r) < 1e-4.
  const auto times = Geometric(2.0, 1e-3, 0.5, 10);
  const auto z = DetectZeno(Events(times, {{"bounce"}}), options);
  ASSERT_TRUE(z);
  const double d_last = times[9] - times[8];
  EXPECT_NEAR(z->report.accumulation_time, times.back() + d_last, 1e-12);
  EXPECT_EQ(z->report.cycle, (std::vector<std::string>{"bounce"}));
  EXPECT_NE(z->message.find("events accumulate near t = "), std::string::npos);
  // Without a repeating cycle, or far from the limit point, it is not Zeno.
  EXPECT_FALSE(DetectZeno(
      Events(times, {{"a"}, {"b"}, {"c"}, {"d"}, {"e"}, {"f"}, {"g"}, {"h"}, {"i"}, {"j"}}),
      options));
  EXPECT_FALSE(DetectZeno(Events(Geometric(2.0, 1.0, 0.5, 10), {{"bounce"}}), options));
}

TEST(ZenoDetectionTest, IterationReportNamesTheLastEvents) {
  const auto events = Events({1, 1, 1, 1, 1, 1, 1, 1, 1, 1}, {{"a"}, {"b", "c"}});
  const ZenoReport z = IterationZenoReport(events, 1.0);
  EXPECT_EQ(z.accumulation_time, 1.0);
  EXPECT_EQ(z.cycle,
            (std::vector<std::string>{"a", "b", "c", "a", "b", "c", "a", "b", "c", "a", "b", "c"}));
  EXPECT_EQ(IterationZenoReport({}, 2.0).cycle.size(), 0u);
}

}  // namespace
}  // namespace hybrid
