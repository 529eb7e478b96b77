#pragma once

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/gripper/finger_effects.h"
#include "hybrid/gripper/measured_data.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid {

/// What the finger model predicts for one measured run.
struct FingerPrediction {
  /// Predicted measured angles (deg), sensor biases included; one entry per sample of the run.
  std::array<std::vector<double>, 3> theta;
  /// The finger mode (index into the finger automaton's modes) at each sample.
  std::vector<int> mode;
  /// Direction of travel of the motor at each sample: +1 closing, -1 opening (a sample where g
  /// does not change keeps the previous direction; the first one counts as closing).
  std::vector<int> direction;
  /// The motor position at each sample: where the controller has driven the motor for the run's
  /// request (MotorPositions with the stops the simulation found).
  std::vector<double> motor;
  /// The finger's drive position at each sample (DrivePositions of `motor`).
  std::vector<double> drive;
  /// The model's own motor position g at each sample (equal to `drive`: the controller stops
  /// the motor where the finger stalls).
  std::vector<double> model_g;
  /// kCompleted, or why the run stopped early (later samples are NaN, mode -1).
  SimulationStatus status = SimulationStatus::kCompleted;
  std::string message;
};

/// Where the controller stopped the motor because the finger could move no further: at the
/// sample `index` (the first whose request went past the stop), at motor position `motor`.
struct ControllerStop {
  size_t index = 0;
  double motor = 0.0;
};

/// The motor positions the gripper's controller reaches for the position requests r_0, r_1, ...
/// (settled samples, the report's protocol; section 2): p_k = r_k, except that from a stop's
/// sample on the motor stays at the stop while the request is not more open than it
/// (r_k >= stop), and follows the request again from the first r_k < stop. `stops` in order of
/// index.
std::vector<double> MotorPositions(std::span<const double> requests,
                                   std::span<const ControllerStop> stops);

/// Runs the finger automaton driven by a measured run's position requests, under FingerEffects.
///
/// The run's `g` are position requests (the report's protocol: each sample taken once the finger
/// has settled). The controller moves the motor to each request, and stops it where the finger
/// stalls (phase 4), until a more open request (MotorPositions); the stops are found by
/// simulating: a pass along the requests, then again with each stall found (where the finger's
/// g lags the drive) made a controller stop, at most 16 passes. The motor path
/// p_0, p_1, ... (from the open finger at 0) is mapped to the finger's drive
/// positions q_k by DrivePositions (backlash, motor offset); the automaton, with the dynamic
/// effects applied (ApplyDynamicEffects) and the run's object at gob<link> = gob - d (the object
/// touches at the same motor position; clipped to [0, 256]), is simulated with input u = +-1
/// along q, so that time is the drive's path length and each sample is recorded at its position
/// on the path (the model is rate-independent: every flow is proportional to u). Sensor biases
/// are added to the angles. This equals simulating ExtendFingerModel's automaton along the
/// motor path `motor` (tests/gripper/finger_predictor_test.cc checks it to 1e-6 deg).
///
/// Simulators are built once per distinct (dynamic effects, object) and cached (at most 256;
/// the cache is emptied when full); Predict is safe to call from several threads.
class FingerPredictor {
 public:
  /// Integration settings (SimulationOptions). The defaults keep the angles within about 1e-7
  /// deg of the exact solution; Diagnose uses FastOptions().
  struct Options {
    double relative_tolerance = 1e-9;
    double absolute_tolerance = 1e-10;
    int dense_checks = 4;
    bool interpolate_samples = false;    ///< SimulationOptions::interpolate_samples
    bool fixed_point_iteration = false;  ///< SimulationOptions::fixed_point_iteration
  };
  /// Diagnose's settings: within 1e-3 deg of the default ones (FingerPredictorProperty checks it
  /// on random runs), far below the measurement noise.
  /// Tolerances 3e-7 / 3e-8; the phase-3 law (the only flow the solver integrates) is non-stiff,
  /// so its steps use fixed-point iteration and the samples are read off the solver's
  /// interpolant (SimulationOptions). No interior double-crossing checks: the finger's guards
  /// cross once per piece (every flow is monotone along a piece of constant u).
  static Options FastOptions() { return Options{3e-7, 3e-8, 0, true, true}; }
  /// `finger` must be spec/finger.ha's automaton (names theta1..3, g, u, gob1, gob2, c1, c2);
  /// throws std::invalid_argument ("the model has no 'NAME' ...") otherwise.
  explicit FingerPredictor(Automaton finger);
  FingerPredictor(Automaton finger, Options options);
  ~FingerPredictor();

  /// Throws std::invalid_argument for effects out of range (e.g. negative backlash).
  FingerPrediction Predict(const MeasuredRun& run, const FingerEffects& effects) const;

  /// Where the finger is when the motor is at 0 under `effects`: nullopt when that is the model's
  /// initial state (drive position 0), else the mode name and continuous values reached by
  /// closing the finger (no object) to the drive position (motor_offset < 0). What
  /// ExtendFingerModel needs as `initial_finger`.
  std::optional<FingerInitialState> StartState(const FingerEffects& effects) const;

  const Automaton& finger() const { return finger_; }
  /// Name of finger mode `mode`.
  const std::string& ModeName(int mode) const;

 private:
  // A simulator with the System it points to.
  struct Entry {
    explicit Entry(System s) : system(std::move(s)), simulator(system) {}
    System system;
    Simulator simulator;
  };
  // The simulator of the finger with the flows `effects` adds (compliance), compiled once.
  std::shared_ptr<const Entry> SimulatorFor(const FingerEffects& effects) const;
  // The parameter values of `effects` and `run`'s object, set per run
  // (SimulationOptions::parameters). Throws std::invalid_argument for bad effects.
  static std::vector<std::pair<std::string, double>> RunParameters(const MeasuredRun& run,
                                                                   const FingerEffects& effects);
  // The prediction along the motor path `motor` (one position per sample of `run`). With
  // `stall_from`, the run ends (kStopped) at the first sample from that index on where the finger
  // has stalled.
  FingerPrediction PredictAlong(const MeasuredRun& run, const FingerEffects& effects,
                                std::vector<double> motor, std::optional<size_t> stall_from) const;
  Automaton finger_;
  Options options_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, std::shared_ptr<const Entry>> cache_;
};

}  // namespace hybrid
