#pragma once

#include <array>
#include <optional>
#include <vector>

#include "hybrid/automaton/automaton.h"
#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/gripper/finger_geometry.h"
#include "hybrid/gripper/obstacle.h"

namespace hybrid::gripper {

/// A finger closing against objects given by geometry: the closed form with the contact
/// positions g_ob found from the shapes, and the automaton whose contact guards are distances.
///
/// Obstacles are the objects (finger frame, metres) plus the palm (a bar whose top surface is
/// the line y = FingerGeometry::palm_y()). Link i is blocked at the first motor position where
/// the signed distance from its contact segment (FingerGeometry::ContactSegments) to some
/// obstacle reaches 0 while it moves; the closed form is then
/// continued with that contact (FingerClosedForm), and the search goes on for the other links.
/// The search samples the path every kResolution counts (in phase 3, whose theta3 rate grows
/// without bound towards g = 255, every 0.025 degrees of theta3), so no point of the finger
/// moves more than 0.105 mm between samples, and it bisects each sign change to 1e-10 counts.
/// Samples that a motion bound proves clear are skipped (no link can have moved as far as its
/// clearance at the last sample evaluated: FingerClosedForm::VariationBound and
/// FingerGeometry::LinkMotionBounds), so the search finds the same first sign change as on every
/// sample, in a few dozen evaluations where the finger is far from everything.
/// Objects are at least 0.2 mm across (Obstacle::kMinimumRadius), so a link cannot cross one
/// between samples; a contact is missed only if a link dips into an object by less than its
/// motion between two samples and leaves again (a graze). Contacts with the palm at or after
/// the free-space stop (g = 240, decision D3, where the fingertip touches the palm by
/// construction) are not counted.
class GeometricFinger {
 public:
  static constexpr double kResolution = 0.05;

  /// `imposed`: contacts found outside this finger (another finger touching link i at
  /// imposed.gob[i], see include/hybrid/gripper/hand.h); each competes with the geometric contacts
  /// (the first one blocks the link). `up_to`: contacts are searched for motor positions up to this
  /// one (the motor command; the closed form beyond it assumes no further contact). Throws
  /// std::invalid_argument ("object ... overlaps the palm ...") if an object overlaps the palm or
  /// the open finger (g = 0).
  explicit GeometricFinger(std::vector<Obstacle> objects,
                           const FingerGeometry& geometry = FingerGeometry(),
                           const FingerParameters& parameters = {},
                           const FingerContacts& imposed = {}, double up_to = 255.0);

  const FingerClosedForm& closed_form() const { return closed_form_; }
  FingerConfiguration At(double g) const { return closed_form_.At(g); }
  /// Motor positions where links 1..3 are blocked (FingerContacts::kNone: never).
  const FingerContacts& contacts() const { return closed_form_.contacts(); }
  /// For each link, the obstacle that blocks it: an index into objects(), kPalm, kImposed, or
  /// nullopt.
  static constexpr int kPalm = -1;
  static constexpr int kImposed = -2;
  const std::array<std::optional<int>, 3>& blocked_by() const { return blocked_by_; }
  /// Whether some link touches one of the objects (not the palm) while closing.
  bool touches_object() const;
  const std::vector<Obstacle>& objects() const { return objects_; }
  const FingerGeometry& geometry() const { return geometry_; }
  /// The palm as an obstacle (a bar 0.3 m long whose top is y = palm_y).
  Obstacle palm() const;
  /// WithGeometricContacts(finger, objects() and palm(), geometry()): the automaton that finds
  /// the same contacts by simulation.
  Automaton ContactAutomaton(const Automaton& finger) const;
  /// Smallest signed distance from contact segment `link` (0-based) to the objects and the palm.
  double Clearance(const Eigen::Vector3d& theta, int link) const;

 private:
  std::vector<Obstacle> objects_;
  FingerGeometry geometry_;
  FingerParameters parameters_;
  FingerClosedForm closed_form_;
  std::array<std::optional<int>, 3> blocked_by_;
};

/// `finger` (the automaton of spec/finger.ha) with each contact guard `g >= gob_i and u > 0`
/// (transitions labelled contact1..3) replaced by `1000 d_i <= 0 and u > 0` (millimetres, so
/// that the simulator's boundary tolerance is 1e-12 m), where d_i is the smallest
/// signed distance from contact segment i (FingerGeometry::ContactSegments), computed from
/// theta1..theta3 by the forward kinematics of `geometry`, to `obstacles`
/// (Obstacle::DistanceExpression). Throws std::invalid_argument (a message for the user) if
/// `finger` lacks theta1..3 or a contact transition's guard does not start with `g >= gob_i`, or
/// `obstacles` is empty.
Automaton WithGeometricContacts(const Automaton& finger, const std::vector<Obstacle>& obstacles,
                                const FingerGeometry& geometry = FingerGeometry());

}  // namespace hybrid::gripper
