#pragma once

#include <Eigen/Core>

#include "hybrid/automaton/automaton.h"

namespace hybrid::gripper {

/// The constants of one Robotiq finger shared by the closed form, the geometry and the generated
/// automaton (`spec/finger.ha`): joint ranges in degrees (Klamp't limits, see
/// docs/gripper_facts.md), the motor range in counts, and the report's transmission
/// rates m1 = theta1_max / 140 and m2 = theta2_max / 100 (degrees per count).
struct FingerParameters {
  Eigen::Vector3d theta_min{0.0, 0.0, -55.0};
  Eigen::Vector3d theta_max{70.0, 90.0, 43.0};
  /// Fully closed motor position; the motor range is [0, motor_max].
  double motor_max = 255.0;
  /// In phase 3, link 3 reaches theta3_max this fraction f of the way from g_s (where link 2
  /// stopped) to motor_max: the report's one half (figure 4.1). The law is section 4's scaled by
  /// (1 - f) / f: theta3 = theta3_s + (1 - f) / f (theta3_max - theta3_s) (g - g_s) /
  /// (motor_max - g), as spec/finger.ha's parameter theta3_fraction has it. In (0, 1) (at 1 the
  /// law would be flat and theta3 would jump to its limit at motor_max).
  double theta3_fraction = 0.5;

  double m1() const { return theta_max[0] / 140.0; }
  double m2() const { return theta_max[1] / 100.0; }
  /// The distal span c = theta3_max - theta3_min of section 4.2.
  double c() const { return theta_max[2] - theta_min[2]; }
  /// The scale (1 - f) / f of the phase-3 law.
  double m3_scale() const { return (1.0 - theta3_fraction) / theta3_fraction; }
};

/// The parameters of a finger automaton like spec/finger.ha: its parameters theta1_min ..
/// theta3_max and theta3_fraction (the default of FingerParameters where the automaton has no
/// theta3_fraction), evaluated with the automaton's current parameter values. Throws
/// std::invalid_argument naming the first joint-range parameter the automaton lacks.
FingerParameters FingerParametersOf(const Automaton& finger);

}  // namespace hybrid::gripper
