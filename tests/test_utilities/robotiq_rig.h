#pragma once

// An independent simulator of the report's measuring rig (section 5), for test data that the code
// under test did not make: one Robotiq finger whose settled joint angles follow the report's
// section-4 tables (written here again from the report, not taken from gripper/), the gripper
// controller as the report (section 2) and the manual describe it, the hidden effects of the
// diagnosis vocabulary, and measurement noise. It depends on the C++ standard library only:
// nothing of automaton/, solvers/ or gripper/, so that a mistake shared by the model and the
// test data cannot hide.
//
// Coordinates. The request r is what the user commands (0 open .. 255 closed); the motor position
// p is where the controller drives the motor; the drive position q is where the finger's
// transmission is (p through the play and offset of RigEffects); the angles are the section-4
// configuration at q, as the report's tables give it for a finger closing from 0 (the tables
// are retraced on opening: the finger has no hysteresis of its own).
//
// The controller (report section 2; the manual, docs/gripper_facts.md): the motor
// moves towards the request and stops when the finger can move no further (the free finger
// against the palm at q = 240; link 3 at its upper limit; link 2 at its limit with link 3 at its
// lower one); it stays there until a more open position is requested. Samples are taken once the
// finger has settled (the report's protocol), so after request r the motor is at
// min(r, p_stop), p_stop being the motor position at which q reaches the stop.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hybrid::testing {

/// The finger's constants: the joint ranges of docs/gripper_facts.md, m1 = theta1_max / 140 and
/// m2 = theta2_max / 100 (deg per count) as in the report, and the phase-3 law of link 3.
struct RigFinger {
  double theta1_max = 70.0;  ///< deg; link 1 reaches it at q = 140
  double theta2_max = 90.0;  ///< deg; link 2 reaches it 100 counts after link 1 stopped
  double theta3_min = -55.0;
  double theta3_max = 43.0;
  /// Link 3 reaches theta3_max this fraction of the way from q_s (link 2 stopped) to 255: the
  /// report's one half (figure 4.1).
  double theta3_fraction = 0.5;
};

/// Where an object blocks link 1 or link 2: drive positions (counts) of first contact, the
/// report's g_ob; nullopt for no contact.
struct RigObject {
  std::optional<double> gob1;
  std::optional<double> gob2;
};

/// The hidden effects of the diagnosis vocabulary; all neutral by default.
struct RigEffects {
  double backlash = 0.0;      ///< counts of play: after a reversal the finger waits this long
  double motor_offset = 0.0;  ///< counts: the finger is driven to p - offset (clipped to [0, 255])
  std::array<double, 3> bias{};        ///< deg added to each measured angle
  std::array<double, 2> compliance{};  ///< deg per count that links 1, 2 yield while blocked
};

/// The finger's joint angles (deg; theta3 relative to link 2) at drive position q in [0, 255],
/// with `compliance` (deg per count) for links blocked by the object.
std::array<double, 3> RigAngles(double q, const RigFinger& finger, const RigObject& object,
                                const std::array<double, 2>& compliance = {});

/// The drive position at which the finger can move no further and the controller stops the
/// motor (at most 255).
double RigStopPosition(const RigFinger& finger, const RigObject& object);

/// One settled sample.
struct RigSample {
  double request = 0.0;           ///< the position request, counts
  double position = 0.0;          ///< the motor position the gripper reports (whole counts)
  double drive = 0.0;             ///< the finger's drive position q (not measured)
  std::array<double, 3> theta{};  ///< measured angles (deg); NaN for a missing cell
};

/// How a run is measured.
struct RigMeasurement {
  double noise_deg = 0.0;       ///< standard deviation of Gaussian noise on each angle
  double missing_fraction = 0;  ///< probability that an angle cell is missing
  std::uint64_t seed = 1;
  /// Outliers on theta3 (the report's section 5: its sensor's): each sample is the first of an
  /// outlier with this probability, of a size drawn uniformly from [outlier_min, outlier_max]
  /// degrees with a random sign, added to the measured angle; with probability
  /// `outlier_pair_fraction` the next sample gets one too (an adjacent pair). Drawn from their
  /// own stream (seeded from `seed`), so that noise and missing cells are those of a run without
  /// outliers.
  double outlier_fraction = 0.0;
  double outlier_min = 10.0, outlier_max = 25.0;
  double outlier_pair_fraction = 0.0;
};

/// The settled samples of a run that commands `requests` in order, starting from the open finger
/// (motor and finger at 0, play taken up in the closing direction).
std::vector<RigSample> RigRun(const std::vector<double>& requests, const RigFinger& finger,
                              const RigObject& object, const RigEffects& effects,
                              const RigMeasurement& measurement);

/// Requests from `from` to `to` (either direction) in steps of `step` > 0, both ends included.
std::vector<double> RigSweep(double from, double to, double step);

/// How a protocol steps the request: by 1 count, by 2, or by irregular amounts (0.5 to 4 counts).
enum class RigStepping { kOne, kTwo, kIrregular };

/// The requests of one run of the report's protocol: from 0 up to `top` and back to 0, stepped
/// as `stepping` says (irregular steps drawn with `seed`). With `reverse_at` in (0, top), the
/// run also reverses once on the way up: up to reverse_at, down by `reverse_depth` (not below 0),
/// then up again to top. Every request lies in [0, 255].
std::vector<double> RigProtocol(double top, RigStepping stepping, std::uint64_t seed,
                                std::optional<double> reverse_at = std::nullopt,
                                double reverse_depth = 20.0);

/// The rows of `samples` as CSV lines of the measured-data format
/// (include/hybrid/gripper/measured_data.h) with the optional `position` column:
/// run,g,position,theta1,theta2,theta3[,gob,contact_link] (gob and contact_link when `contact_link`
/// is 1 or 2; `gob` is then the object's position for that link; two empty cells for a free run
/// when `contact_columns`). No header.
std::string RigCsvRows(const std::string& run, const std::vector<RigSample>& samples,
                       const RigObject& object, int contact_link, bool contact_columns = false);

/// The header that goes with RigCsvRows: with or without the contact columns.
std::string RigCsvHeader(bool contact_columns);

}  // namespace hybrid::testing
