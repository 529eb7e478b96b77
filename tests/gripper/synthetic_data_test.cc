// Tests of synthetic measured data (include/hybrid/gripper/synthetic_data.h): the written CSV reads
// back to the same runs; the seed decides the data; noiseless data equal the predictor's angles;
// noise, outliers and missing samples follow the design; the hidden effects outside FingerEffects
// (ripple, theta3 hysteresis) change the angles as documented; bad designs are rejected.

#include "hybrid/gripper/synthetic_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Automaton Finger() {
  return ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha")
      .components()[0]
      .automaton;
}

// One predictor for all tests (its simulators are cached).
const FingerPredictor& Predictor() {
  static const FingerPredictor predictor(Finger());
  return predictor;
}

SyntheticDesign Noiseless(SyntheticDesign design = {}) {
  design.noise_sd = {0.0, 0.0, 0.0};
  design.outlier_probability = 0.0;
  design.missing_probability = 0.0;
  return design;
}

// Same value, NaN equal to NaN.
bool Same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

bool SameData(const MeasuredData& a, const MeasuredData& b) {
  if (a.runs.size() != b.runs.size()) return false;
  for (size_t r = 0; r < a.runs.size(); ++r) {
    const MeasuredRun& x = a.runs[r];
    const MeasuredRun& y = b.runs[r];
    if (x.label != y.label || x.g != y.g || x.position != y.position || x.gob != y.gob ||
        x.contact_link != y.contact_link) {
      return false;
    }
    for (int j = 0; j < 3; ++j) {
      if (x.theta[j].size() != y.theta[j].size()) return false;
      for (size_t k = 0; k < x.theta[j].size(); ++k) {
        if (!Same(x.theta[j][k], y.theta[j][k])) return false;
      }
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// The runs of the design.

TEST(SynthesizeTest, RunsFollowTheDesign) {
  const SyntheticDesign design;
  const MeasuredData data = Synthesize(Predictor(), {}, design);
  const std::vector<std::string> labels = {"free1",   "free2",   "free3",   "free4",   "link1_1",
                                           "link1_2", "link1_3", "link2_1", "link2_2", "link2_3"};
  ASSERT_EQ(data.runs.size(), labels.size());
  EXPECT_EQ(data.samples(), 10 * 512);
  EXPECT_EQ(data.source, "synthetic");
  const std::vector<double> gobs = {80, 80, 100, 170, 170, 190};
  int line = 2;
  for (size_t r = 0; r < labels.size(); ++r) {
    const MeasuredRun& run = data.runs[r];
    SCOPED_TRACE(run.label);
    EXPECT_EQ(run.label, labels[r]);
    if (r < 4) {
      EXPECT_FALSE(run.gob.has_value());
      EXPECT_FALSE(run.contact_link.has_value());
    } else {
      ASSERT_TRUE(run.gob.has_value());
      EXPECT_EQ(*run.gob, gobs[r - 4]);
      EXPECT_EQ(run.contact_link, r < 7 ? 1 : 2);
    }
    ASSERT_EQ(run.g.size(), 512u);
    // The requests, evenly spaced up to 255 and back through the same positions (the report's
    // protocol); the motor the gripper reports stops where the finger stops it: at the palm
    // (240) in free space, else at (255 + g_s) / 2 with g_s where link 2 stopped (at the object,
    // or at its limit 100 counts after link 1 stopped), and stays there until the request comes
    // back below it; whole counts.
    const std::vector<double> g_s = {180, 180, 200, 170, 170, 190};
    const double stop = r < 4 ? 240.0 : (255.0 + g_s[r - 4]) / 2;
    EXPECT_EQ(run.g.front(), 0.0);
    EXPECT_EQ(run.g[255], 255.0);
    EXPECT_EQ(run.g[256], 255.0);
    EXPECT_EQ(run.g.back(), 0.0);
    ASSERT_EQ(run.position.size(), 512u);
    for (int k = 1; k < 256; ++k) {
      EXPECT_NEAR(run.g[k], 255.0 * k / 255.0, 1.0 / 128) << "sample " << k;
      EXPECT_EQ(run.g[k], std::round(run.g[k] * 64) / 64);  // a multiple of 1/64
      EXPECT_EQ(run.g[511 - k], run.g[k]);                  // the same positions, opening
    }
    for (int k = 0; k < 512; ++k) {
      EXPECT_EQ(run.position[k], std::round(run.position[k])) << "sample " << k;
      EXPECT_NEAR(run.position[k], std::min(run.g[k], stop), 0.5 + 1e-6) << "sample " << k;
    }
    // Where the motor is held, link 3 is at its limit (the finger is in phase 4).
    if (r >= 4) {
      const FingerPrediction p = Predictor().Predict(run, FingerEffects{});
      ASSERT_EQ(p.status, SimulationStatus::kCompleted) << p.message;
      for (int k = 0; k < 512; ++k) {
        if (run.g[k] > stop + 1e-6) EXPECT_NEAR(p.theta[2][k], 43.0, 1e-6) << "sample " << k;
      }
    }
    // Repeated runs have identical g.
    if (r > 0 && run.gob == data.runs[r - 1].gob) {
      EXPECT_EQ(run.g, data.runs[r - 1].g);
    }
    ASSERT_EQ(run.lines.size(), 512u);
    EXPECT_EQ(run.lines.front(), line);
    EXPECT_EQ(run.lines.back(), line + 511);
    line += 512;
  }
}

// ---------------------------------------------------------------------------------------------
// Writing and reading back.

TEST(WriteMeasuredDataTest, ReadsBackToTheSameRuns) {
  HiddenEffects hidden;
  hidden.finger.backlash = 3.0;
  hidden.finger.sensor_bias = {0.5, -1.0, 2.0};
  const MeasuredData data = Synthesize(Predictor(), hidden, {});
  std::ostringstream out;
  WriteMeasuredData(out, data, {"synthetic data", "two\nlines"});
  const std::string text = out.str();
  EXPECT_EQ(text.rfind("# synthetic data\n# two\n# lines\nrun,g,position,theta1,theta2,theta3,gob,"
                       "contact_link\n",
                       0),
            0u)
      << text.substr(0, 200);

  std::istringstream in(text);
  const MeasuredData back = ReadMeasuredData(in, "synthetic.csv");
  ASSERT_EQ(back.runs.size(), data.runs.size());
  int missing = 0;
  for (size_t r = 0; r < data.runs.size(); ++r) {
    const MeasuredRun& a = data.runs[r];
    const MeasuredRun& b = back.runs[r];
    SCOPED_TRACE(a.label);
    EXPECT_EQ(b.label, a.label);
    EXPECT_EQ(b.gob, a.gob);
    EXPECT_EQ(b.contact_link, a.contact_link);
    ASSERT_EQ(b.g.size(), a.g.size());
    EXPECT_EQ(b.position, a.position);  // whole counts, written exactly
    for (size_t k = 0; k < a.g.size(); ++k) {
      EXPECT_NEAR(b.g[k], a.g[k], 1e-6);
      for (int j = 0; j < 3; ++j) {
        if (std::isnan(a.theta[j][k])) {
          ++missing;
          EXPECT_TRUE(std::isnan(b.theta[j][k])) << "sample " << k << " joint " << j + 1;
        } else {
          EXPECT_NEAR(b.theta[j][k], a.theta[j][k], 1e-6) << "sample " << k << " joint " << j + 1;
        }
      }
    }
    // The file's lines: three comment lines before the header.
    ASSERT_EQ(b.lines.size(), a.lines.size());
    EXPECT_EQ(b.lines.front(), a.lines.front() + 3);
  }
  EXPECT_GT(missing, 0);  // the design's missing samples were exercised
  // g is written exactly, so the data read back are predicted as generated.
  for (size_t r = 0; r < data.runs.size(); ++r) {
    EXPECT_EQ(back.runs[r].g, data.runs[r].g) << data.runs[r].label;
    const FingerPrediction p = Predictor().Predict(back.runs[r], hidden.finger);
    EXPECT_EQ(p.status, SimulationStatus::kCompleted) << data.runs[r].label << ": " << p.message;
  }
  // Repeated runs stay repeats: the noise floor comes from them.
  EXPECT_EQ(EstimateNoiseFloor(back).method, "repeated_runs");
}

TEST(WriteMeasuredDataTest, FormatsNumbersAndEmptyCells) {
  MeasuredData data;
  MeasuredRun free;
  free.label = "a";
  free.g = {0.0, 254.99999949, 254.9999996, 0.0000001, 12.5};
  free.theta = {{{1.0, kNaN, 0.1234564, -2.0, 3.0},
                 {1e-7, 2.0, 3.0, kNaN, 5.0},
                 {-1e-7, 70.0, 1.5, 2.5, kNaN}}};
  MeasuredRun object = free;
  object.label = "b";
  object.g = {0, 1, 2, 3, 4};
  object.gob = 99.5;
  object.contact_link = 2;
  data.runs = {free, object};
  std::ostringstream out;
  WriteMeasuredData(out, data, {});
  EXPECT_EQ(out.str(),
            "run,g,theta1,theta2,theta3,gob,contact_link\n"
            "a,0,1,0,0,,\n"
            "a,254.999999,,2,70,,\n"
            "a,255,0.123456,3,1.5,,\n"
            "a,0,-2,,2.5,,\n"
            "a,12.5,3,5,,,\n"
            "b,0,1,0,0,99.5,2\n"
            "b,1,,2,70,99.5,2\n"
            "b,2,0.123456,3,1.5,99.5,2\n"
            "b,3,-2,,2.5,99.5,2\n"
            "b,4,3,5,,99.5,2\n");
}

TEST(WriteMeasuredDataTest, RejectsWhatCannotBeReadBack) {
  MeasuredRun run;
  run.label = "r";
  run.g = {0, 1};
  run.theta = {{{0, 0}, {0, 0}, {0, 0}}};
  const auto write = [](const MeasuredRun& r) {
    MeasuredData data;
    data.runs = {r};
    std::ostringstream out;
    WriteMeasuredData(out, data, {});
  };
  EXPECT_NO_THROW(write(run));
  for (const std::string label : {"", "a,b", "a\"", "a\nb", "#a", " a", "a\t"}) {
    MeasuredRun bad = run;
    bad.label = label;
    EXPECT_THROW(write(bad), std::invalid_argument) << "label '" << label << "'";
  }
  MeasuredRun shorter = run;
  shorter.theta[1] = {0};
  EXPECT_THROW(write(shorter), std::invalid_argument);
  MeasuredRun infinite = run;
  infinite.theta[2][1] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write(infinite), std::invalid_argument);
  MeasuredRun nan_g = run;
  nan_g.g[0] = kNaN;
  EXPECT_THROW(write(nan_g), std::invalid_argument);
  MeasuredRun half_object = run;
  half_object.gob = 10.0;
  try {
    write(half_object);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot write measured data: ", 0), 0u) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Randomness.

TEST(SynthesizeTest, TheSeedDecidesTheData) {
  SyntheticDesign design;
  const MeasuredData a = Synthesize(Predictor(), {}, design);
  const MeasuredData b = Synthesize(Predictor(), {}, design);
  EXPECT_TRUE(SameData(a, b));
  design.seed = 2;
  const MeasuredData c = Synthesize(Predictor(), {}, design);
  EXPECT_FALSE(SameData(a, c));
  // Every angle differs (noise on each sample), except where both are missing.
  int equal = 0;
  for (size_t r = 0; r < a.runs.size(); ++r) {
    for (int j = 0; j < 3; ++j) {
      for (size_t k = 0; k < a.runs[r].g.size(); ++k) {
        equal += a.runs[r].theta[j][k] == c.runs[r].theta[j][k];
      }
    }
  }
  EXPECT_EQ(equal, 0);
}

TEST(SynthesizeTest, NoiselessDataEqualThePrediction) {
  const MeasuredData data = Synthesize(Predictor(), {}, Noiseless());
  for (const MeasuredRun& run : data.runs) {
    SCOPED_TRACE(run.label);
    const FingerPrediction p = Predictor().Predict(run, FingerEffects{});
    ASSERT_EQ(p.status, SimulationStatus::kCompleted);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(run.theta[j], p.theta[j]) << "theta" << j + 1;
  }
  // The model: theta1 = m1 g = g / 2 in phase 1 of a free run.
  EXPECT_NEAR(data.runs[0].theta[0][100], data.runs[0].g[100] / 2.0, 1e-6);
}

TEST(SynthesizeTest, NoiseOutliersAndMissingSamplesFollowTheDesign) {
  const SyntheticDesign design;
  SyntheticDesign clean_design = design;
  clean_design.outlier_probability = 0.0;
  const MeasuredData data = Synthesize(Predictor(), {}, design);
  const MeasuredData clean = Synthesize(Predictor(), {}, clean_design);  // same draws
  const MeasuredData truth = Synthesize(Predictor(), {}, Noiseless(design));
  std::array<double, 3> sum_squares = {0, 0, 0};
  std::array<int, 3> count = {0, 0, 0};
  std::array<int, 3> missing = {0, 0, 0};
  int outliers = 0;
  int theta3_present = 0;
  for (size_t r = 0; r < data.runs.size(); ++r) {
    for (int j = 0; j < 3; ++j) {
      for (size_t k = 0; k < data.runs[r].g.size(); ++k) {
        const double x = data.runs[r].theta[j][k];
        const double x_clean = clean.runs[r].theta[j][k];
        ASSERT_EQ(std::isnan(x), std::isnan(x_clean));  // missing samples do not move
        if (std::isnan(x)) {
          ++missing[j];
          continue;
        }
        if (j == 2) {
          ++theta3_present;
          if (x != x_clean) {
            ++outliers;
            EXPECT_GE(std::abs(x - x_clean), 10.0 - 1e-9);
            EXPECT_LE(std::abs(x - x_clean), 25.0 + 1e-9);
            continue;
          }
        } else {
          EXPECT_EQ(x, x_clean);  // outliers on theta3 only
        }
        const double e = x - truth.runs[r].theta[j][k];
        sum_squares[j] += e * e;
        ++count[j];
      }
    }
  }
  for (int j = 0; j < 3; ++j) {
    const double sd = std::sqrt(sum_squares[j] / count[j]);
    std::printf("theta%d: noise sd %.4f (design %.2f), %d missing of %d\n", j + 1, sd,
                design.noise_sd[j], missing[j], data.samples());
    EXPECT_NEAR(sd, design.noise_sd[j], 0.05 * design.noise_sd[j]) << "theta" << j + 1;
    // Missing samples: binomial, within 4 standard deviations.
    const double n = data.samples();
    const double p = design.missing_probability;
    EXPECT_NEAR(missing[j], n * p, 4.0 * std::sqrt(n * p * (1 - p))) << "theta" << j + 1;
  }
  const double p = design.outlier_probability;
  const double expected = theta3_present * p;
  std::printf("theta3: %d outliers, expected %.1f\n", outliers, expected);
  EXPECT_NEAR(outliers, expected, 4.0 * std::sqrt(expected * (1 - p)));

  // The report's rule (5 degrees) clamps about as many samples of theta3.
  MeasuredData cleaned = data;
  const OutlierReport report = CleanOutliers(cleaned);
  EXPECT_NEAR(report.clamped[2], outliers, 0.1 * outliers);
}

TEST(SynthesizeTest, NoiseFloorFromRepeatedRuns) {
  SyntheticDesign design;
  design.outlier_probability = 0.0;
  const NoiseFloor floor = EstimateNoiseFloor(Synthesize(Predictor(), {}, design));
  EXPECT_EQ(floor.method, "repeated_runs");
  for (int j = 0; j < 3; ++j) {
    const double variance = design.noise_sd[j] * design.noise_sd[j];
    std::printf("theta%d: noise floor variance %.4f (design %.4f), dof %d\n", j + 1,
                floor.variance[j], variance, floor.dof[j]);
    EXPECT_NEAR(floor.variance[j], variance, 0.1 * variance) << "theta" << j + 1;
  }
}

// ---------------------------------------------------------------------------------------------
// Hidden effects.

// Every run completes under effects that move where the finger stops the motor, and its angles
// are the predictor's for its (stopped) motor path.
TEST(SynthesizeTest, FingerEffectsGoThroughThePredictor) {
  std::vector<FingerEffects> cases(4);
  cases[0].backlash = 4.0;
  cases[0].motor_offset = -2.0;
  cases[0].compliance = {0.05, 0.0};
  cases[1].motor_offset = 3.0;
  cases[1].theta3_fraction = 0.4;
  cases[1].sensor_bias = {0.0, 0.0, 1.5};
  cases[2].joint_max = {65.0, 80.0, 40.0};
  cases[2].compliance = {0.0, 0.03};
  cases[3].theta3_fraction = 0.7;
  cases[3].backlash = 2.0;
  cases[3].motor_offset = 1.0;
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE("case " + std::to_string(c));
    HiddenEffects hidden;
    hidden.finger = cases[c];
    const MeasuredData data = Synthesize(Predictor(), hidden, Noiseless());
    for (const MeasuredRun& run : data.runs) {
      const FingerPrediction p = Predictor().Predict(run, hidden.finger);
      for (int j = 0; j < 3; ++j) EXPECT_EQ(run.theta[j], p.theta[j]) << run.label;
    }
  }
  // With ripple too (on every run, the object runs included).
  HiddenEffects rippled;
  rippled.finger = cases[1];
  rippled.ripple_amplitude = 2.0;
  rippled.ripple_period = 25.0;
  const MeasuredData data = Synthesize(Predictor(), rippled, Noiseless());
  for (const MeasuredRun& run : data.runs) {
    for (int j = 0; j < 3; ++j) {
      for (const double x : run.theta[j]) EXPECT_TRUE(std::isfinite(x)) << run.label;
    }
  }
}

TEST(SynthesizeTest, RippleShiftsTheDrivePosition) {
  HiddenEffects hidden;
  hidden.ripple_amplitude = 3.0;
  hidden.ripple_period = 40.0;
  const double m1 = 0.5;  // theta1_max / 140
  const MeasuredData base = Synthesize(Predictor(), {}, Noiseless());
  const MeasuredData rippled = Synthesize(Predictor(), hidden, Noiseless());
  double largest = 0.0;
  for (size_t r = 0; r < 4; ++r) {  // the free runs
    const MeasuredRun& a = base.runs[r];
    const MeasuredRun& b = rippled.runs[r];
    EXPECT_EQ(a.g, b.g);  // the data keep the nominal g
    for (size_t k = 0; k < a.g.size(); ++k) {
      const double g = a.g[k];
      const double d = b.theta[0][k] - a.theta[0][k];
      EXPECT_LE(std::abs(d), m1 * hidden.ripple_amplitude + 1e-6) << "g " << g;
      largest = std::max(largest, std::abs(d));
      if (g + hidden.ripple_amplitude < 140.0) {  // phase 1 for both
        EXPECT_NEAR(d, m1 * hidden.ripple_amplitude * std::sin(2 * std::numbers::pi * g / 40.0),
                    1e-6)
            << "g " << g;
      }
    }
  }
  EXPECT_GT(largest, 0.95 * m1 * hidden.ripple_amplitude);
  // The object runs differ too.
  EXPECT_NE(base.runs[4].theta[0], rippled.runs[4].theta[0]);
}

TEST(SynthesizeTest, HysteresisFollowsTheDirection) {
  HiddenEffects hidden;
  hidden.theta3_hysteresis = 1.5;
  const MeasuredData base = Synthesize(Predictor(), {}, Noiseless());
  const MeasuredData lagged = Synthesize(Predictor(), hidden, Noiseless());
  for (size_t r = 0; r < base.runs.size(); ++r) {
    const MeasuredRun& a = base.runs[r];
    const MeasuredRun& b = lagged.runs[r];
    SCOPED_TRACE(a.label);
    EXPECT_EQ(b.theta[0], a.theta[0]);
    EXPECT_EQ(b.theta[1], a.theta[1]);
    const size_t half = a.g.size() / 2;
    for (size_t k = 0; k < a.g.size(); ++k) {
      EXPECT_NEAR(b.theta[2][k] - a.theta[2][k], k < half ? 1.5 : -1.5, 1e-12) << "sample " << k;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Bad designs.

TEST(SynthesizeTest, RejectsBadDesigns) {
  const auto expect_throw = [](const SyntheticDesign& design, const HiddenEffects& hidden,
                               const std::string& what) {
    try {
      Synthesize(Predictor(), hidden, design);
      ADD_FAILURE() << what << ": no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("synthetic data: ", 0), 0u) << what << ": " << e.what();
    }
  };
  const auto with = [](auto change) {
    SyntheticDesign design;
    change(design);
    return design;
  };
  const HiddenEffects none;
  expect_throw(with([](SyntheticDesign& d) { d.samples_per_run = 8; }), none, "8 samples");
  expect_throw(with([](SyntheticDesign& d) { d.samples_per_run = 13; }), none, "odd samples");
  expect_throw(with([](SyntheticDesign& d) { d.noise_sd[1] = -0.1; }), none, "negative noise");
  expect_throw(with([](SyntheticDesign& d) { d.noise_sd[2] = kNaN; }), none, "NaN noise");
  expect_throw(with([](SyntheticDesign& d) { d.outlier_probability = -0.01; }), none,
               "negative outlier probability");
  expect_throw(with([](SyntheticDesign& d) { d.outlier_probability = 1.5; }), none,
               "outlier probability above 1");
  expect_throw(with([](SyntheticDesign& d) { d.missing_probability = kNaN; }), none,
               "NaN missing probability");
  expect_throw(with([](SyntheticDesign& d) { d.missing_probability = 2.0; }), none,
               "missing probability above 1");
  expect_throw(with([](SyntheticDesign& d) { d.free_runs = -1; }), none, "negative free runs");
  expect_throw(with([](SyntheticDesign& d) { d.link2_gob = {300}; }), none, "gob above 255");
  // Sizes are capped before anything is allocated (2e9 free runs asked for 7.9 GB).
  expect_throw(with([](SyntheticDesign& d) { d.free_runs = 2000000000; }), none, "2e9 free runs");
  expect_throw(with([](SyntheticDesign& d) { d.free_runs = kMaxSyntheticFreeRuns + 1; }), none,
               "one free run more than the cap");
  expect_throw(with([](SyntheticDesign& d) { d.samples_per_run = 2000000000; }), none,
               "2e9 samples per run");
  expect_throw(with([](SyntheticDesign& d) {
                 d.free_runs = 0;
                 d.link1_gob.assign(2, 80.0);
                 d.link2_gob.clear();
                 d.samples_per_run = static_cast<int>(kMaxSyntheticSamples / 2 + 2);
               }),
               none, "one run's rows more than the cap");
  expect_throw(with([](SyntheticDesign& d) {
                 d.free_runs = 0;
                 d.link1_gob.clear();
                 d.link2_gob.clear();
               }),
               none, "no runs");
  HiddenEffects bad_period;
  bad_period.ripple_period = 0.0;
  expect_throw({}, bad_period, "zero ripple period");
  HiddenEffects bad_hysteresis;
  bad_hysteresis.theta3_hysteresis = kNaN;
  expect_throw({}, bad_hysteresis, "NaN hysteresis");
  // The predictor's own checks.
  HiddenEffects bad_backlash;
  bad_backlash.finger.backlash = -1.0;
  EXPECT_THROW(Synthesize(Predictor(), bad_backlash, {}), std::invalid_argument);
  // The smallest design is fine: probabilities 0 and 1, no noise.
  SyntheticDesign smallest;
  smallest.samples_per_run = 10;
  smallest.free_runs = 1;
  smallest.link1_gob.clear();
  smallest.link2_gob.clear();
  smallest.outlier_probability = 1.0;
  smallest.missing_probability = 0.0;
  const MeasuredData data = Synthesize(Predictor(), {}, smallest);
  ASSERT_EQ(data.samples(), 10);
  smallest.outlier_probability = 0.0;
  const MeasuredData no_outliers = Synthesize(Predictor(), {}, smallest);
  for (int k = 0; k < 10; ++k) {
    const double jump = std::abs(data.runs[0].theta[2][k] - no_outliers.runs[0].theta[2][k]);
    EXPECT_TRUE(jump >= 10.0 - 1e-9 && jump <= 25.0 + 1e-9) << jump;
  }
  smallest.missing_probability = 1.0;
  const MeasuredData all_missing = Synthesize(Predictor(), {}, smallest);
  for (const auto& theta : all_missing.runs[0].theta) {
    for (const double x : theta) EXPECT_TRUE(std::isnan(x));
  }
}

// ---------------------------------------------------------------------------------------------
// Timing (printed, not asserted).

TEST(SynthesizeTest, TimeOfTheDefaultDesign) {
  const FingerPredictor fresh(Finger());  // no cached simulators
  const SyntheticDesign design;
  const auto t0 = std::chrono::steady_clock::now();
  const MeasuredData data = Synthesize(fresh, {}, design);
  const auto t1 = std::chrono::steady_clock::now();
  Synthesize(fresh, {}, design);
  const auto t2 = std::chrono::steady_clock::now();
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  std::printf(
      "Synthesize, default design (%zu runs, %d samples): %.1f ms with a fresh predictor, "
      "%.1f ms with its simulators cached\n",
      data.runs.size(), data.samples(), ms(t1 - t0), ms(t2 - t1));
}

}  // namespace
}  // namespace hybrid
