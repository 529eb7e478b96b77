// An outside program built against an installed hybrid (tests/package/): parses a constant-rate
// tank, simulates it and checks its properties with both provers, comparing each result with its
// value worked out by hand. Prints one line per check and exits 1 if any check fails.
//
// The tank: a pump fills it at 1 cm/s from y = 1; a monitor signals "off" at y = 10 and "on" at
// y = 5, and each signal takes effect 2 s later (clock x), while the level falls at 2 cm/s with
// the pump off. So "off" is signalled at t = 9 (y = 10), the pump stops at t = 11 (y = 12), the
// level falls to 5 at t = 14.5, the pump starts at t = 16.5 (y = 1), and at t = 20 y = 4.5. The
// reachable levels are exactly [1, 12].

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"

namespace {

constexpr const char* kTank = R"(
automaton tank {
  var y [cm] in [0, 20];
  var x [s] in [0, 100];
  mode on { y' = 1; x' = 1; inv y <= 10; }
  mode stopping { y' = 1; x' = 1; inv x <= 2; }
  mode off { y' = -2; x' = 1; inv y >= 5; }
  mode starting { y' = -2; x' = 1; inv x <= 2; }
  transition signal_off: on -> stopping { guard y == 10; reset x := 0; lazy; }
  transition pump_stops: stopping -> off { guard x == 2; lazy; }
  transition signal_on: off -> starting { guard y == 5; reset x := 0; lazy; }
  transition pump_starts: starting -> on { guard x == 2; lazy; }
  init on { y = 1; x = 0; }
  property in_range: always y >= 1 and y <= 12;
  property below_11: always y <= 11;
  property reaches_12: reach y >= 12;
}
)";

int failures = 0;

// Prints the check and counts it as failed when `ok` is false.
void Expect(bool ok, const std::string& what) {
  std::printf("%s %s\n", ok ? "ok  " : "FAIL", what.c_str());
  if (!ok) ++failures;
}

bool Near(double a, double b) { return std::abs(a - b) < 1e-6; }

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

// The run to t = 20: four events at their analytic times, the peak level 12, y = 4.5 at the end.
void Simulate(const hybrid::System& tank) {
  hybrid::Simulator simulator(tank);
  hybrid::SimulationOptions options;
  options.until = 20.0;
  options.sample_step = 0.5;
  const hybrid::SimulationResult run = simulator.Run(options);
  Expect(run.status == hybrid::SimulationStatus::kCompleted,
         "simulation completed: " + std::string(hybrid::StatusName(run.status)));
  const std::vector<std::string>& names = simulator.variable_names();
  const auto y = std::find(names.begin(), names.end(), "y") - names.begin();
  Expect(y < static_cast<long>(names.size()), "the level is a variable of the model");
  if (y >= static_cast<long>(names.size()) || run.samples.empty()) return;

  const std::vector<std::string> transitions = {"signal_off", "pump_stops", "signal_on",
                                                "pump_starts"};
  const std::vector<double> times = {9.0, 11.0, 14.5, 16.5};
  Expect(run.events.size() == times.size(),
         "simulation: " + std::to_string(run.events.size()) + " events (expected 4)");
  for (std::size_t i = 0; i < run.events.size() && i < times.size(); ++i) {
    const hybrid::EventRecord& event = run.events[i];
    const std::string name = event.transitions.empty() ? "?" : event.transitions.front();
    Expect(Near(event.time, times[i]) && name.ends_with(transitions[i]),
           "event " + name + " at t = " + Number(event.time) + " (expected " + transitions[i] +
               " at t = " + Number(times[i]) + ")");
  }
  double peak = run.samples.front().x[y];
  for (const hybrid::StateSample& sample : run.samples) peak = std::max(peak, sample.x[y]);
  Expect(Near(peak, 12.0), "highest level " + Number(peak) + " (expected 12)");
  const double last = run.samples.back().x[y];
  Expect(Near(run.samples.back().time, 20.0) && Near(last, 4.5),
         "level " + Number(last) + " at t = " + Number(run.samples.back().time) +
             " (expected 4.5 at t = 20)");
}

// The verdict a checker gave `property` among `results`, "missing" if none.
std::string VerdictOf(const std::vector<hybrid::CheckResult>& results,
                      const std::string& property) {
  for (const hybrid::CheckResult& result : results) {
    if (result.property == property) return std::string(hybrid::VerdictName(result.verdict));
  }
  return "missing";
}

void ExpectVerdict(const std::vector<hybrid::CheckResult>& results, const std::string& checker,
                   const std::string& property, const std::string& expected) {
  const std::string verdict = VerdictOf(results, property);
  Expect(verdict == expected,
         checker + ": " + property + " " + verdict + " (expected " + expected + ")");
}

// Exact polyhedral reachability proves the range and refutes y <= 11; the SMT prover finds the
// level 12 and refutes y <= 11 too.
void Verify(const hybrid::System& tank) {
  const std::vector<hybrid::Property> properties = hybrid::DeclaredProperties(tank);
  const auto reach = hybrid::PolyhedralReachability().Check(tank, properties);
  ExpectVerdict(reach, "reachability", "in_range", "proved");
  ExpectVerdict(reach, "reachability", "below_11", "violated");
  const auto prove = hybrid::PropertyProver().Check(tank, properties);
  ExpectVerdict(prove, "prover", "below_11", "violated");
  ExpectVerdict(prove, "prover", "reaches_12", "reachable");
}

}  // namespace

int main() {
  try {
    const hybrid::System tank = hybrid::ParseModel(kTank, "tank.ha");
    Simulate(tank);
    Verify(tank);
  } catch (const std::exception& e) {
    std::printf("FAIL error: %s\n", e.what());
    return 1;
  }
  if (failures > 0) {
    std::printf("tank: %d checks failed\n", failures);
    return 1;
  }
  std::printf("tank: all checks passed\n");
  return 0;
}
