#pragma once

// Measured data for `hybrid diagnose`: reading the CSV of gripper runs, cleaning outliers with
// the gripper report's rule (section 5.1) and estimating the measurement noise floor.
//
// File format. A CSV file (comma-separated, no quoting) with a header row naming its columns in
// any order:
//   run            required; the run's label (any non-empty text, e.g. `1` or `free_a`)
//   g              required; the position request at which the sample was taken once the finger
//                  had settled (the report's protocol), counts, finite, in [0, 255]; never empty
//   theta1..theta3 required; the joint angles, degrees, finite; an empty cell is a missing sample
//   gob            optional; motor position of first contact with an object, counts, in [0, 255]
//   contact_link   optional; the link (1 or 2) that touches the object
//   position       optional; the motor position the gripper reports, counts, in [0, 255]; never
//                  more than half a count above the request g (the controller does not drive
//                  the motor past the request; the gripper reports whole counts); an empty cell
//                  is a missing report
// `gob` and `contact_link` come together (a header with one and not the other is an error); on
// each row both are empty (a free-space run) or both are given (a contact run), and they are
// constant within a run. Any other column is an error naming it, so that typos are caught.
// Each further line is a row of one sample. The rows of a run are contiguous and in measurement
// order (the motor's direction of travel follows from successive g); a run has at least
// kMinRunSamples rows. A line whose first non-blank character is `#` is a comment; a line of only
// blanks is ignored; both may appear anywhere, also before the header. Cells are trimmed of
// surrounding spaces and tabs. Lines may end with "\r\n"; a UTF-8 byte-order mark at the start
// of the file is skipped. Numbers are in the one decimal syntax of the command line
// (automaton/number_syntax.h: an optional sign, digits with an optional fraction and exponent; no
// hexadecimal, inf or nan), read with std::from_chars (locale-independent), and the whole
// trimmed cell must be a number.

#include <array>
#include <istream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybrid/diagnosis/data_error.h"
#include "hybrid/diagnosis/spike_filter.h"

namespace hybrid {

/// The fewest samples (rows) a run may have.
inline constexpr int kMinRunSamples = 10;

/// One run of measurements: parallel vectors with one entry per sample, in measurement order.
struct MeasuredRun {
  /// The run's label (the `run` column), non-empty.
  std::string label;
  /// Position requests, counts; finite, in [0, 255].
  std::vector<double> g;
  /// The motor positions the gripper reported (the `position` column), one per sample, NaN
  /// where missing; empty when the file has no such column.
  std::vector<double> position;
  /// Joint angles theta1..theta3, degrees; NaN marks a missing sample, other values are finite.
  std::array<std::vector<double>, 3> theta;
  /// Motor position of first contact with an object, counts, in [0, 255]; empty for a
  /// free-space run. Set exactly when contact_link is.
  std::optional<double> gob;
  /// The link (1 or 2) that touches the object; empty for a free-space run.
  std::optional<int> contact_link;
  /// The file line (1-based, counting the header, comments and blank lines) of each sample.
  std::vector<int> lines;
};

/// The runs of one data file, in file order.
struct MeasuredData {
  /// The file name used in messages.
  std::string source;
  std::vector<MeasuredRun> runs;

  /// The total number of samples (rows) over all runs.
  int samples() const;
};

/// Reads measured data in the format described at the top of this file from `in`; `source` names
/// it in messages and becomes MeasuredData::source. Throws DataError at the first problem:
/// no header (an empty file or only comments and blank lines: line 0); in the header (column 0
/// unless a single cell is concerned): a missing required column, a duplicate, unknown or empty
/// column name, `gob` without `contact_link` or the reverse; no data rows (at the header); a row
/// with too few or too many cells (column 0); in a cell: a `"` (quotes are not supported), an
/// empty `run` or `g`, a value that is not a number (the cell is quoted in the message) or not
/// finite (NaN, inf), g or gob outside [0, 255], contact_link other than 1 or 2, only one of gob
/// and contact_link given, gob or contact_link differing from the run's first row, a run label
/// reappearing after another run; a run with fewer than kMinRunSamples rows (at the run's first
/// row, column of `run`). Cells of a row are checked from left to right.
MeasuredData ReadMeasuredData(std::istream& in, const std::string& source);

/// ReadMeasuredData on the file at `path` (which is also the source in messages). Throws
/// DataError with line 0 and column 0 if the file cannot be opened or is a directory.
MeasuredData ReadMeasuredDataFile(const std::string& path);

/// What CleanOutliers changed.
struct OutlierReport {
  /// Number of samples changed, per joint (index 0 for theta1).
  std::array<int, 3> clamped = {0, 0, 0};
  /// One changed sample.
  struct Entry {
    /// The run's label.
    std::string run;
    /// The sample's file line (MeasuredRun::lines).
    int line = 0;
    /// The joint, 1..3 (as in theta1..theta3).
    int joint = 0;
    /// The angle as measured and as cleaned, degrees.
    double measured = 0.0;
    double cleaned = 0.0;
  };
  /// The changed samples, by run (file order), then joint, then sample.
  std::vector<Entry> entries;
};

/// Applies the gripper report's outlier rule (section 5.1) in place to every run and joint and
/// returns what it changed. The report: "We considered an outlier to be a change in sensed angle
/// that is more than 5 degrees from one value of g to the next (which certainly does not actually
/// occur on the physical robot). We limited the measurement to be within +-5 degrees of the
/// previous and next inlier points." With T = `threshold` (the report's 5 degrees), per run and
/// joint, walking the samples in order and skipping missing (NaN) ones, which stay missing:
///  - the first non-missing sample is an inlier (the report is silent; so a spike on the very
///    first sample is kept);
///  - a later sample x_k, with p the previous inlier and n the next non-missing sample as
///    measured (if any), is an outlier when |x_k - p| > T and, if n exists, |x_k - n| > T.
///    Requiring both keeps a genuine step: when the next sample agrees with x_k (within T), x_k
///    is the start of a new level, not an outlier. Hence only single-sample spikes are caught
///    (two equal spikes in a row are kept), and a change of more than T on the last sample is
///    always an outlier (there is no next sample to confirm it);
///  - an outlier is replaced by x_k clamped into [max(p, n) - T, min(p, n) + T] (the values
///    within T of both neighbours; [p - T, p + T] without n; n stands for the report's "next
///    inlier", which is not known yet when walking forward); when that interval is empty
///    (|p - n| > 2 T) by p + T towards x_k. The cleaned sample does not become the previous
///    inlier: p stays the same for the next sample, which is compared to the inlier before the
///    spike, not to the clamped value;
///  - otherwise x_k is an inlier and becomes p.
/// The report's premise is that motions faster than T per sample do not occur on the robot; a
/// sustained faster motion would be clamped sample after sample. Throws std::invalid_argument
/// unless threshold is finite and positive.
OutlierReport CleanOutliers(MeasuredData& data, double threshold = 5.0);

/// The measurement noise of each joint angle, estimated from the data.
struct NoiseFloor {
  /// Estimated noise variance, deg^2, per joint (index 0 for theta1); 0 when dof is 0.
  std::array<double, 3> variance = {0, 0, 0};
  /// Degrees of freedom behind each estimate (see EstimateNoiseFloor); 0 means no estimate.
  std::array<int, 3> dof = {0, 0, 0};
  /// "repeated_runs" or "second_differences".
  std::string method;
};

/// Estimates the noise variance of each joint angle, assuming independent noise of equal
/// variance on every sample: EstimateChannelNoise (include/hybrid/diagnosis/noise_floor.h) on the
/// three angles, so with the diagnosis's one outlier rule (SpikeMask, 4 noise standard
/// deviations from the median of a 5-sample window: spikes are left out) and its two estimators.
/// Runs are repeats when they have the same gob and contact_link (both empty, or equal), the same
/// number of samples and the same g at every sample (within 1e-9); each run joins the group of
/// the first earlier run it repeats.
/// With at least one group of two or more repeats, method "repeated_runs": the pooled
/// within-group variance over the groups of two or more runs, at the samples where every run of
/// the group has the angle (and none has a spike there): the sum over those samples of the
/// squared deviations from the group's mean at the sample, divided by dof = the sum over them of
/// (runs in the group - 1).
/// Otherwise, method "second_differences": from the second differences
/// d_k = x[k+1] - 2 x[k] + x[k-1] over consecutive samples of a run where all three are present
/// and none is a spike (Var d = 6 sigma^2 for independent noise on a curve whose second
/// differences are negligible). Each run's d are centred on their median, the absolute
/// deviations of all runs are pooled, and variance = (1.4826 * their median)^2 / 6 (a robust,
/// median-absolute-deviation estimate); dof is the number of second differences used.
/// `spike_sigmas` is the outlier rule's threshold (DiagnosisOptions::spike_sigmas).
NoiseFloor EstimateNoiseFloor(const MeasuredData& data, double spike_sigmas = kDefaultSpikeSigmas);

}  // namespace hybrid
