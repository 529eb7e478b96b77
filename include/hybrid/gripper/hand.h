#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "hybrid/automaton/system.h"
#include "hybrid/gripper/geometric_finger.h"

namespace hybrid::gripper {

/// The operating modes of the real gripper; each sets the spread motor position s (0..255).
enum class SpreadMode { kBasic, kWide, kPinch, kScissor };

/// "basic", "wide", "pinch", "scissor".
std::string SpreadModeName(SpreadMode mode);
/// Inverse of SpreadModeName; throws std::invalid_argument naming the accepted values.
SpreadMode SpreadModeByName(const std::string& name);

/// Palm layout and spread actuator (metres, degrees). Frame: x from finger A towards fingers B
/// and C, y the palm normal (joint 1 of every finger at y = 0), z across. Finger A stands at
/// (-half_span, 0, 0) and closes towards +x; B and C at (half_span, 0, +-lateral) close towards
/// -x, their planes turned by the spread angle phi about the y axis towards the centre plane
/// (phi > 0) or away from it. phi = phi_min + (phi_max - phi_min) s / 255, with the spread
/// presets of spec/hand.ha. The palm dimensions are not in docs/gripper_facts.md:
/// they are assumptions of this model (decision H1 of docs/finger_model.md).
struct HandLayout {
  double half_span = 0.045;
  double lateral = 0.036;
  /// Links are `link_width` wide across their plane: two fingers touch when their link centre
  /// lines come within link_width of each other (docs/gripper_facts.md: about 0.03).
  double link_width = 0.03;
  double phi_min = -17.0;
  double phi_max = 17.0;
  double s_basic = 137.0;
  double s_wide = 0.0;
  double s_pinch = 255.0;
};

/// The three-finger hand closing on objects, quasistatically: every finger follows its closed
/// form (GeometricFinger) for its own motor command, objects and the palm block links, and
/// fingers that touch each other block each other.
///
/// Objects are described in the palm's x-y plane and extruded along z (a circle is a cylinder
/// across the hand, a segment a bar); each finger meets them through its FingerPlacement.
/// Fingers in planes turned by the spread angle see the object's section exactly (contact is
/// the projection of a link onto the x-y plane touching the section).
///
/// Finger-finger contact: links of different fingers are segments in space; they touch when
/// their distance reaches HandLayout::link_width. The motor positions are swept together (all
/// fingers at g while g is below their command); at the first touch both links are blocked
/// (GeometricFinger `imposed` contacts) and the sweep continues. Touches are found by sampling
/// every GeometricFinger::kResolution counts and bisection, like object contacts (skipping the
/// samples a motion bound proves apart, per pair of links, as GeometricFinger does).
class Hand {
 public:
  struct FingerTouch {
    int finger_a, link_a;  // 0 = A, 1 = B, 2 = C; links 0..2
    int finger_b, link_b;
    double g;
  };

  /// `commands`: motor position requested for fingers A, B and C (one value for all models
  /// the single motor command). `spread`: the spread motor position s in [0, 255] (see
  /// SpreadPosition). Throws std::invalid_argument (a message for the user; "finger B: ..." for an
  /// object that overlaps the palm or an open finger B) for a command or spread outside [0, 255],
  /// or an object that overlaps the palm or an open finger.
  Hand(std::vector<Obstacle> objects, double spread, const std::array<double, 3>& commands,
       const HandLayout& layout = {});

  /// The spread position of an operating mode (kScissor: the basic position; in scissor mode
  /// the spread follows its own command).
  static double SpreadPosition(SpreadMode mode, const HandLayout& layout = {});

  /// Spread angle phi in degrees.
  double spread_angle() const { return phi_; }
  const HandLayout& layout() const { return layout_; }
  const std::vector<Obstacle>& objects() const { return objects_; }
  const std::array<double, 3>& commands() const { return commands_; }
  const GeometricFinger& finger(int f) const { return fingers_.at(f); }
  const std::vector<FingerTouch>& touches() const { return touches_; }

  /// Configuration of finger f when the common sweep is at g (the finger at min(g, its
  /// command)). Throws std::out_of_range for g outside [0, 255].
  FingerConfiguration At(int f, double g) const;
  /// Joint 1, 2, 3 and the fingertip of finger f in palm coordinates (x, y, z), metres.
  std::array<Eigen::Vector3d, 4> Points(int f, const Eigen::Vector3d& theta) const;
  /// The finger's placement in the x-y plane (origin_x, x_scale) and its plane's base z.
  FingerGeometry FingerGeometryOf(int f) const;

  /// The hand as composed automata, for simulation: instances A, B and C of the automaton named
  /// "finger" in `hand_model` (spec/hand.ha) with this hand's geometric contact guards, and
  /// instance S of its "spread" automaton if it has one. Contact guard of link i of a finger:
  /// `1000 min(d_i, c_i) <= 0 and u > 0` with d_i its distance to the objects and the palm
  /// (GeometricFinger::ContactAutomaton) and c_i the distance of its centre line to the other
  /// fingers' links minus link_width (the finger-finger rule of this class). For that every
  /// finger automaton declares the other fingers' joint angles as variables named "B.theta1",
  /// ..., shared, without flow (their own instance gives it) and starting at 0 like the owner.
  /// Only link pairs that come within 2 mm of touching on this quasistatic closing enter the
  /// guards (the others stay that far apart as long as the simulation follows the same path). One
  /// motor command `u` shared by the fingers when `shared_command`, else one per finger (A.u, B.u,
  /// C.u). Throws std::invalid_argument ("the model '...' has no automaton named 'finger'") if
  /// `hand_model` has none.
  System ComposedAutomata(const System& hand_model, bool shared_command) const;

 private:
  /// Origin and closing direction of finger f in space.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> Frame(int f) const;
  /// Points() as expressions of joint-angle expressions.
  std::array<std::array<Expression, 3>, 4> PointExpressions(
      int f, const std::array<Expression, 3>& theta) const;

  static constexpr double kCandidateMargin = 0.002;

  std::vector<Obstacle> objects_;
  HandLayout layout_;
  std::array<double, 3> commands_;
  double phi_;
  std::vector<GeometricFinger> fingers_;
  std::vector<FingerTouch> touches_;
};

/// Distance between segments [p, q] and [r, s] in space.
double SegmentDistance3(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                        const Eigen::Vector3d& r, const Eigen::Vector3d& s);

}  // namespace hybrid::gripper
