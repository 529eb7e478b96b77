#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/gripper/hand.h"
#include "hybrid/gripper/obstacle.h"
#include "hybrid/gripper/robot_frames.h"

namespace hybrid {
class Simulator;
}

namespace hybrid::gripper {

/// The gripper's output registers (robot to gripper), named as in the Robotiq 3-Finger
/// Adaptive Gripper's manual. Each is an integer: the flags 0 or 1, rMOD 0..3 (basic, pinch,
/// wide, scissor), the others 0..255. Per-finger arrays are indexed A, B, C, S (the scissor
/// axis); what each changes in the model is in docs/gripper_emulator.md.
struct GripperRegisters {
  int rACT = 0;  ///< activation (0: reset)
  int rMOD = 0;  ///< operating mode: 0 basic, 1 pinch, 2 wide, 3 scissor
  int rGTO = 0;  ///< go to the requested positions (0: stop)
  int rATR = 0;  ///< automatic release: open every finger
  int rGLV = 0;  ///< glove mode (not modelled)
  int rICF = 0;  ///< individual control of fingers: rPR[1], rPR[2] drive B and C
  int rICS = 0;  ///< individual control of the scissor axis: rPR[3] drives it
  std::array<int, 4> rPR = {0, 0, 0, 0};          ///< position requests (rPRA, rPRB, rPRC, rPRS)
  std::array<int, 4> rSP = {255, 255, 255, 255};  ///< speeds (rSPA, ...)
  std::array<int, 4> rFR = {150, 150, 150, 150};  ///< forces (rFRA, ...; not modelled)

  /// The register named `name` as the manual names it ("rACT", ..., "rPRA".."rPRS",
  /// "rSPA".."rSPS", "rFRA".."rFRS"); nullptr for a name that is no register.
  int* Find(std::string_view name);
};

/// The gripper's input registers (status), as the manual names them. Arrays are indexed A, B,
/// C, S.
struct GripperStatus {
  int gACT = 0;  ///< activation echo
  int gMOD = 0;  ///< operating mode echo
  int gGTO = 0;  ///< go-to echo
  int gIMC = 0;  ///< 0 reset, 1 activating, 2 changing mode, 3 done
  int gSTA = 0;  ///< 0 moving, 1 some fingers stopped early, 2 all stopped early, 3 all arrived
  int gFLT = 0;  ///< fault (not modelled: 0)
  std::array<int, 4> gDT = {0, 0, 0, 0};  ///< 0 moving, 1/2 stopped opening/closing, 3 arrived
  std::array<int, 4> gPR = {0, 0, 0, 0};  ///< the position requests the motors follow
  std::array<int, 4> gPO = {0, 0, 0, 0};  ///< motor positions, rounded
  std::array<int, 4> gCU = {0, 0, 0, 0};  ///< motor currents (not modelled: 0)
};

/// What the emulator reports after a step.
struct GripperState {
  double time = 0.0;  ///< seconds since construction
  GripperStatus status;
  std::array<Eigen::Vector3d, 3> theta;     ///< the report's angles of fingers A, B, C (degrees)
  std::array<double, 3> motor = {0, 0, 0};  ///< motor positions g of A, B, C (counts)
  double scissor = 0.0;                     ///< scissor axis position s (counts)
  double spread_angle = 0.0;                ///< phi (degrees, HandLayout)
  JointState joints;                        ///< the ROS description's joints (RosJointState)
  std::string simulation = "completed";     ///< the last step's run status (SimulationStatus name)
  std::string message;                      ///< why, when not completed
};

/// A stateful emulator of the gripper for a physics simulator's loop: registers in (Command),
/// time steps (Step), joint states and status registers out. It steps the composed automata of
/// spec/gripper.ha (three driven fingers, the scissor axis, their controllers) incrementally:
/// the model is compiled once, and each step is one simulation run from the state the last one
/// reached (SimulationOptions::start_modes and start_x) with the requests and speeds the
/// registers give, held constant over the step. A run with the same requests at the same times
/// is the same run (docs/gripper_emulator.md states the tolerance measured).
///
/// Objects (palm plane, as Hand takes them) enter as contact positions: each finger's gob1..3
/// are those of the hand closing on them (Hand, all fingers commanded to 255) at the spread
/// position the scissor axis is sent to; they are recomputed when that changes. The scissor axis
/// detects no object, and finger-finger touches are those of the fingers closing together.
class GripperEmulator {
 public:
  /// `model`: a system like spec/gripper.ha (instances A, B, C, S, ctlA, ctlB, ctlC, ctlS).
  /// Starts reset (gACT = 0), open, with the scissor axis at 0. Throws std::invalid_argument (a
  /// message for the user) for a model without those instances or an object that overlaps the
  /// palm or an open finger.
  GripperEmulator(System model, std::vector<Obstacle> objects, const HandLayout& layout = {});
  ~GripperEmulator();
  GripperEmulator(GripperEmulator&&) noexcept;
  GripperEmulator& operator=(GripperEmulator&&) noexcept;

  /// Writes the output registers; they take effect from the next step. Throws
  /// std::invalid_argument naming the register for a value out of its range.
  void Command(const GripperRegisters& registers);
  /// Advances `dt` seconds (0 < dt <= 10) and returns the state reached. A run that does not
  /// complete (SimulationStatus) leaves the state where it stopped and says so in `simulation`.
  const GripperState& Step(double dt);
  const GripperState& state() const { return state_; }
  const GripperRegisters& registers() const { return registers_; }
  const System& system() const { return *system_; }

 private:
  void ApplyRegisters();
  void ResolveNames();
  void UpdateState();
  void SetContacts(double spread);
  /// The System slot of symbol `name` (inputs).
  int Slot(const std::string& name) const;
  /// The index of continuous variable `name` in the simulator's state.
  int Index(const std::string& name) const;

  std::unique_ptr<System> system_;
  std::unique_ptr<Simulator> simulator_;
  std::vector<Obstacle> objects_;
  HandLayout layout_;
  GripperRegisters registers_;
  GripperState state_;
  std::vector<int> modes_;
  Eigen::VectorXd x_;
  int imc_ = 0;                                   // gIMC
  std::array<double, 4> request_ = {0, 0, 0, 0};  // the controllers' requests (A, B, C, S)
  std::array<double, 4> speed_ = {255, 255, 255, 255};
  std::array<double, 12> gob_;  // A.gob1..3, B..., C...
  double contacts_spread_ = -1.0;
  // Resolved once (ResolveNames): the requests' input slots, the per-run parameters' names
  // (speeds, then A.gob1..C.gob3), the state indices of theta1..3 and g per finger and of S.s,
  // and per controller its component and the `status` of each of its modes.
  std::array<int, 4> request_slot_ = {};
  std::vector<std::string> parameter_names_;
  std::array<int, 12> variable_index_ = {};
  int scissor_index_ = 0;
  std::array<int, 4> controller_ = {};
  std::array<std::vector<int>, 4> status_of_mode_;
};

}  // namespace hybrid::gripper
