// libFuzzer harness: the measured-data CSV reader of `hybrid diagnose` (ReadMeasuredData in
// include/hybrid/gripper/measured_data.h), then the outlier cleaning and noise estimate applied to
// what it reads. Every input either throws DataError (line and column not negative, a message about
// the data) or gives runs that keep the documented invariants: a non-empty label, at least
// kMinRunSamples samples, g finite in [0, 255], angles finite or NaN (missing), gob and
// contact_link set together with gob in [0, 255] and contact_link 1 or 2, increasing lines,
// positions (when the file has the column) one per sample, missing or in [0, 255] and at most half
// a count above the request.
// CleanOutliers keeps missing samples missing and present ones present and finite.

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>

#include "hybrid/gripper/measured_data.h"
#include "tests/fuzz/fuzz_utilities.h"

namespace {

using hybrid::fuzz::FuzzFail;

void CheckRun(const hybrid::MeasuredRun& run) {
  const size_t n = run.g.size();
  if (run.label.empty()) FuzzFail("a run without a label");
  if (n < static_cast<size_t>(hybrid::kMinRunSamples)) FuzzFail("a run with too few samples");
  if (run.lines.size() != n) FuzzFail("lines and samples differ in number");
  for (const auto& theta : run.theta) {
    if (theta.size() != n) FuzzFail("angles and samples differ in number");
    for (double x : theta) {
      if (std::isinf(x)) FuzzFail("an infinite angle");
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (!(run.g[i] >= 0.0 && run.g[i] <= 255.0)) FuzzFail("g outside [0, 255]");
    if (i > 0 && !(run.lines[i] > run.lines[i - 1])) FuzzFail("lines do not increase");
  }
  if (!run.position.empty() && run.position.size() != n) {
    FuzzFail("positions and samples differ in number");
  }
  for (size_t i = 0; i < run.position.size(); ++i) {
    const double p = run.position[i];
    if (!std::isnan(p) && !(p >= 0.0 && p <= 255.0 && p <= run.g[i] + 0.5)) {
      FuzzFail("a position outside [0, 255] or past the request");
    }
  }
  if (run.gob.has_value() != run.contact_link.has_value()) {
    FuzzFail("gob and contact_link not set together");
  }
  if (run.gob && !(*run.gob >= 0.0 && *run.gob <= 255.0)) FuzzFail("gob outside [0, 255]");
  if (run.contact_link && *run.contact_link != 1 && *run.contact_link != 2) {
    FuzzFail("contact_link other than 1 or 2");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hybrid::fuzz;  // NOLINT(google-build-using-namespace): the harness's helpers
  const std::string_view text = AsText(data, size);
  std::istringstream in{std::string(text)};
  hybrid::MeasuredData measured;
  try {
    measured = hybrid::ReadMeasuredData(in, "data.csv");
  } catch (const hybrid::DataError& e) {
    if (e.line() < 0 || e.column() < 0 || e.source() != "data.csv") {
      FuzzFail("bad DataError position: " + std::string(e.what()));
    }
    if (e.message().empty() || LeaksCppNames(e.message(), text)) {
      FuzzFail("bad message: " + std::string(e.what()));
    }
    return 0;
  }
  if (measured.runs.empty()) FuzzFail("data without runs");
  for (const hybrid::MeasuredRun& run : measured.runs) CheckRun(run);
  const hybrid::MeasuredData read = measured;
  hybrid::CleanOutliers(measured);
  for (size_t r = 0; r < read.runs.size(); ++r) {
    for (size_t j = 0; j < 3; ++j) {
      for (size_t i = 0; i < read.runs[r].g.size(); ++i) {
        const double before = read.runs[r].theta[j][i], after = measured.runs[r].theta[j][i];
        if (std::isnan(before) != std::isnan(after) || std::isinf(after)) {
          FuzzFail("CleanOutliers changed which samples are missing or made one infinite");
        }
      }
    }
  }
  const hybrid::NoiseFloor noise = hybrid::EstimateNoiseFloor(measured);
  for (size_t j = 0; j < 3; ++j) {
    if (noise.dof[j] < 0 || std::isnan(noise.variance[j]) || noise.variance[j] < 0.0) {
      FuzzFail("a noise estimate that is negative or NaN");
    }
  }
  return 0;
}
