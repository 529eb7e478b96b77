#pragma once

// Synthetic measured data for `hybrid diagnose`: runs of one finger generated from the finger
// model with hidden effects (those `hybrid diagnose` can name, FingerEffects, and effects outside
// its list that it must call unexplained), measurement noise, outliers and missing samples like
// the gripper report's (about 0.7 deg on theta1 and theta2, 1.2 deg on theta3, outliers on
// theta3); and writing measured data in the CSV format that ReadMeasuredData reads.

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "hybrid/gripper/finger_effects.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"

namespace hybrid {

/// An effect hidden in synthetic data: the diagnosable FingerEffects plus effects outside the
/// list that `hybrid diagnose` must call unexplained.
struct HiddenEffects {
  /// Applied through FingerPredictor::Predict.
  FingerEffects finger;
  /// A (counts): a drive position error A*sin(2*pi*g/ripple_period) (gear eccentricity), added
  /// to the motor positions handed to the predictor (rounded to a multiple of 2^-20 and clipped
  /// to [0, 255]); the data keep the nominal g. Finite.
  double ripple_amplitude = 0.0;
  /// The ripple's period (counts); finite and positive.
  double ripple_period = 40.0;
  /// h (deg): +h added to the measured theta3 while the motor closes, -h while it opens (a
  /// direction-dependent sensor lag; not a constant bias). Finite.
  double theta3_hysteresis = 0.0;
};

/// Caps on the size of synthetic data, checked by Synthesize before anything is allocated. At
/// about 300 bytes per row at the peak of `hybrid synthesize` (the data, the CSV text and its
/// copy), kMaxSyntheticSamples rows take about 0.3 GB and a few seconds.
/// The most rows (samples over all runs) of a design.
inline constexpr std::int64_t kMaxSyntheticSamples = 1000000;
/// The most free-space runs of a design.
inline constexpr int kMaxSyntheticFreeRuns = 10000;

/// The runs of synthetic data and its measurement errors.
struct SyntheticDesign {
  /// Free-space runs, in [0, kMaxSyntheticFreeRuns]: the request g from 0 up to 255 and back to
  /// 0 (the report's protocol: past the palm stop, where the controller holds the motor at 240
  /// for the model as declared until the request comes back below it).
  int free_runs = 4;
  /// One run per entry (counts, in [0, 255]): an object touching link 1 at gob; the request from
  /// 0 up to 255 and back to 0. The controller holds the motor where the finger stops it (the
  /// model's phase 4: for the model as declared at (255 + g_s) / 2 with g_s where link 2
  /// stopped, e.g. 217.5 for gob 80) until the request comes back below it.
  std::vector<double> link1_gob = {80, 80, 100};
  /// The same for an object touching link 2.
  std::vector<double> link2_gob = {170, 170, 190};
  /// Samples per run: even, >= kMinRunSamples, and the rows of all runs (runs times samples)
  /// at most kMaxSyntheticSamples. The first half closes, the requests evenly spaced from 0 to
  /// 255 inclusive; the second half opens through the same requests in reverse (255 is
  /// requested twice, once per half), so that repeated runs have identical g. Requests are
  /// rounded to multiples of 1/64 count, so that WriteMeasuredData writes every g exactly and
  /// FingerPredictor's sums of path length are exact (see Synthesize).
  int samples_per_run = 512;
  /// Standard deviation of the Gaussian measurement noise (deg) on theta1..theta3; finite, >= 0.
  std::array<double, 3> noise_sd = {0.7, 0.7, 1.2};
  /// Per theta3 sample, in [0, 1]: a jump of random sign and size uniform in [10, 25] deg added.
  double outlier_probability = 0.02;
  /// Per angle sample (each joint on its own), in [0, 1]: the sample is missing (NaN).
  double missing_probability = 0.005;
  /// Seed of the std::mt19937_64 that draws noise, outliers and missing samples.
  std::uint64_t seed = 1;
};

/// Generates the runs of `design`, in the order free runs, link-1 runs, link-2 runs, labelled
/// "free1", "free2", .., "link1_1", .., "link2_1", ..; object runs have gob and contact_link set.
/// Each run is taken as the report took its data: g is the position request (samples_per_run
/// requests, 0 up to 255 and back), each sample taken once the finger settled.
/// The angles are those FingerPredictor::Predict gives for `hidden.finger` on the run with the
/// ripple added to its requests (rounded to a multiple of 2^-20): the finger behind its
/// controller, which holds the motor where the finger stops it until a more open request. The
/// `position` column is the motor position the gripper would report: the request, or where the
/// controller holds the motor (taken back from the rippled drive, one fixed-point step), in
/// whole counts, never above the request. Positions on these grids keep the predictor's sums of
/// path length exact: it fails on a run that returns to g = 0 after summing a few 1e-12 more on
/// the way back than on the way out (e.g. 256 steps of 230/255 rounded to 6 decimals, up and
/// back). Then the hysteresis (+h on the closing half, -h on the opening half); then, per sample
/// in order and per joint theta1..theta3, Gaussian noise of sd noise_sd[j], for theta3 an outlier
/// with outlier_probability, and a missing sample with missing_probability.
/// The random numbers come from a std::mt19937_64 seeded with `seed`, only through its raw
/// output (uniforms in (0, 1) from the top 52 bits; each normal variate by Box-Muller, cosine
/// branch, from two uniforms), so that the data are identical across standard libraries. Per
/// run, sample and joint they are drawn in this order: the noise (a normal), for theta3 whether
/// it is an outlier, its sign and its size (three uniforms), then whether it is missing. Every
/// sample and joint draws the same random numbers whatever the probabilities and noise levels, so
/// designs that differ only in those share their draws (e.g. the noise of a design with outliers
/// equals that of the same design without them). MeasuredData::source is "synthetic" and
/// MeasuredRun::lines are the lines WriteMeasuredData without a comment gives (2, 3, ...). Throws
/// std::invalid_argument ("synthetic data: ...") for a bad design, before allocating anything
/// (no runs, free_runs outside [0, kMaxSyntheticFreeRuns], samples_per_run < kMinRunSamples or
/// odd, more than kMaxSyntheticSamples rows, a gob outside [0, 255], noise negative or not
/// finite, a probability outside [0, 1]) or bad hidden effects (non-finite ripple or hysteresis,
/// ripple_period <= 0; FingerPredictor::Predict's own checks), or if a prediction does not complete
/// (naming the run and the predictor's message).
MeasuredData Synthesize(const FingerPredictor& predictor, const HiddenEffects& hidden,
                        const SyntheticDesign& design);

/// Writes `data` in the CSV format ReadMeasuredData reads: first each line of `comment` (an
/// element with line breaks gives several lines) prefixed with "# ", then the header
/// `run,g,theta1,theta2,theta3,gob,contact_link` (with `position` after g when some run has
/// reported positions; an empty cell for a run without them or a NaN), then one row per sample.
/// Numbers are written with at most 6 decimals, trailing zeros dropped (`%.6f`: they read back
/// within 5e-7); a missing angle (NaN) and the gob and contact_link of a free-space run are empty
/// cells. Throws std::invalid_argument ("cannot write measured data: ...") for what could not be
/// read back: a label that is empty, starts with '#' or a blank, ends with a blank or holds ',',
/// '"', '\r' or
/// '\n'; vectors of a run of unequal lengths; a value that is infinite (or NaN other than an
/// angle); only one of gob and contact_link set.
void WriteMeasuredData(std::ostream& out, const MeasuredData& data,
                       const std::vector<std::string>& comment);

}  // namespace hybrid
