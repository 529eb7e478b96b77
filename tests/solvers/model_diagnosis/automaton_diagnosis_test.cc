#include "hybrid/model_diagnosis/automaton_diagnosis.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"

namespace hybrid {
namespace {

// The bundled thermostat traces (data/thermostat_*.csv) were made by tools/thermostat_trace.py
// from the thermostat's piecewise-exponential closed form, apart from the code under test
// (tests/python/test_thermostat_data.py checks the files against it and against `simulate`).
AutomatonDiagnosis DiagnoseBundled(const std::string& spec, const std::string& data) {
  const std::string root = HYBRID_SOURCE_DIR;
  const System model = ParseModelFile(root + "/spec/" + spec + ".ha");
  return DiagnoseAutomaton(model, ReadTraceFile(root + "/data/" + data + ".csv", model));
}

std::string Causes(const AutomatonDiagnosis& d) {
  std::string text;
  for (const std::string& c : d.result.cause) text += c + " ";
  for (const auto& [name, value] : d.named) text += name + "=" + std::to_string(value) + " ";
  return text;
}

void ExpectNamed(const AutomatonDiagnosis& d, const std::string& name, double truth,
                 double tolerance) {
  ASSERT_EQ(d.result.cause, std::vector<std::string>{name}) << Causes(d);
  ASSERT_EQ(d.named.size(), 1u);
  EXPECT_NEAR(d.named[0].second, truth, tolerance) << Causes(d);
  EXPECT_LT(d.result.extended_mse[0], 1.2 * d.noise.variance[0]);
  EXPECT_GT(d.result.explained_fraction, 0.9);
}

TEST(ThermostatExamples, CleanTraceHasNoCause) {
  const AutomatonDiagnosis d = DiagnoseBundled("thermostat", "thermostat_clean");
  EXPECT_EQ(d.result.cause, std::vector<std::string>{"none"}) << Causes(d);
  // The generator's noise: sd 0.1 (the floor from the repeated runs).
  EXPECT_NEAR(std::sqrt(d.noise.variance[0]), 0.1, 0.01);
  EXPECT_EQ(d.noise_method[0], "repeated runs");
}

// A heater of 2.4 degC/min where the model has 3: within 5%.
TEST(ThermostatExamples, WeakHeater) {
  ExpectNamed(DiagnoseBundled("thermostat", "thermostat_weak_heater"), "p", 2.4, 0.05 * 2.4);
}

// The sensor reads 0.4 degC high: within 5%.
TEST(ThermostatExamples, SensorBias) {
  ExpectNamed(DiagnoseBundled("thermostat", "thermostat_sensor_bias"), "x_bias", 0.4, 0.05 * 0.4);
}

// The urgent model's switch-on threshold is 18.5 where the model's guard has the literal 18:
// the threshold found within 5% of the shift.
TEST(ThermostatExamples, ShiftedThresholdWrittenAsALiteral) {
  const AutomatonDiagnosis d = DiagnoseBundled("thermostat_urgent", "thermostat_threshold");
  ExpectNamed(d, "switch_on.threshold", 18.5, 0.05 * 0.5);
  // The extended model reads the new parameter in the guard, and parses back.
  const std::string text = PrintSystem(d.extended);
  EXPECT_NE(text.find("guard x <= switch_on_threshold;"), std::string::npos) << text;
  EXPECT_NO_THROW(ParseModel(text, "extended.ha"));
}

TEST(AutomatonDiagnosis, RefusesSeveralComponents) {
  const std::string root = HYBRID_SOURCE_DIR;
  const System hand = ParseModelFile(root + "/spec/hand.ha");
  const System thermostat = ParseModelFile(root + "/spec/thermostat.ha");
  const TraceData data = ReadTraceFile(root + "/data/thermostat_clean.csv", thermostat);
  EXPECT_THROW(DiagnoseAutomaton(hand, data), std::invalid_argument);
}

}  // namespace
}  // namespace hybrid
