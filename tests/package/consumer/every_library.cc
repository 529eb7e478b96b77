// An outside program built against an installed hybrid (tests/package/) that uses the libraries
// tank.cc does not: hybrid::spaceex (with hybrid::reachability, on the installed
// share/hybrid/spec/spaceex/water_tank.xml), hybrid::diagnosis, hybrid::gripper and
// hybrid::plotting, each for a result known by hand. Prints one line per check and exits 1 if any
// check fails.

#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "hybrid/diagnosis/parallel_for.h"
#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/plotting/svg_plot.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "hybrid/spaceex/spaceex_import.h"
#include "hybrid/verification/property_prover.h"

namespace {

int failures = 0;

// Prints the check and counts it as failed when `ok` is false.
void Expect(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  if (!ok) ++failures;
}

// The SpaceEx water tank's levels stay in [1, 12], so its forbidden set (y >= 12.5 or y <= 0.5)
// is never reached.
void SpaceEx() {
  const std::string xml = std::string(HYBRID_DATA_DIR) + "/spec/spaceex/water_tank.xml";
  const hybrid::System tank = hybrid::spaceex::ReadModelFile(xml);
  const std::vector<hybrid::Property> properties = hybrid::DeclaredProperties(tank);
  const auto results = hybrid::PolyhedralReachability().Check(tank, properties);
  const std::string verdict =
      results.size() == 1 ? std::string(hybrid::VerdictName(results[0].verdict)) : "missing";
  Expect(verdict == "proved",
         "spaceex: the installed water tank's forbidden set: " + verdict + " (expected proved)");
}

// 0 + 1 + ... + 99 = 4950, summed on two threads.
void Diagnosis() {
  std::atomic<int> sum = 0;
  hybrid::ParallelFor(100, 2, [&sum](int i) { sum += i; });
  Expect(sum == 4950, "diagnosis: parallel sum " + std::to_string(sum.load()) + " (expected 4950)");
}

// Phase 1 of the free finger: theta1 = (theta1_max / 140) g, so 35 degrees at g = 70.
void Gripper() {
  const hybrid::gripper::FingerClosedForm finger;
  const double theta1 = finger.At(70.0).theta[0];
  Expect(std::abs(theta1 - 35.0) < 1e-9, "gripper: theta1 at g = 70 is " +
                                             hybrid::plotting::FormatShortest(theta1) +
                                             " (expected 35)");
}

void Plotting() {
  const std::string text = hybrid::plotting::FormatFixed(12.5, 2);
  Expect(text == "12.50", "plotting: 12.5 with two decimals is " + text + " (expected 12.50)");
}

}  // namespace

int main() {
  try {
    SpaceEx();
    Diagnosis();
    Gripper();
    Plotting();
  } catch (const std::exception& e) {
    std::printf("FAIL error: %s\n", e.what());
    return 1;
  }
  if (failures > 0) {
    std::printf("every library: %d checks failed\n", failures);
    return 1;
  }
  std::printf("every library: all checks passed\n");
  return 0;
}
