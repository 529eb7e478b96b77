#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/automaton.h"

namespace hybrid {

/// A physical effect of the gripper or of its measuring rig that the report's finger model leaves
/// out, as `hybrid diagnose` names it.
enum class Cause {
  kBacklash,     ///< play of b counts between motor and finger
  kMotorOffset,  ///< the finger follows the model at g - d
  kJointRange,   ///< a joint's upper limit differs from the report (its rate scales with it)
  kSensorBias,   ///< a constant offset on one measured angle
  kCompliance,   ///< a link blocked by an object keeps yielding k degrees per motor count
  kTheta3Law,    ///< link 3 reaches its limit at another fraction of the way from g_s to 255
};

/// "backlash", "motor_offset", "joint_range", "sensor_bias", "compliance", "theta3_law".
std::string_view CauseName(Cause cause);

/// The effects on one finger, every one neutral by default (the model as declared).
struct FingerEffects {
  /// Play b >= 0 (counts): after the motor reverses, the finger stays put for b counts.
  double backlash = 0.0;
  /// d (counts): the finger is driven to g - d (clipped to [0, 255]); d > 0 starts late.
  double motor_offset = 0.0;
  /// Upper limits theta1_max, theta2_max, theta3_max (deg); nullopt keeps the model's. m1 and m2
  /// follow theta1_max and theta2_max, as in the report.
  std::array<std::optional<double>, 3> joint_max;
  /// Added to the measured theta1, theta2, theta3 (deg): an output map.
  std::array<double, 3> sensor_bias = {0.0, 0.0, 0.0};
  /// Yield rates k1, k2 >= 0 (deg per count) of links 1 and 2 while blocked by an object.
  std::array<double, 2> compliance = {0.0, 0.0};
  /// The model parameter theta3_fraction (report: 0.5); nullopt keeps the model's.
  std::optional<double> theta3_fraction;

  /// True when nothing changes the model's dynamics (only the drive and output maps differ).
  bool SameDynamics(const FingerEffects& other) const;
};

/// One fitted number of FingerEffects: a cause and, for per-joint or per-link causes, which one
/// (joint 0..2 for kJointRange and kSensorBias, link 0..1 for kCompliance, else 0).
struct EffectParameter {
  Cause cause = Cause::kBacklash;
  int index = 0;
  friend bool operator==(const EffectParameter&, const EffectParameter&) = default;
};

/// Its name in reports: "backlash", "motor_offset", "theta2_max", "theta3_bias",
/// "compliance_link1", "theta3_fraction".
std::string ParameterName(const EffectParameter& p);
/// Its unit: "count", "deg", "deg/count" or "" (a fraction).
std::string_view ParameterUnit(const EffectParameter& p);
/// Every parameter a diagnosis can fit, one candidate extension each (11).
std::vector<EffectParameter> AllEffectParameters();
/// The value `p` has in `effects`, or the model's value (`finger`'s parameters) when `effects`
/// leaves it neutral (e.g. theta2_max = 90 from spec/finger.ha).
double GetEffect(const FingerEffects& effects, const EffectParameter& p, const Automaton& finger);
/// Sets `p` in `effects` to `value`.
void SetEffect(FingerEffects& effects, const EffectParameter& p, double value);
/// The model's own value of `p` (neutral: 0 for offsets, biases, play and yield rates).
double NeutralValue(const EffectParameter& p, const Automaton& finger);

/// The drive positions of the finger for motor positions g[0..n): the play operator with offset,
/// q_k = clip(clamp(q_{k-1}, g_k - d, g_k - d + b), 0, 255) with q_{-1} = 0 (the finger starts
/// open and the play taken up in the closing direction). Throws std::invalid_argument
/// ("the drive positions: ...") if b < 0 or a value is not finite.
std::vector<double> DrivePositions(std::span<const double> g, double backlash, double offset);

/// The finger automaton with the effects that change its dynamics: SetParameter for theta_j_max
/// and theta3_fraction, and for compliance a parameter `compliance_link<i>` and the flow
/// theta_i' = compliance_link<i> * u in every mode where c_i = 1 (the blocked link yields).
/// Precondition: `finger` is spec/finger.ha's automaton (throws std::invalid_argument
/// "the finger's effects: ..." when a name it needs is missing or a value is out of range).
Automaton ApplyDynamicEffects(const Automaton& finger, const FingerEffects& effects);

/// Throws std::invalid_argument ("the finger's effects: ...") unless theta3_fraction (if set)
/// lies in (0, 1) and both compliances are finite and >= 0: the checks ApplyDynamicEffects makes
/// of values it is given.
void CheckDynamicEffects(const FingerEffects& effects);

/// The extended model as one automaton (ApplyDynamicEffects, then the maps as automaton parts):
/// - the transmission: a play automaton with offset composed between the motor and the finger
///   (product): each finger mode M becomes M_closing (engaged, g = g_motor - d), M_slack (the
///   finger frozen while the motor moves) and M_opening (engaged, g = g_motor - d + b); the
///   finger's transitions are kept in the engaged copies; the play's transitions come first
///   (priority): closing -> slack when u < 0 or g reaches 255, slack -> closing when
///   g_motor - d >= g, g <= 255 - 1e-6 and u > 0, slack -> opening when g_motor - d + b <= g,
///   g >= 1e-6 and u < 0, opening -> slack when u > 0 or g reaches 0. The new variable g_motor is
///   the measured motor position: it moves with g in the engaged copies (and stalls with it where
///   the finger stops the motor, phase 4) and at rate u in the slack copies; g stays the finger's
///   drive position;
/// - sensor biases: variables theta<j>_measured = theta<j> + bias (same flows and resets), only
///   for non-zero biases.
/// The initial state is the motor at 0 and the finger where DrivePositions puts it (for d < 0,
/// `initial_finger` gives the finger's mode name and continuous values there, as simulated).
/// Properties and the scenario of `finger` are kept (properties read the finger's variables).
struct FingerInitialState {
  std::string mode;
  std::vector<std::pair<std::string, double>> values;
};
Automaton ExtendFingerModel(const Automaton& finger, const FingerEffects& effects,
                            const std::optional<FingerInitialState>& initial_finger = {});

}  // namespace hybrid
