#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "hybrid/gripper/finger_parameters.h"

namespace hybrid::gripper {

/// Motor positions (counts) at which links 1, 2 and 3 are blocked by an object while the finger
/// closes: the report's g_ob (section 4.2). A value above the motor range (the default, +inf, or
/// the model's 256) means the link is never blocked by an object.
struct FingerContacts {
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  std::array<double, 3> gob = {kNone, kNone, kNone};
};

/// The report's movement phases (section 3). k4 is the stopped finger: link 3 blocked by an
/// object or at its upper limit, or the fully closed free finger against the palm (decision D3).
enum class FingerPhase { k1, k1Prime, k2, k2Prime, k3, k4 };

/// "1", "1'", "2", "2'", "3" or "4".
std::string PhaseName(FingerPhase phase);

/// The phase of the discrete state (c1, c2, c3), (l1, l2, l3) (l3 = -1 at link 3's lower limit),
/// by section 3's table with decision D3: 4 when link 3 is blocked (c3 or l3 = 1) or the free
/// finger is against the palm (l1 = l2 = 1, l3 = -1, no contact); else 3 when link 2 is blocked;
/// else 2 (2' with l3 = -1) when link 1 is; else 1 (1' with l3 = -1).
FingerPhase PhaseOfState(const std::array<int, 3>& c, const std::array<int, 3>& l);

/// The quasistatic state of a finger at a commanded motor position.
struct FingerConfiguration {
  /// Joint angles (theta1, theta2, theta3) in degrees; theta3 relative to link 2.
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  /// Where the motor is: the commanded g, or the position where the finger stopped (phase 4),
  /// whichever is smaller.
  double motor = 0.0;
  /// The discrete state (c1, c2, c3) and (l1, l2, l3); l3 = -1 at the lower limit of link 3.
  std::array<int, 3> c = {0, 0, 0};
  std::array<int, 3> l = {0, 0, 0};
  FingerPhase phase = FingerPhase::k1;
};

/// The name of the mode of spec/finger.ha with `q`'s discrete state: "c<c1c2c3>_l<l1l2l3>", "n"
/// for -1 (e.g. "c100_l00n").
std::string FingerModeName(const FingerConfiguration& q);

/// The closed-form (quasistatic) model of one finger closing from g = 0: the tables of section 4
/// of the report with the decisions of docs/finger_model.md, assembled at their breakpoints.
///
/// The configuration is a continuous, piecewise function of g with at most eight pieces:
/// - phase 1 (0 <= g, link 3 vertical): theta1 = m1 g, theta3 = -m1 g; phase 1' once theta3 is
///   at its minimum (theta3 = theta3_min);
/// - phase 2 from g1, where link 1 stopped (object at gob1 or its limit at 140):
///   theta2 = m2 (g - g1), theta3 = max(-(theta1 + theta2), theta3_min) (2 and 2');
/// - phase 3 from g_s, where link 2 stopped (object at gob2, or its limit):
///   theta3 = theta3_s + (theta3_max - theta3_s) (g - g_s) / (255 - g) (decision C1: section 4's
///   law continued from theta3_s, theta3's value at g_s, so theta3 is continuous; the report's
///   tables have theta3_s = theta3_min). It reaches theta3_max at g = (255 + g_s) / 2; with
///   FingerParameters::theta3_fraction f other than 1/2 the law is scaled by (1 - f) / f and
///   reaches it at g_s + f (255 - g_s);
/// - phase 4 (stopped) from the first of: link 3 blocked by an object (gob3), theta3 reaching
///   theta3_max, or the free finger fully closed against the palm at g = 240 (D3). Beyond that
///   the configuration no longer changes and `motor` stays at the stopping position.
///
/// Events at the same g are taken in the model's declaration order (contact before limit, link 1
/// before 2 before 3), as the simulator does for events at exactly the same instant. (A contact
/// that coincides with theta3 reaching theta3_max in phase 3, a root found numerically, may be
/// taken in the other order by the simulator: the angles agree, the flags differ.) Every value is
/// finite for every g in [0, 255], including g = 255 (the report's law divides by 255 - g; the
/// pieces end before that except when g_s = 255, where theta3 stays at theta3_s).
class FingerClosedForm {
 public:
  /// Throws std::invalid_argument (a message for the user) if a contact position is negative or
  /// NaN, or the parameters are inconsistent (empty joint range, m1 or m2 not positive,
  /// theta3_min > 0 or theta3_max < 0, the open straight finger outside the joint ranges).
  explicit FingerClosedForm(const FingerContacts& contacts = {},
                            const FingerParameters& parameters = {});

  /// The configuration at commanded motor position g. Precondition: 0 <= g <= motor_max; throws
  /// std::out_of_range ("g = ... is outside the motor range ...") otherwise (NaN included).
  /// Breakpoints belong to the piece that ends there, as in the report's tables (g = 110 is
  /// phase 1).
  FingerConfiguration At(double g) const;

  /// The joint angles At(g[k]).theta of every g[k], written to theta[3 k .. 3 k + 2] (the same
  /// values, bit for bit), without the rest of the configuration: the batch form for many
  /// queries. Precondition: theta.size() == 3 g.size(); throws std::out_of_range as At does for
  /// the first g outside [0, motor_max] (theta's contents are unspecified then: the range is
  /// checked in the same pass), std::invalid_argument on sizes.
  void AnglesAt(std::span<const double> g, std::span<double> theta) const;

  /// Upper bounds, in degrees, on each joint angle's total variation while g goes from a to b
  /// (0 <= a <= b <= motor_max): per piece, |rate_i| times the length it shares with [a, b], plus
  /// for theta3 |span3| times the growth of phase 3's fraction there (exact where every angle is
  /// monotone on each piece, as in the report's phases). Zero for b <= a. With
  /// FingerGeometry::LinkMotionBounds, how far each link can move on the way: the step bound by
  /// which the contact searches skip (GeometricFinger, Hand).
  Eigen::Vector3d VariationBound(double a, double b) const;

  /// The motor position where the finger stops (phase 4), or nullopt-like +inf when it is still
  /// moving at motor_max.
  double stop() const { return stop_; }

  /// One piece of the path: on (g0, g1] (the first on [g0, g1]) theta = theta0 + rate (g - g0),
  /// except theta3 in phase 3, which follows the law above from (g_s, theta3_s) = (g0,
  /// theta0[2]).
  struct Piece {
    double g0 = 0.0;
    double g1 = 0.0;
    Eigen::Vector3d theta0 = Eigen::Vector3d::Zero();
    Eigen::Vector3d rate = Eigen::Vector3d::Zero();
    std::array<int, 3> c = {0, 0, 0};
    std::array<int, 3> l = {0, 0, 0};
    FingerPhase phase = FingerPhase::k1;
    /// theta3_max - theta0[2] in phase 3 (theta3 = theta0[2] + span3 (g - g0) / (255 - g),
    /// clamped at 1), 0 in other phases.
    double span3 = 0.0;
  };
  std::span<const Piece> pieces() const { return pieces_; }
  const FingerParameters& parameters() const { return parameters_; }
  const FingerContacts& contacts() const { return contacts_; }

 private:
  const Piece& PieceAt(double g) const;
  Eigen::Vector3d Evaluate(const Piece& piece, double g) const;
  void PackEnds();

  FingerParameters parameters_;
  FingerContacts contacts_;
  std::vector<Piece> pieces_;
  // pieces_[k].g1, packed for the search in At (at most 8 pieces; the rest +inf).
  std::array<double, 8> ends_;
  double stop_ = std::numeric_limits<double>::infinity();
};

}  // namespace hybrid::gripper
