// Tests of Diagnose (include/hybrid/gripper/finger_diagnosis.h) on data that hide an effect:
// synthetic runs of the finger model (include/hybrid/gripper/synthetic_data.h) with the report's
// measurement noise (0.7 deg on theta1 and theta2, 1.2 deg on theta3, outliers on theta3, missing
// samples), written to CSV and read back, so that the diagnosis sees only what `hybrid diagnose
// DATA.csv` sees.
//
// - Deterministic cases: `none` on clean data, one cause, two causes, the effects outside the
//   list (`unexplained` with `where`), bad input.
// - DiagnosisProperty.NamesTheHiddenEffect: rapidcheck draws the effect (each cause, with each
//   joint, link and direction, `none`, and two effects outside the list: gear ripple and theta3
//   hysteresis), its size on a log scale from below detectable to large, and the noise seed.
//   From the measured detectability threshold of its kind (Kinds()) the diagnosis must name it
//   (with its parameter within 15%) in at least 95% of draws; below the threshold it must not
//   name a cause of another kind (checked per draw, shrunk by rapidcheck). Where Diagnose is
//   known to break the law (a kind that never reaches 95%, sizes above a ceiling, false alarms
//   below a size) Kinds() says so and the draws are reported, not checked.
//   Each draw costs one Diagnose (1-2 s), so the property runs HYBRID_DIAGNOSE_DRAWS draws
//   (default 24, about 40 s) whatever RC_PARAMS's max_success; RC_PARAMS still gives the seed
//   (CTest pins it; the draws of a longer run start with those of a shorter one) and
//   `reproduce` / `noshrink`. HYBRID_DIAGNOSE_LOG=1 prints every draw as a CSV row.
// - DiagnosisDetectability.Sweep (skipped unless HYBRID_DIAGNOSE_SWEEP is set): the measurement
//   behind Kinds()' thresholds and docs/diagnosis_detectability.md, a grid of sizes x seeds.
//
// Each diagnosis runs on one thread (two test processes can share a machine).

#include "hybrid/gripper/finger_diagnosis.h"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_effects.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"
#include "hybrid/gripper/synthetic_data.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/robotiq_rig.h"

namespace hybrid {
namespace {

using testing::SpecText;

// spec/finger.ha's automaton, parsed once.
const Automaton& Finger() {
  static const Automaton finger =
      ParseModel(SpecText("finger"), "finger.ha").components()[0].automaton;
  return finger;
}

// The documented defaults, on one thread so that two test processes can share a machine.
FingerDiagnosisOptions Options() {
  FingerDiagnosisOptions options;
  options.threads = 1;
  return options;
}

// The whole pipeline as the tools run it: `hybrid synthesize` (the default design: 4 free runs,
// 3 runs against link 1, 3 against link 2, 512 samples each, the report's noise, outliers and
// missing samples, drawn from `seed`), the CSV it writes, and `hybrid diagnose` reading that CSV.
// Like the tools, each call has its own predictors (synthesize: the default, accurate
// integration; diagnose: FastOptions): a predictor caches a simulator for every effect it is
// asked about and never evicts one, so that one predictor shared by hundreds of diagnoses grows
// by tens of MB per diagnosis.
Diagnosis DiagnoseSynthetic(const HiddenEffects& hidden, std::uint64_t seed) {
  SyntheticDesign design;
  design.seed = seed;
  const MeasuredData data = Synthesize(FingerPredictor(Finger()), hidden, design);
  std::ostringstream csv;
  WriteMeasuredData(csv, data, {"SYNTHETIC data (diagnosis_test)"});
  std::istringstream in(csv.str());
  MeasuredData read = ReadMeasuredData(in, "synthetic.csv");
  const FingerPredictor predictor(Finger(), FingerPredictor::FastOptions());
  return Diagnose(predictor, std::move(read), Options());
}

// The fitted value of `p`, if the diagnosis names it.
std::optional<double> Fitted(const Diagnosis& d, const EffectParameter& p) {
  for (const auto& [q, v] : d.parameters) {
    if (q == p) return v;
  }
  return std::nullopt;
}

std::string Describe(const Diagnosis& d) {
  std::ostringstream s;
  for (size_t i = 0; i < d.cause.size(); ++i) s << (i ? "+" : "") << d.cause[i];
  for (const auto& [p, v] : d.parameters) s << " " << ParameterName(p) << "=" << v;
  if (d.where) {
    s << " where=theta" << d.where->channel + 1 << "/" << d.where->mode << "/"
      << (d.where->direction > 0 ? "closing" : "opening");
  }
  return s.str();
}

constexpr EffectParameter kBacklash{Cause::kBacklash, 0};
constexpr EffectParameter kTheta3Bias{Cause::kSensorBias, 2};

// ---------------------------------------------------------------------------------------------
// Deterministic cases.

TEST(DiagnoseTest, CleanDataIsNone) {
  const Diagnosis d = DiagnoseSynthetic({}, 3);
  EXPECT_EQ(d.cause, std::vector<std::string>{"none"}) << Describe(d);
  EXPECT_TRUE(d.parameters.empty()) << Describe(d);
  EXPECT_FALSE(d.where.has_value()) << Describe(d);
  EXPECT_EQ(d.samples, 10 * 512);
  EXPECT_EQ(d.curves.size(), 10u);
}

TEST(DiagnoseTest, NamesBacklashWithItsPlay) {
  HiddenEffects hidden;
  hidden.finger.backlash = 6.0;
  const Diagnosis d = DiagnoseSynthetic(hidden, 3);
  EXPECT_EQ(d.cause, std::vector<std::string>{"backlash"}) << Describe(d);
  const std::optional<double> b = Fitted(d, kBacklash);
  ASSERT_TRUE(b.has_value()) << Describe(d);
  EXPECT_NEAR(*b, 6.0, 0.15 * 6.0);
  EXPECT_DOUBLE_EQ(d.effects.backlash, *b);
  EXPECT_FALSE(d.where.has_value()) << Describe(d);
  // The extended model brings every joint down to the noise floor.
  for (int j = 0; j < 3; ++j) {
    EXPECT_LT(d.extended_mse[j], d.baseline_mse[j]) << "theta" << j + 1;
    EXPECT_LT(d.extended_mse[j], 1.2 * d.noise.variance[j]) << "theta" << j + 1;
  }
}

TEST(DiagnoseTest, NamesTwoCauses) {
  HiddenEffects hidden;
  hidden.finger.backlash = 6.0;
  hidden.finger.sensor_bias[2] = 2.5;
  const Diagnosis d = DiagnoseSynthetic(hidden, 3);
  std::vector<std::string> causes = d.cause;
  std::sort(causes.begin(), causes.end());
  EXPECT_EQ(causes, (std::vector<std::string>{"backlash", "sensor_bias"})) << Describe(d);
  const std::optional<double> b = Fitted(d, kBacklash);
  const std::optional<double> bias = Fitted(d, kTheta3Bias);
  ASSERT_TRUE(b.has_value()) << Describe(d);
  ASSERT_TRUE(bias.has_value()) << Describe(d);
  EXPECT_NEAR(*b, 6.0, 0.15 * 6.0);
  EXPECT_NEAR(*bias, 2.5, 0.15 * 2.5);
}

TEST(DiagnoseTest, GearRippleIsUnexplained) {
  HiddenEffects hidden;
  hidden.ripple_amplitude = 4.0;
  const Diagnosis d = DiagnoseSynthetic(hidden, 3);
  EXPECT_EQ(d.cause, std::vector<std::string>{"unexplained"}) << Describe(d);
  ASSERT_TRUE(d.where.has_value()) << Describe(d);
  EXPECT_LE(d.where->input_min, d.where->input_max);
  EXPECT_GT(d.where->excess, 0.0);
}

TEST(DiagnoseTest, Theta3HysteresisIsUnexplainedOnTheta3) {
  HiddenEffects hidden;
  hidden.theta3_hysteresis = 2.0;
  const Diagnosis d = DiagnoseSynthetic(hidden, 3);
  EXPECT_EQ(d.cause, std::vector<std::string>{"unexplained"}) << Describe(d);
  ASSERT_TRUE(d.where.has_value()) << Describe(d);
  EXPECT_EQ(d.where->channel, 2) << Describe(d);
  EXPECT_LE(d.where->input_min, d.where->input_max);
  // A direction-dependent offset: the baseline residual of theta3 differs between closing and
  // opening by about 2 h.
  EXPECT_NEAR(d.direction_difference[2], 4.0, 1.0);
}

TEST(DiagnoseTest, NoRunsThrows) {
  MeasuredData empty;
  empty.source = "empty.csv";
  const FingerPredictor predictor(Finger(), FingerPredictor::FastOptions());
  EXPECT_THROW(Diagnose(predictor, empty, Options()), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Hidden effects drawn by rapidcheck.

// What a kind hides besides the listed parameters.
enum class Other { kListed, kNone, kRipple, kHysteresis };

// One kind of hidden effect. The size is the effect's magnitude: the play, the offset, the bias,
// the yield rate, the ripple amplitude, the hysteresis, and for joint_range and theta3_law the
// deviation |value - model's value|; `sign` +1 or -1 fixes the direction (the value is the
// model's plus or minus the size), 0 draws both. Sizes are drawn on a log scale over
// [low, high], from below the detectability threshold to large.
//
// The law, with the numbers measured by DiagnosisDetectability.Sweep (HEAD de27bd3; see
// docs/diagnosis_detectability.md for the data):
// - from `threshold` (the detectability threshold: the smallest size from which every size
//   measured was named correctly in >= 95% of its draws) up to `ceiling`, >= 95% of the draws are
//   named correctly (Verdict::hit; checked over all such draws of a run);
// - below the threshold, no cause of another kind is named (checked per draw), from `quiet` on:
//   below `quiet` the diagnosis is known to raise false alarms;
// - kinds where the 95% law holds at no size have threshold kInf; draws above the ceiling and
//   below `quiet` are only reported. `note` says why (known failures of Diagnose, see the docs):
//   these are failures of the law, marked here rather than hidden by narrower size ranges.
struct KindSpec {
  const char* name;
  const char* unit;
  std::optional<EffectParameter> parameter;
  Other other;
  int sign;
  double low, high;
  double threshold, ceiling, quiet;
  const char* note;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

// Why the outlier rule matters: Diagnose first applies the report's rule (a change of more than
// 5 deg from one sample to the next is clamped), but in phase 3 theta3 moves 2-4 deg per sample
// in these runs, more with noise, and effects that speed it up get genuine samples clamped:
// the clamped residual is systematic and the diagnosis says `unexplained` (with
// FingerDiagnosisOptions::outlier_threshold = 1000 the same data are named correctly).
const std::vector<KindSpec>& Kinds() {
  using P = EffectParameter;
  static const std::vector<KindSpec> kinds = {
      {"backlash", "count", kBacklash, Other::kListed, 1, 0.3, 15, 0.6, kInf, 0.6,
       "below 0.6 count a play is named as a sensor bias or theta2_max (false alarm)"},
      {"motor_offset+", "count", P{Cause::kMotorOffset, 0}, Other::kListed, 1, 0.5, 15, 1.4, kInf,
       0, "below 1.4 count the fit is about 0.2 count low (more than 15%)"},
      {"motor_offset-", "count", P{Cause::kMotorOffset, 0}, Other::kListed, -1, 0.5, 15, kInf, kInf,
       0,
       "law not met: below 1.7 count the fit is about 0.2 count too negative (more than 15%); "
       "from 2 counts 10-100% of draws are unexplained (outlier rule)"},
      {"theta1_max", "deg", P{Cause::kJointRange, 0}, Other::kListed, 0, 0.1, 20, 0.2, kInf, 0, ""},
      {"theta2_max", "deg", P{Cause::kJointRange, 1}, Other::kListed, 0, 0.2, 20, 0.4, kInf, 0, ""},
      {"theta3_max+", "deg", P{Cause::kJointRange, 2}, Other::kListed, 1, 0.3, 20, 0.7, 7, 0,
       "above 7 deg 12-75% of draws are unexplained (outlier rule)"},
      {"theta3_max-", "deg", P{Cause::kJointRange, 2}, Other::kListed, -1, 0.2, 20, 0.5, kInf, 0,
       ""},
      {"theta1_bias", "deg", P{Cause::kSensorBias, 0}, Other::kListed, 0, 0.05, 5, 0.12, kInf, 0.1,
       "below 0.1 deg sometimes named theta1_max (false alarm)"},
      {"theta2_bias", "deg", P{Cause::kSensorBias, 1}, Other::kListed, 0, 0.05, 5, 0.1, kInf, 0,
       ""},
      {"theta3_bias", "deg", kTheta3Bias, Other::kListed, 0, 0.1, 5, 0.3, kInf, 0, ""},
      {"compliance_link1", "deg/count", P{Cause::kCompliance, 0}, Other::kListed, 1, 0.003, 0.1,
       0.006, kInf, 0.006,
       "below 0.006 deg/count sometimes named theta1_bias (false alarm), or compliance with "
       "compliance_link1 = 0"},
      {"compliance_link2", "deg/count", P{Cause::kCompliance, 1}, Other::kListed, 1, 0.003, 0.1,
       0.0075, kInf, 0, ""},
      {"theta3_fraction+", "", P{Cause::kTheta3Law, 0}, Other::kListed, 1, 0.005, 0.2, 0.01, 0.02,
       0.01,
       "below 0.01 once named theta3_bias (false alarm); above 0.02 about 9% of draws are "
       "unexplained (outlier rule) or name a second cause"},
      {"theta3_fraction-", "", P{Cause::kTheta3Law, 0}, Other::kListed, -1, 0.005, 0.2, kInf, kInf,
       kInf,
       "law not met: up to about 0.035 named joint_range (theta3_max 45-57 fits these data as "
       "well: false alarm), above that unexplained in 25-100% of draws (outlier rule)"},
      {"none", "", std::nullopt, Other::kNone, 1, 0, 0, 0, kInf, 0, ""},
      {"ripple_amplitude", "count", std::nullopt, Other::kRipple, 1, 0.3, 5, 0.8, kInf, 0.8,
       "below 0.8 count named theta3_max (false alarm)"},
      {"theta3_hysteresis", "deg", std::nullopt, Other::kHysteresis, 1, 0.2, 3, 0.65, kInf, 0, ""},
  };
  return kinds;
}

// One draw: a kind (index into Kinds()), a sign (+1 or -1) and a size.
struct Effect {
  int kind = 0;
  int sign = 1;
  double size = 0.0;
  const KindSpec& spec() const { return Kinds()[kind]; }
};

// The model's own value of the kind's parameter.
double Nominal(const KindSpec& k) { return NeutralValue(*k.parameter, Finger()); }

// The true value of the hidden parameter.
double Truth(const Effect& e) { return Nominal(e.spec()) + e.sign * e.size; }

HiddenEffects Hide(const Effect& e) {
  HiddenEffects hidden;
  switch (e.spec().other) {
    case Other::kListed:
      SetEffect(hidden.finger, *e.spec().parameter, Truth(e));
      break;
    case Other::kNone:
      break;
    case Other::kRipple:
      hidden.ripple_amplitude = e.sign * e.size;
      break;
    case Other::kHysteresis:
      hidden.theta3_hysteresis = e.sign * e.size;
      break;
  }
  return hidden;
}

// How a diagnosis compares with the hidden effect.
struct Verdict {
  // Named correctly. For a listed cause: its parameter is named, no other parameter is named
  // with it, and the fit lies within 15% of the true value, where the 15% applies to the
  // deviation from the model's own value: |fit - true| <= 0.15 * |true - nominal|. For
  // backlash, motor_offset, sensor_bias and compliance the model's value is 0 (15% of the true
  // value); for joint_range (theta_j_max) and theta3_law (theta3_fraction) it is the model's
  // (e.g. theta1_max = 70, theta3_fraction = 0.5), so that a fit that merely stays near the
  // model does not pass. For `none`: cause == {"none"}. For ripple: cause == {"unexplained"}
  // with a `where`; for hysteresis, a `where` on theta3.
  bool hit = false;
  // A cause of another kind is named: any listed parameter other than the hidden one (for none,
  // ripple and hysteresis: any listed parameter at all). `none` and `unexplained` are no false
  // alarms (for hidden `none`, `unexplained` is a miss).
  bool false_alarm = false;
  // |fit - true| / |true - nominal| when the hidden parameter is named, else NaN.
  double error = std::nan("");
};

Verdict Judge(const Effect& e, const Diagnosis& d) {
  Verdict v;
  const KindSpec& k = e.spec();
  const bool named = !d.cause.empty() && d.cause[0] != "none" && d.cause[0] != "unexplained";
  if (named) {
    for (const auto& [p, value] : d.parameters) {
      if (!k.parameter || !(p == *k.parameter)) v.false_alarm = true;
    }
  }
  switch (k.other) {
    case Other::kListed: {
      const std::optional<double> fit = named ? Fitted(d, *k.parameter) : std::nullopt;
      if (fit) v.error = std::abs(*fit - Truth(e)) / std::abs(Truth(e) - Nominal(k));
      v.hit = fit && !v.false_alarm && v.error <= 0.15;
      break;
    }
    case Other::kNone:
      v.hit = d.cause == std::vector<std::string>{"none"};
      break;
    case Other::kRipple:
      v.hit = d.cause == std::vector<std::string>{"unexplained"} && d.where.has_value();
      break;
    case Other::kHysteresis:
      v.hit = d.cause == std::vector<std::string>{"unexplained"} && d.where.has_value() &&
              d.where->channel == 2;
      break;
  }
  return v;
}

// Where the law puts a draw: in the 95% law's range, below it (no false alarm), or only
// reported (above the ceiling, below `quiet`, kinds that do not meet the law).
enum class Zone { kBelow, kLaw, kReported };

Zone ZoneOf(const Effect& e) {
  const KindSpec& k = e.spec();
  if (k.other == Other::kNone) return Zone::kLaw;
  if (e.size >= k.threshold) return e.size <= k.ceiling ? Zone::kLaw : Zone::kReported;
  return e.size >= k.quiet ? Zone::kBelow : Zone::kReported;
}

struct Outcome {
  Effect effect;
  std::uint64_t seed = 0;
  Verdict verdict;
  std::string diagnosis;
};

std::string Number(double x) {
  std::ostringstream s;
  s << std::setprecision(3) << x;
  return s.str();
}

// Per kind: draws, those in the law's range, hits there, the worst parameter error there, false
// alarms, the smallest size above which this run's draws hit in >= 95% of cases, and every draw
// that was not named correctly.
void PrintStatistics(const std::vector<Outcome>& outcomes, std::ostream& out) {
  out << "kind               range (law)        draws    law   hits    rate  worst_err  "
         "false_alarms  empirical_threshold\n";
  for (size_t i = 0; i < Kinds().size(); ++i) {
    const KindSpec& k = Kinds()[i];
    std::vector<const Outcome*> mine;
    for (const Outcome& o : outcomes) {
      if (o.effect.kind == static_cast<int>(i)) mine.push_back(&o);
    }
    int in_law = 0, hits = 0, alarms = 0;
    double worst = 0.0;
    for (const Outcome* o : mine) {
      alarms += o->verdict.false_alarm;
      if (ZoneOf(o->effect) != Zone::kLaw) continue;
      ++in_law;
      hits += o->verdict.hit;
      if (o->verdict.hit && std::isfinite(o->verdict.error)) {
        worst = std::max(worst, o->verdict.error);
      }
    }
    std::sort(mine.begin(), mine.end(),
              [](const Outcome* a, const Outcome* b) { return a->effect.size < b->effect.size; });
    std::string empirical = "-";
    int tail = 0, tail_hits = 0;
    for (int j = static_cast<int>(mine.size()) - 1; j >= 0; --j) {
      ++tail;
      tail_hits += mine[j]->verdict.hit;
      if (tail_hits >= 0.95 * tail) empirical = Number(mine[j]->effect.size);
    }
    const std::string range = std::isinf(k.threshold) ? "not met"
                              : std::isinf(k.ceiling)
                                  ? ">= " + Number(k.threshold)
                                  : "[" + Number(k.threshold) + ", " + Number(k.ceiling) + "]";
    char line[240];
    std::snprintf(line, sizeof(line), "%-18s %-18s %5zu %6d %6d %6.1f%% %9.3f %13d  %s %s\n",
                  k.name, range.c_str(), mine.size(), in_law, hits,
                  in_law ? 100.0 * hits / in_law : 100.0, worst, alarms, empirical.c_str(), k.unit);
    out << line;
    if (*k.note) out << "    note: " << k.note << "\n";
    for (const Outcome* o : mine) {
      if (o->verdict.hit) continue;
      static const char* const kZone[] = {"below   ", "MISS    ", "reported"};
      out << "    " << kZone[static_cast<int>(ZoneOf(o->effect))] << " size "
          << Number(o->effect.size) << " seed " << o->seed << ": " << o->diagnosis << "\n";
    }
  }
}

// One CSV row: PREFIX,kind,signed size,seed,hit,false_alarm,error,diagnosis.
void PrintRow(const char* prefix, const Outcome& o, std::ostream& out) {
  out << prefix << "," << o.effect.spec().name << "," << o.effect.sign * o.effect.size << ","
      << o.seed << "," << o.verdict.hit << "," << o.verdict.false_alarm << "," << o.verdict.error
      << "," << o.diagnosis << std::endl;
}

// A number from the environment, or `fallback`.
int EnvInt(const char* name, int fallback) {
  const char* text = std::getenv(name);
  return text && *text ? std::atoi(text) : fallback;
}

// Log-scale size steps: size = low * (high / low)^(step / kSizeSteps).
constexpr int kSizeSteps = 1000;

// The property. Per draw (a failure is shrunk: towards the first kind, the smallest size and
// seed 1): Diagnose does not throw, and no cause of another kind is named (at any size, for
// kinds whose law holds). Over all draws: in the law's range (threshold..ceiling) at least 95%
// are named correctly (Verdict::hit).
TEST(DiagnosisProperty, NamesTheHiddenEffect) {
  const int draws = EnvInt("HYBRID_DIAGNOSE_DRAWS", 24);
  ASSERT_GE(draws, 1);
  const bool log = EnvInt("HYBRID_DIAGNOSE_LOG", 0) != 0;
  std::vector<Outcome> outcomes;
  const auto property = [&] {
    // Size-independent draws (rapidcheck's size would otherwise favour the first kinds and small
    // effects in a short run).
    const auto draw = [](auto gen) { return *rc::gen::resize(100, gen); };
    const int kind = draw(rc::gen::inRange<int>(0, static_cast<int>(Kinds().size())));
    const int sign = draw(rc::gen::element(1, -1));
    const int step = draw(rc::gen::inRange<int>(0, kSizeSteps + 1));
    const auto seed = draw(rc::gen::inRange<std::uint64_t>(1, 1000000));
    const KindSpec& k = Kinds()[kind];
    Effect e;
    e.kind = kind;
    e.sign = k.sign != 0 ? k.sign : sign;
    e.size = k.other == Other::kNone
                 ? 0.0
                 : k.low * std::pow(k.high / k.low, static_cast<double>(step) / kSizeSteps);
    const Diagnosis d = DiagnoseSynthetic(Hide(e), seed);
    const Outcome o{e, seed, Judge(e, d), Describe(d)};
    outcomes.push_back(o);
    if (log) PrintRow("draw", o, std::cout);
    RC_LOG() << k.name << " size " << e.size << " " << k.unit << " seed " << seed << ": "
             << o.diagnosis << "\n";
    RC_ASSERT(!(o.verdict.false_alarm && ZoneOf(e) == Zone::kBelow));
  };
  // RC_PARAMS gives the seed (and reproduce, noshrink); the number of draws is ours.
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  params.maxSuccess = draws;
  rc::detail::TestMetadata metadata;
  metadata.id = "DiagnosisProperty/NamesTheHiddenEffect";
  metadata.description = "NamesTheHiddenEffect";
  const auto start = std::chrono::steady_clock::now();
  const rc::detail::TestResult result = rc::detail::checkTestable(property, metadata, params);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  int in_law = 0, hits = 0;
  for (const Outcome& o : outcomes) {
    if (ZoneOf(o.effect) != Zone::kLaw) continue;
    ++in_law;
    hits += o.verdict.hit;
  }
  std::cout << outcomes.size() << " draws (rapidcheck seed " << params.seed << ") in "
            << Number(seconds) << " s; in the law's range " << hits << " of " << in_law
            << " named correctly\n";
  PrintStatistics(outcomes, std::cout);
  std::ostringstream message;
  rc::detail::printResultMessage(result, message);
  EXPECT_TRUE(result.template is<rc::detail::SuccessResult>()) << message.str();
  EXPECT_GE(hits, 0.95 * in_law);
}

// ---------------------------------------------------------------------------------------------
// The measurement behind the thresholds. HYBRID_DIAGNOSE_SWEEP=SEEDS runs, for every kind (or
// those named in HYBRID_DIAGNOSE_SWEEP_KINDS, comma-separated), each of its signs,
// HYBRID_DIAGNOSE_SWEEP_SIZES sizes evenly spaced on a log scale over its range (or the sizes in
// HYBRID_DIAGNOSE_SWEEP_AT, comma-separated) and noise seeds 1..SEEDS;
// HYBRID_DIAGNOSE_SWEEP_SHARD=i/n runs every n-th case from the i-th (0-based). One CSV row per
// case on stdout: sweep,kind,signed size,seed,hit,false_alarm,error,diagnosis.

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, ',');) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

std::string Env(const char* name) {
  const char* text = std::getenv(name);
  return text ? text : "";
}

TEST(DiagnosisDetectability, Sweep) {
  const int seeds = EnvInt("HYBRID_DIAGNOSE_SWEEP", 0);
  if (seeds <= 0) GTEST_SKIP() << "set HYBRID_DIAGNOSE_SWEEP=SEEDS to measure the thresholds";
  const int sizes = EnvInt("HYBRID_DIAGNOSE_SWEEP_SIZES", 8);
  const std::vector<std::string> kinds = Split(Env("HYBRID_DIAGNOSE_SWEEP_KINDS"));
  std::vector<double> at;
  for (const std::string& s : Split(Env("HYBRID_DIAGNOSE_SWEEP_AT"))) at.push_back(std::stod(s));
  int shard = 0, shards = 1;
  if (!Env("HYBRID_DIAGNOSE_SWEEP_SHARD").empty()) {
    ASSERT_EQ(std::sscanf(Env("HYBRID_DIAGNOSE_SWEEP_SHARD").c_str(), "%d/%d", &shard, &shards), 2);
  }
  std::vector<std::pair<Effect, std::uint64_t>> cases;
  for (size_t i = 0; i < Kinds().size(); ++i) {
    const KindSpec& k = Kinds()[i];
    if (!kinds.empty() && std::find(kinds.begin(), kinds.end(), k.name) == kinds.end()) continue;
    std::vector<double> grid = at;
    if (grid.empty()) {
      for (int j = 0; j < sizes; ++j) {
        grid.push_back(k.low * std::pow(k.high / k.low, sizes > 1 ? j / (sizes - 1.0) : 0.0));
      }
    }
    if (k.other == Other::kNone) grid = {0.0};
    for (int sign : {1, -1}) {
      if (k.sign != 0 && sign != k.sign) continue;
      for (double size : grid) {
        for (int seed = 1; seed <= seeds; ++seed) {
          cases.push_back({Effect{static_cast<int>(i), sign, size}, seed});
        }
      }
    }
  }
  std::vector<Outcome> outcomes;
  for (size_t i = shard; i < cases.size(); i += shards) {
    const auto& [e, seed] = cases[i];
    Outcome o{e, seed, {}, {}};
    try {
      const Diagnosis d = DiagnoseSynthetic(Hide(e), seed);
      o.verdict = Judge(e, d);
      o.diagnosis = Describe(d);
    } catch (const std::exception& error) {
      o.diagnosis = std::string("EXCEPTION ") + error.what();
      ADD_FAILURE() << e.spec().name << " " << e.sign * e.size << " seed " << seed << ": "
                    << error.what();
    }
    PrintRow("sweep", o, std::cout);
    outcomes.push_back(o);
  }
  PrintStatistics(outcomes, std::cout);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::cout << "peak resident memory: " << usage.ru_maxrss / 1024 << " MB\n";
}

// ---------------------------------------------------------------------------------------------
// Data from the independent rig (tests/test_utilities/robotiq_rig.h): the report's protocol,
// requests that close past the stop and reopen, the controller as the manual describes it. The
// diagnosis sees only the CSV.

// One data set like `hybrid synthesize`'s default design: 4 free runs, 3 against link 1 (gob 80,
// 80, 100), 3 against link 2 (170, 170, 190), each the report's protocol up to 255 and back
// (stepped as `stepping`, with a reversal on the way up when `reverse`), noise `noise_deg` on
// every angle and 1% missing cells, drawn from `seed`. The CSV gives the object as the motor
// position of first contact (the drive's contact plus the motor offset).
std::string RigDataCsv(const testing::RigFinger& finger, const testing::RigEffects& effects,
                       std::uint64_t seed, testing::RigStepping stepping, bool reverse,
                       double noise_deg = 0.7, double outlier_fraction = 0.0) {
  struct RunSpec {
    int link;
    double gob;
  };
  const std::vector<RunSpec> runs = {{0, 0},  {0, 0},   {0, 0},   {0, 0},   {1, 80},
                                     {1, 80}, {1, 100}, {2, 170}, {2, 170}, {2, 190}};
  std::string csv = testing::RigCsvHeader(true);
  for (size_t r = 0; r < runs.size(); ++r) {
    testing::RigObject object, reported;
    if (runs[r].link == 1)
      object.gob1 = runs[r].gob, reported.gob1 = runs[r].gob + effects.motor_offset;
    if (runs[r].link == 2)
      object.gob2 = runs[r].gob, reported.gob2 = runs[r].gob + effects.motor_offset;
    const std::optional<double> reverse_at =
        reverse ? std::optional<double>(60.0 + 15.0 * static_cast<double>(r)) : std::nullopt;
    const std::vector<double> requests =
        testing::RigProtocol(255, stepping, seed * 31 + r, reverse_at, 25.0);
    testing::RigMeasurement m;
    m.noise_deg = noise_deg;
    m.missing_fraction = 0.01;
    m.seed = seed * 1009 + r;
    m.outlier_fraction = outlier_fraction / 1.3;  // 30% of them in adjacent pairs
    m.outlier_pair_fraction = 0.3;
    const auto samples = testing::RigRun(requests, finger, object, effects, m);
    csv += testing::RigCsvRows("run" + std::to_string(r), samples, reported, runs[r].link, true);
  }
  return csv;
}

Diagnosis DiagnoseCsv(const std::string& csv) {
  std::istringstream in(csv);
  MeasuredData read = ReadMeasuredData(in, "rig.csv");
  const FingerPredictor predictor(Finger(), FingerPredictor::FastOptions());
  return Diagnose(predictor, std::move(read), Options());
}

// Clean rig data whose requests close past the stop (the palm at 240, link 3 at its limit with
// an object) and reopen: nothing to explain, whatever the stepping.
TEST(DiagnoseRigTest, CleanDataPastTheStopIsNone) {
  for (const auto stepping :
       {testing::RigStepping::kOne, testing::RigStepping::kTwo, testing::RigStepping::kIrregular}) {
    const Diagnosis d =
        DiagnoseCsv(RigDataCsv({}, {}, 5, stepping, stepping != testing::RigStepping::kOne));
    EXPECT_EQ(d.cause, std::vector<std::string>{"none"})
        << "stepping " << static_cast<int>(stepping) << ": " << Describe(d);
  }
}

// Clean rig data with irregular steps (so no two runs repeat: the noise floor comes from second
// differences) and 2% outliers of 10 to 25 degrees on theta3, 30% of them in adjacent pairs,
// which the report's 5-degree rule does not catch: the spike rule keeps them out of the noise
// floor and of the test for systematic residuals alike, so nothing is named. 8 seeds in ctest;
// HYBRID_DIAGNOSE_OUTLIER_SEEDS=N runs N.
TEST(DiagnoseRigTest, OutliersInAdjacentPairsAreNone) {
  const int seeds = EnvInt("HYBRID_DIAGNOSE_OUTLIER_SEEDS", 8);
  int none = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    const Diagnosis d = DiagnoseCsv(
        RigDataCsv({}, {}, seed, testing::RigStepping::kIrregular, seed % 2 == 0, 0.7, 0.02));
    EXPECT_EQ(d.noise.method, "second_differences");
    const bool ok = d.cause == std::vector<std::string>{"none"};
    none += ok;
    EXPECT_TRUE(ok) << "seed " << seed << ": " << Describe(d);
  }
  std::cout << none << " of " << seeds << " seeds: none\n";
}

// Two causes on rig data, each fitted with the other (the pair fitted jointly): a play of 18.175
// counts and a theta3 sensor bias of 3.3 degrees, both within 2%.
TEST(DiagnoseRigTest, NamesLargeBacklashWithASensorBias) {
  testing::RigEffects effects;
  effects.backlash = 18.175;
  effects.bias[2] = 3.3;
  const int seed = EnvInt("HYBRID_DIAGNOSE_PAIR_SEED", 3);
  const auto stepping =
      static_cast<testing::RigStepping>(EnvInt("HYBRID_DIAGNOSE_PAIR_STEPPING", 0));
  const Diagnosis d = DiagnoseCsv(RigDataCsv({}, effects, seed, stepping, true, 0.7,
                                             EnvInt("HYBRID_DIAGNOSE_PAIR_OUTLIERS", 2) / 100.0));
  std::cout << Describe(d) << "\n";
  ASSERT_EQ(d.cause, (std::vector<std::string>{"backlash", "sensor_bias"})) << Describe(d);
  ASSERT_TRUE(Fitted(d, kBacklash)) << Describe(d);
  ASSERT_TRUE(Fitted(d, kTheta3Bias)) << Describe(d);
  EXPECT_NEAR(*Fitted(d, kBacklash), 18.175, 0.02 * 18.175) << Describe(d);
  EXPECT_NEAR(*Fitted(d, kTheta3Bias), 3.3, 0.02 * 3.3) << Describe(d);
}

// A motor offset of 4 counts and theta2_max 5 degrees above the model's: both named.
TEST(DiagnoseRigTest, NamesMotorOffsetWithJointRange) {
  testing::RigFinger finger;
  finger.theta2_max += 5.0;
  testing::RigEffects effects;
  effects.motor_offset = 4.0;
  const Diagnosis d = DiagnoseCsv(RigDataCsv(finger, effects, 4, testing::RigStepping::kOne, true));
  EXPECT_EQ(d.cause.size(), 2u) << Describe(d);
  EXPECT_NE(std::find(d.cause.begin(), d.cause.end(), "motor_offset"), d.cause.end())
      << Describe(d);
  EXPECT_NE(std::find(d.cause.begin(), d.cause.end(), "joint_range"), d.cause.end()) << Describe(d);
  const auto offset = Fitted(d, EffectParameter{Cause::kMotorOffset, 0});
  const auto range = Fitted(d, EffectParameter{Cause::kJointRange, 1});
  ASSERT_TRUE(offset && range) << Describe(d);
  EXPECT_NEAR(*offset, 4.0, 0.5) << Describe(d);
  EXPECT_NEAR(*range, 95.0, 1.0) << Describe(d);
}

// One kind of hidden effect in the rig's terms, with the range of sizes the law covers: from
// `threshold` (measured on rig data, docs/diagnosis_detectability.md) to `high`; `sign` fixes the
// direction (0 draws both).
struct RigKind {
  const char* name;
  std::optional<EffectParameter> parameter;  // nullopt: `none`
  int sign;
  double threshold, high;
};

const std::vector<RigKind>& RigKinds() {
  using P = EffectParameter;
  static const std::vector<RigKind> kinds = {
      {"backlash", kBacklash, 1, 0.6, 15},
      {"motor_offset", P{Cause::kMotorOffset, 0}, 0, 0.3, 15},
      {"theta1_max", P{Cause::kJointRange, 0}, 0, 0.2, 10},
      {"theta2_max", P{Cause::kJointRange, 1}, 0, 0.2, 10},
      {"theta3_max", P{Cause::kJointRange, 2}, 0, 0.5, 10},
      {"theta1_bias", P{Cause::kSensorBias, 0}, 0, 0.2, 5},
      {"theta2_bias", P{Cause::kSensorBias, 1}, 0, 0.2, 5},
      {"theta3_bias", kTheta3Bias, 0, 0.2, 5},
      {"compliance_link1", P{Cause::kCompliance, 0}, 1, 0.008, 0.1},
      {"compliance_link2", P{Cause::kCompliance, 1}, 1, 0.016, 0.1},
      {"theta3_fraction", P{Cause::kTheta3Law, 0}, 0, 0.005, 0.12},
      {"none", std::nullopt, 1, 0, 0},
  };
  return kinds;
}

// The rig with effect `kind` of signed size `value` (the deviation from the model's value).
void ApplyRigEffect(const std::string& kind, double value, testing::RigFinger& finger,
                    testing::RigEffects& effects) {
  if (kind == "backlash") effects.backlash = value;
  if (kind == "motor_offset") effects.motor_offset = value;
  if (kind == "theta1_max") finger.theta1_max += value;
  if (kind == "theta2_max") finger.theta2_max += value;
  if (kind == "theta3_max") finger.theta3_max += value;
  if (kind == "theta1_bias") effects.bias[0] = value;
  if (kind == "theta2_bias") effects.bias[1] = value;
  if (kind == "theta3_bias") effects.bias[2] = value;
  if (kind == "compliance_link1") effects.compliance[0] = value;
  if (kind == "compliance_link2") effects.compliance[1] = value;
  if (kind == "theta3_fraction") finger.theta3_fraction += value;
}

// Named correctly: `none` for clean data; otherwise the hidden parameter alone, within 15% of the
// deviation from the model's value.
bool RigHit(const RigKind& k, double value, const Diagnosis& d) {
  if (!k.parameter) return d.cause == std::vector<std::string>{"none"};
  if (d.parameters.size() != 1 || !(d.parameters[0].first == *k.parameter)) return false;
  const double nominal = NeutralValue(*k.parameter, Finger());
  return std::abs(d.parameters[0].second - (nominal + value)) <= 0.15 * std::abs(value);
}

// The property of the issue: over effect kind, size (from the kind's measured threshold up, log
// scale), sign, noise seed and run protocol (steps of 1, 2 or irregular; with or without a
// reversal on the way up; every run past the stop and back), data from the independent rig,
// diagnosed from the CSV alone: >= 95% of the draws named correctly with the parameter within
// 15%, and clean data never get a cause (checked per draw). HYBRID_DIAGNOSE_RIG_DRAWS draws
// (default 24, about 50 s); RC_PARAMS gives the seed.
TEST(DiagnosisRigProperty, NamesTheHiddenEffectOnRigData) {
  const int draws = EnvInt("HYBRID_DIAGNOSE_RIG_DRAWS", 24);
  ASSERT_GE(draws, 1);
  int hits = 0, total = 0;
  std::ostringstream misses;
  const auto property = [&] {
    const auto draw = [](auto gen) { return *rc::gen::resize(100, gen); };
    const auto& kinds = RigKinds();
    const RigKind& k = kinds[draw(rc::gen::inRange<size_t>(0, kinds.size()))];
    const int sign = k.sign != 0 ? k.sign : draw(rc::gen::element(1, -1));
    const int step = draw(rc::gen::inRange<int>(0, kSizeSteps + 1));
    const double size = k.parameter ? k.threshold * std::pow(k.high / k.threshold,
                                                             static_cast<double>(step) / kSizeSteps)
                                    : 0.0;
    const auto seed = draw(rc::gen::inRange<std::uint64_t>(1, 1000000));
    const auto stepping = static_cast<testing::RigStepping>(draw(rc::gen::inRange(0, 3)));
    const bool reverse = draw(rc::gen::arbitrary<bool>());
    testing::RigFinger finger;
    testing::RigEffects effects;
    ApplyRigEffect(k.name, sign * size, finger, effects);
    const Diagnosis d = DiagnoseCsv(RigDataCsv(finger, effects, seed, stepping, reverse));
    const bool hit = RigHit(k, sign * size, d);
    ++total;
    hits += hit;
    if (!hit) {
      misses << "    " << k.name << " " << sign * size << " seed " << seed << " stepping "
             << static_cast<int>(stepping) << " reverse " << reverse << ": " << Describe(d) << "\n";
    }
    RC_ASSERT(k.parameter || hit);  // clean data never get a cause
  };
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  params.maxSuccess = draws;
  params.disableShrinking = true;  // each draw is a whole diagnosis
  rc::detail::TestMetadata metadata;
  metadata.id = "DiagnosisRigProperty/NamesTheHiddenEffectOnRigData";
  metadata.description = "NamesTheHiddenEffectOnRigData";
  const rc::detail::TestResult result = rc::detail::checkTestable(property, metadata, params);
  std::cout << total << " draws (rapidcheck seed " << params.seed << "): " << hits
            << " named correctly\n"
            << misses.str();
  std::ostringstream message;
  rc::detail::printResultMessage(result, message);
  EXPECT_TRUE(result.template is<rc::detail::SuccessResult>()) << message.str();
  EXPECT_GE(hits, 0.95 * total);
}

// Exploration: HYBRID_DIAGNOSE_RIG="kind size" diagnoses rig data with one hidden effect.
TEST(DiagnoseRigTest, Explore) {
  const std::vector<std::string> args = Split(Env("HYBRID_DIAGNOSE_RIG"));
  if (args.size() < 2) GTEST_SKIP() << "set HYBRID_DIAGNOSE_RIG=kind,size[,seed,stepping,reverse]";
  testing::RigFinger finger;
  testing::RigEffects effects;
  const std::string kind = args[0];
  const double size = std::stod(args[1]);
  const std::uint64_t seed = args.size() > 2 ? std::stoull(args[2]) : 1;
  const auto stepping = static_cast<testing::RigStepping>(args.size() > 3 ? std::stoi(args[3]) : 0);
  const bool reverse = args.size() > 4 && args[4] == "1";
  ApplyRigEffect(kind, size, finger, effects);
  const std::string csv = RigDataCsv(finger, effects, seed, stepping, reverse);
  if (const std::string path = Env("HYBRID_DIAGNOSE_RIG_CSV"); !path.empty()) {
    std::ofstream(path) << csv;
  }
  const Diagnosis d = DiagnoseCsv(csv);
  std::cout << "rig " << kind << " " << size << " seed " << seed << ": " << Describe(d) << "\n";
}

}  // namespace
}  // namespace hybrid
