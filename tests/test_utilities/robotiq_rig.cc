#include "tests/test_utilities/robotiq_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>

namespace hybrid::testing {
namespace {

constexpr double kMotorMax = 255.0;
constexpr double kLink1Travel = 140.0;  // counts until link 1 reaches theta1_max (m1's divisor)
constexpr double kLink2Travel = 100.0;  // counts until link 2 reaches theta2_max (m2's divisor)

// Where links 1 and 2 stop while the finger closes, and why.
struct Stops {
  double g1 = 0.0;       // link 1 stops (its object, its limit, or link 2 blocked first)
  double g2 = 0.0;       // link 2 stops (its object or its limit); g2 >= g1
  bool object1 = false;  // link 1 is held by the object (it may yield)
  bool object2 = false;  // link 2 is held by the object (it may yield)
  bool palm = false;     // both at their limits: the free finger stops against the palm at g2
};

Stops StopsOf(const RigObject& object) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  const double gob1 = object.gob1.value_or(kNever);
  const double gob2 = object.gob2.value_or(kNever);
  Stops s;
  s.g1 = std::min(gob1, kLink1Travel);
  s.object1 = gob1 <= kLink1Travel;
  if (gob2 <= s.g1) {  // link 2 blocked while link 1 still moves: the base stops with it
    s.g1 = s.g2 = gob2;
    s.object1 = false;
    s.object2 = true;
    return s;
  }
  s.g2 = std::min(gob2, s.g1 + kLink2Travel);
  s.object2 = gob2 <= s.g1 + kLink2Travel;
  s.palm = !s.object1 && !s.object2;
  return s;
}

double Rate1(const RigFinger& f) { return f.theta1_max / kLink1Travel; }
double Rate2(const RigFinger& f) { return f.theta2_max / kLink2Travel; }

// Link 3 keeps its orientation while links 1 and 2 are driven (the report's -(theta1 + theta2)),
// down to its lower limit. Yield of a blocked link is not driven motion and does not count.
double Coupled3(double q, const RigFinger& f, const Stops& s) {
  const double driven1 = Rate1(f) * std::min(q, s.g1);
  const double driven2 = q <= s.g1 ? 0.0 : Rate2(f) * (std::min(q, s.g2) - s.g1);
  return std::max(-(driven1 + driven2), f.theta3_min);
}

// Section 4's phase-3 law from theta3_s at g_s (continued from theta3's value when link 2
// stopped, so that the joint does not jump), scaled so that theta3_max is reached the fraction
// f of the way from g_s to 255.
double Phase3(double q, double theta3_s, const RigFinger& f, const Stops& s) {
  if (q <= s.g2) return theta3_s;
  if (q >= kMotorMax) return f.theta3_max;
  const double scale = (1.0 - f.theta3_fraction) / f.theta3_fraction;
  const double law = theta3_s + scale * (f.theta3_max - theta3_s) * (q - s.g2) / (kMotorMax - q);
  return std::min(f.theta3_max, law);
}

}  // namespace

double RigStopPosition(const RigFinger& finger, const RigObject& object) {
  const Stops s = StopsOf(object);
  if (s.palm) return s.g2;
  return std::min(kMotorMax, s.g2 + finger.theta3_fraction * (kMotorMax - s.g2));
}

std::array<double, 3> RigAngles(double q, const RigFinger& finger, const RigObject& object,
                                const std::array<double, 2>& compliance) {
  const Stops s = StopsOf(object);
  q = std::clamp(q, 0.0, RigStopPosition(finger, object));
  std::array<double, 3> theta{};
  theta[0] = Rate1(finger) * std::min(q, s.g1);
  if (s.object1) theta[0] += compliance[0] * std::max(0.0, q - s.g1);
  theta[0] = std::min(theta[0], finger.theta1_max);
  if (q > s.g1) theta[1] = Rate2(finger) * (std::min(q, s.g2) - s.g1);
  if (s.object2) theta[1] += compliance[1] * std::max(0.0, q - s.g2);
  theta[1] = std::min(theta[1], finger.theta2_max);
  theta[2] = s.palm || q <= s.g2 ? Coupled3(q, finger, s)
                                 : Phase3(q, Coupled3(s.g2, finger, s), finger, s);
  return theta;
}

namespace {

// RigMeasurement's outliers on theta3, from their own stream.
void AddOutliers(const RigMeasurement& m, std::vector<RigSample>& samples) {
  if (m.outlier_fraction <= 0.0) return;
  std::mt19937_64 random(m.seed ^ 0x9e3779b97f4a7c15ULL);
  std::bernoulli_distribution start(m.outlier_fraction), pair(m.outlier_pair_fraction), up(0.5);
  std::uniform_real_distribution<double> size(m.outlier_min, m.outlier_max);
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!start(random)) continue;
    const size_t count = pair(random) && k + 1 < samples.size() ? 2 : 1;
    for (size_t i = k; i < k + count; ++i)
      samples[i].theta[2] += (up(random) ? 1 : -1) * size(random);
    k += count - 1;
  }
}

}  // namespace

std::vector<RigSample> RigRun(const std::vector<double>& requests, const RigFinger& finger,
                              const RigObject& object, const RigEffects& effects,
                              const RigMeasurement& measurement) {
  if (effects.backlash < 0) throw std::invalid_argument("RigRun: negative backlash");
  const double stop = RigStopPosition(finger, object);
  // The motor stops where the engaged transmission (q = p - offset) brings q to the stop.
  const double motor_stop = std::clamp(stop + effects.motor_offset, 0.0, kMotorMax);
  std::mt19937_64 random(measurement.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::bernoulli_distribution missing(measurement.missing_fraction);
  double q = 0.0;
  std::vector<RigSample> samples;
  for (double request : requests) {
    RigSample sample;
    sample.request = request;
    const double p = std::min(std::clamp(request, 0.0, kMotorMax), motor_stop);
    // The play: the finger moves only when the motor pushes it from one side or the other.
    const double low = p - effects.motor_offset;
    q = std::clamp(std::clamp(q, low, low + effects.backlash), 0.0, stop);
    sample.position = std::round(p);
    sample.drive = q;
    sample.theta = RigAngles(q, finger, object, effects.compliance);
    for (int j = 0; j < 3; ++j) {
      sample.theta[j] += effects.bias[j] + measurement.noise_deg * noise(random);
      if (missing(random)) sample.theta[j] = std::numeric_limits<double>::quiet_NaN();
    }
    samples.push_back(sample);
  }
  AddOutliers(measurement, samples);
  return samples;
}

std::vector<double> RigSweep(double from, double to, double step) {
  if (!(step > 0)) throw std::invalid_argument("RigSweep: step must be positive");
  std::vector<double> out;
  const double sign = to >= from ? 1.0 : -1.0;
  const int n = static_cast<int>(std::floor(std::abs(to - from) / step + 1e-9));
  for (int k = 0; k <= n; ++k) out.push_back(from + sign * step * k);
  if (std::abs(out.back() - to) > 1e-9) out.push_back(to);
  return out;
}

namespace {

// Appends the requests after `out.back()` up or down to `to` (included), stepped as `stepping`.
void StepTo(double to, RigStepping stepping, std::mt19937_64& random, std::vector<double>& out) {
  std::uniform_real_distribution<double> irregular(0.5, 4.0);
  const double from = out.back();
  const double sign = to >= from ? 1.0 : -1.0;
  double at = from;
  for (;;) {
    const double step = stepping == RigStepping::kOne   ? 1.0
                        : stepping == RigStepping::kTwo ? 2.0
                                                        : irregular(random);
    at += sign * step;
    if (sign * (at - to) >= 0.0) break;
    out.push_back(at);
  }
  out.push_back(to);
}

}  // namespace

std::vector<double> RigProtocol(double top, RigStepping stepping, std::uint64_t seed,
                                std::optional<double> reverse_at, double reverse_depth) {
  if (!(top > 0.0 && top <= kMotorMax)) throw std::invalid_argument("RigProtocol: top");
  std::mt19937_64 random(seed);
  std::vector<double> out = {0.0};
  if (reverse_at && *reverse_at > 0.0 && *reverse_at < top) {
    StepTo(*reverse_at, stepping, random, out);
    StepTo(std::max(0.0, *reverse_at - reverse_depth), stepping, random, out);
  }
  StepTo(top, stepping, random, out);
  StepTo(0.0, stepping, random, out);
  return out;
}

namespace {

std::string Cell(double value) {
  if (std::isnan(value)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

}  // namespace

std::string RigCsvHeader(bool contact_columns) {
  return contact_columns ? "run,g,position,theta1,theta2,theta3,gob,contact_link\n"
                         : "run,g,position,theta1,theta2,theta3\n";
}

std::string RigCsvRows(const std::string& run, const std::vector<RigSample>& samples,
                       const RigObject& object, int contact_link, bool contact_columns) {
  std::string contact = contact_columns ? ",," : "";
  if (contact_link == 1 || contact_link == 2) {
    const std::optional<double>& gob = contact_link == 1 ? object.gob1 : object.gob2;
    if (!gob) throw std::invalid_argument("RigCsvRows: no object on that link");
    contact = "," + Cell(*gob) + "," + std::to_string(contact_link);
  }
  std::string out;
  for (const RigSample& s : samples) {
    out += run + "," + Cell(s.request) + "," + Cell(s.position);
    for (double theta : s.theta) out += "," + Cell(theta);
    out += contact + "\n";
  }
  return out;
}

}  // namespace hybrid::testing
