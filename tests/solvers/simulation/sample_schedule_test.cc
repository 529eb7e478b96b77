// Tests of the sample times of a run (solvers/simulation/sample_schedule.h): uniform samples at
// exact multiples of the step, listed ones once per occurrence, and the next time due.

#include "solvers/simulation/sample_schedule.h"

#include <gtest/gtest.h>

namespace hybrid {
namespace {

TEST(SampleScheduleTest, UniformSamplesAtExactMultiples) {
  SimulationOptions options;
  options.sample_step = 0.1;
  SampleSchedule schedule(options, 1.0);
  EXPECT_EQ(schedule.Next(), 0.1);
  EXPECT_FALSE(schedule.TakeUniform(0.05));
  EXPECT_TRUE(schedule.TakeUniform(0.1));
  EXPECT_EQ(schedule.Next(), 0.1 * 2.0);
  EXPECT_FALSE(schedule.TakeUniform(0.1));
  // A stop a little late (an event after the sample time): the next one is still k * step.
  EXPECT_TRUE(schedule.TakeUniform(0.2 + 1e-12));
  EXPECT_EQ(schedule.Next(), 0.1 * 3.0);
  EXPECT_TRUE(schedule.TakeUniform(0.95));
  EXPECT_EQ(schedule.Next(), 1.0);          // the horizon at most
  EXPECT_FALSE(schedule.TakeUniform(1.0));  // the end is recorded anyway
}

TEST(SampleScheduleTest, NoStepNoUniformSamples) {
  SimulationOptions options;
  SampleSchedule schedule(options, 5.0);
  EXPECT_EQ(schedule.Next(), 5.0);
  EXPECT_FALSE(schedule.TakeUniform(2.0));
  EXPECT_FALSE(schedule.TakeListed(5.0));
}

TEST(SampleScheduleTest, ListedSamplesOncePerOccurrence) {
  SimulationOptions options;
  options.sample_step = 1.0;
  options.sample_times = {0.0, 0.5, 0.5, 3.0};
  SampleSchedule schedule(options, 4.0);
  EXPECT_EQ(schedule.Next(), 0.0);
  EXPECT_TRUE(schedule.TakeListed(0.0));
  EXPECT_FALSE(schedule.TakeListed(0.0));
  EXPECT_EQ(schedule.Next(), 0.5);
  int taken = 0;
  while (schedule.TakeListed(0.7)) ++taken;
  EXPECT_EQ(taken, 2);
  EXPECT_EQ(schedule.Next(), 1.0);  // the uniform sample comes first
  EXPECT_TRUE(schedule.TakeUniform(1.0));
  EXPECT_TRUE(schedule.TakeUniform(2.0));
  EXPECT_EQ(schedule.Next(), 3.0);
  EXPECT_TRUE(schedule.TakeListed(3.0));
  EXPECT_TRUE(schedule.TakeUniform(3.0));
  EXPECT_EQ(schedule.Next(), 4.0);
}

}  // namespace
}  // namespace hybrid
