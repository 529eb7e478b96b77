#include "hybrid/gripper/synthetic_data.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

namespace hybrid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The top of the requests of every run (counts): the report closed each run to 255.
constexpr double kTop = 255.0;
// Size of an outlier's jump on theta3 (deg).
constexpr double kOutlierMin = 10.0;
constexpr double kOutlierMax = 25.0;

[[noreturn]] void Fail(const std::string& message) {
  throw std::invalid_argument("synthetic data: " + message);
}

std::string Number(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

// Random numbers from the engine's raw output only (std::*_distribution differ between standard
// libraries).
class Draws {
 public:
  explicit Draws(std::uint64_t seed) : engine_(seed) {}
  // Uniform in the open interval (0, 1): the top 52 bits, centred in their cell (exact).
  double Uniform() { return (static_cast<double>(engine_() >> 12) + 0.5) * 0x1p-52; }
  // Standard normal from two uniforms (Box-Muller, cosine branch).
  double Normal() {
    const double u1 = Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::mt19937_64 engine_;
};

void CheckDesign(const HiddenEffects& hidden, const SyntheticDesign& design) {
  if (design.free_runs < 0 || design.free_runs > kMaxSyntheticFreeRuns) {
    Fail("free_runs must lie in [0, " + std::to_string(kMaxSyntheticFreeRuns) + "] (is " +
         std::to_string(design.free_runs) + ")");
  }
  if (design.free_runs == 0 && design.link1_gob.empty() && design.link2_gob.empty()) {
    Fail("the design has no runs");
  }
  if (design.samples_per_run < kMinRunSamples || design.samples_per_run % 2 != 0) {
    Fail("samples_per_run must be even and at least " + std::to_string(kMinRunSamples) + " (is " +
         std::to_string(design.samples_per_run) + ")");
  }
  const std::int64_t runs = static_cast<std::int64_t>(design.free_runs) +
                            static_cast<std::int64_t>(design.link1_gob.size()) +
                            static_cast<std::int64_t>(design.link2_gob.size());
  if (runs * design.samples_per_run > kMaxSyntheticSamples) {
    Fail(std::to_string(runs) + " runs of " + std::to_string(design.samples_per_run) +
         " samples are " + std::to_string(runs * design.samples_per_run) + " rows; at most " +
         std::to_string(kMaxSyntheticSamples) + " are made");
  }
  for (const auto* gobs : {&design.link1_gob, &design.link2_gob}) {
    for (const double gob : *gobs) {
      if (!(gob >= 0.0 && gob <= 255.0)) Fail("gob " + Number(gob) + " is outside [0, 255]");
    }
  }
  for (int j = 0; j < 3; ++j) {
    const double sd = design.noise_sd[j];
    if (!(std::isfinite(sd) && sd >= 0.0)) {
      Fail("noise_sd of theta" + std::to_string(j + 1) + " must be finite and >= 0 (is " +
           Number(sd) + ")");
    }
  }
  if (!(design.outlier_probability >= 0.0 && design.outlier_probability <= 1.0)) {
    Fail("outlier_probability " + Number(design.outlier_probability) + " is outside [0, 1]");
  }
  if (!(design.missing_probability >= 0.0 && design.missing_probability <= 1.0)) {
    Fail("missing_probability " + Number(design.missing_probability) + " is outside [0, 1]");
  }
  if (!std::isfinite(hidden.ripple_amplitude)) Fail("ripple_amplitude is not finite");
  if (!(std::isfinite(hidden.ripple_period) && hidden.ripple_period > 0.0)) {
    Fail("ripple_period must be finite and positive (is " + Number(hidden.ripple_period) + ")");
  }
  if (!std::isfinite(hidden.theta3_hysteresis)) Fail("theta3_hysteresis is not finite");
}

// FingerPredictor::Predict simulates along the drive's path length, summed step by step, and
// fails when a run that returns to g = 0 has summed a few 1e-12 more on the way back than on the
// way out (the finger's g ends below 0, outside the model's invariant). The positions it is
// given are therefore multiples of a power of two, whose sums are exact: the motor positions of
// the data multiples of 1/64 (which also have at most 6 decimals, so WriteMeasuredData writes
// them exactly), the rippled drive positions multiples of 2^-20.
constexpr double kGrid = 64.0;
constexpr double kFineGrid = 1048576.0;  // 2^20

// `v` rounded to a multiple of 1 / kGrid.
double OnGrid(double v) { return std::round(v * kGrid) / kGrid; }

// Motor path of `samples` (even) samples: 0 up to `top` on the first half, back on the second.
std::vector<double> MotorPath(int samples, double top) {
  const int half = samples / 2;
  std::vector<double> g(samples);
  for (int k = 0; k < half; ++k) {
    g[k] = OnGrid(top * static_cast<double>(k) / static_cast<double>(half - 1));
    g[samples - 1 - k] = g[k];
  }
  return g;
}

// A + sin(2 pi g / period) added to g, rounded to a multiple of 2^-20 and clipped to the motor
// range.
double Rippled(double g, const HiddenEffects& hidden) {
  if (hidden.ripple_amplitude == 0.0) return g;
  const double ripple =
      hidden.ripple_amplitude * std::sin(2.0 * std::numbers::pi * g / hidden.ripple_period);
  return std::clamp(std::round((g + ripple) * kFineGrid) / kFineGrid, 0.0, 255.0);
}

// The motor positions the gripper reports for `run` (whole counts, as the firmware reports
// them), from the motor positions `motor` the predictor found for the rippled requests `driven`
// (FingerPrediction::motor): the request where the motor reached it; where the controller held
// the motor at a stop, that stop taken back from drive to motor coordinates (m + ripple(m) = the
// stop, solved by one fixed-point step: the ripple's slope is small), never above the request.
std::vector<double> ReportedPositions(const MeasuredRun& run, const MeasuredRun& driven,
                                      const std::vector<double>& motor,
                                      const HiddenEffects& hidden) {
  std::vector<double> position(run.g.size());
  for (size_t k = 0; k < run.g.size(); ++k) {
    double m = run.g[k];
    if (motor[k] != driven.g[k]) m = std::min(m, motor[k] - (Rippled(motor[k], hidden) - motor[k]));
    position[k] = std::clamp(std::round(m), 0.0, 255.0);
  }
  return position;
}

// `v` with at most 6 decimals and no trailing zeros ("-0" written as "0").
std::string CsvNumber(double v) {
  char buffer[400];  // %.6f of the largest double: 309 digits, sign, point and 6 decimals
  std::snprintf(buffer, sizeof buffer, "%.6f", v);
  std::string s = buffer;
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

[[noreturn]] void WriteFail(const std::string& message) {
  throw std::invalid_argument("cannot write measured data: " + message);
}

}  // namespace

MeasuredData Synthesize(const FingerPredictor& predictor, const HiddenEffects& hidden,
                        const SyntheticDesign& design) {
  CheckDesign(hidden, design);
  MeasuredData data;
  data.source = "synthetic";
  for (int i = 0; i < design.free_runs; ++i) {
    MeasuredRun run;
    run.label = "free" + std::to_string(i + 1);
    run.g = MotorPath(design.samples_per_run, kTop);
    data.runs.push_back(std::move(run));
  }
  for (int link = 1; link <= 2; ++link) {
    const std::vector<double>& gobs = link == 1 ? design.link1_gob : design.link2_gob;
    for (size_t i = 0; i < gobs.size(); ++i) {
      MeasuredRun run;
      run.label = "link" + std::to_string(link) + "_" + std::to_string(i + 1);
      run.g = MotorPath(design.samples_per_run, kTop);
      run.gob = gobs[i];
      run.contact_link = link;
      data.runs.push_back(std::move(run));
    }
  }

  // The model's angles with the hidden effects, the finger behind its controller.
  const int n = design.samples_per_run;
  int line = 2;  // after the header
  for (MeasuredRun& run : data.runs) {
    MeasuredRun driven = run;
    for (double& g : driven.g) g = Rippled(g, hidden);
    FingerPrediction p = predictor.Predict(driven, hidden.finger);
    if (p.status != SimulationStatus::kCompleted) {
      Fail("run '" + run.label + "': the prediction did not complete: " + p.message);
    }
    run.position = ReportedPositions(run, driven, p.motor, hidden);
    run.theta = std::move(p.theta);
    if (hidden.theta3_hysteresis != 0.0) {
      for (int k = 0; k < n; ++k) {
        run.theta[2][k] += k < n / 2 ? hidden.theta3_hysteresis : -hidden.theta3_hysteresis;
      }
    }
    run.lines.resize(n);
    for (int k = 0; k < n; ++k) run.lines[k] = line++;
  }

  // Measurement errors, drawn in a fixed order: run, sample, joint.
  Draws draws(design.seed);
  for (MeasuredRun& run : data.runs) {
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < 3; ++j) {
        double& x = run.theta[j][k];
        x += design.noise_sd[j] * draws.Normal();
        if (j == 2) {
          const bool outlier = draws.Uniform() < design.outlier_probability;
          const double sign = draws.Uniform() < 0.5 ? -1.0 : 1.0;
          const double size = kOutlierMin + (kOutlierMax - kOutlierMin) * draws.Uniform();
          if (outlier) x += sign * size;
        }
        if (draws.Uniform() < design.missing_probability) x = kNaN;
      }
    }
  }
  return data;
}

void WriteMeasuredData(std::ostream& out, const MeasuredData& data,
                       const std::vector<std::string>& comment) {
  // Check everything first, so that nothing is written for data that cannot be.
  for (const MeasuredRun& run : data.runs) {
    const std::string& label = run.label;
    if (label.empty()) WriteFail("a run has an empty label");
    if (label.find_first_of(",\"\r\n") != std::string::npos || label.front() == '#' ||
        label.front() == ' ' || label.front() == '\t' || label.back() == ' ' ||
        label.back() == '\t') {
      WriteFail("run '" + label + "': the label cannot be written in a CSV cell");
    }
    for (const auto& theta : run.theta) {
      if (theta.size() != run.g.size()) WriteFail("run '" + label + "': vectors of unequal length");
      for (const double x : theta) {
        if (std::isinf(x)) WriteFail("run '" + label + "': an angle is infinite");
      }
    }
    for (const double g : run.g) {
      if (!std::isfinite(g)) WriteFail("run '" + label + "': a position request is not finite");
    }
    if (!run.position.empty() && run.position.size() != run.g.size()) {
      WriteFail("run '" + label + "': vectors of unequal length");
    }
    for (const double x : run.position) {
      if (std::isinf(x)) WriteFail("run '" + label + "': a reported motor position is infinite");
    }
    if (run.gob.has_value() != run.contact_link.has_value()) {
      WriteFail("run '" + label + "': only one of gob and contact_link is set");
    }
    if (run.gob && !std::isfinite(*run.gob)) WriteFail("run '" + label + "': gob is not finite");
  }

  for (const std::string& text : comment) {
    size_t begin = 0;
    while (true) {
      const size_t end = text.find('\n', begin);
      std::string part = text.substr(begin, end == std::string::npos ? end : end - begin);
      if (!part.empty() && part.back() == '\r') part.pop_back();
      out << "# " << part << '\n';
      if (end == std::string::npos) break;
      begin = end + 1;
    }
  }
  const bool positions = std::any_of(data.runs.begin(), data.runs.end(),
                                     [](const MeasuredRun& run) { return !run.position.empty(); });
  out << (positions ? "run,g,position,theta1,theta2,theta3,gob,contact_link\n"
                    : "run,g,theta1,theta2,theta3,gob,contact_link\n");
  for (const MeasuredRun& run : data.runs) {
    const std::string object =
        run.gob ? CsvNumber(*run.gob) + "," + std::to_string(*run.contact_link) : ",";
    for (size_t k = 0; k < run.g.size(); ++k) {
      std::string row = run.label + "," + CsvNumber(run.g[k]);
      if (positions) {
        row += ',';
        if (!run.position.empty() && !std::isnan(run.position[k]))
          row += CsvNumber(run.position[k]);
      }
      for (const auto& theta : run.theta) {
        row += ',';
        if (!std::isnan(theta[k])) row += CsvNumber(theta[k]);
      }
      row += ',' + object + '\n';
      out << row;
    }
  }
}

}  // namespace hybrid
