#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/gripper/finger_geometry.h"
#include "hybrid/gripper/hand.h"
#include "hybrid/gripper/obstacle.h"

namespace hybrid::gripper {

/// Small multiples of one finger closing (like figures 6.2 to 6.5 of the report): one panel per
/// (g, configuration) in `frames`, in the given order, at most four panels per row.
///
/// Each panel shows, in the finger frame of `geometry` (metres; +y up, +x the closing
/// direction), the palm (a filled rectangle below y = palm_y()), `objects` (a circle as
/// <circle>, a bar as a thick <line> with round caps, which is exactly its capsule), the three
/// links at configuration.theta (degrees) as thick round-capped lines in three colours
/// (class "link l1", "link l2", "link l3"; the same colours as AnglePlotSvg's theta1..3) and
/// joints 1 to 3 as small circles, with the caption "g = <g>, phase <PhaseName>" underneath (g
/// rounded to two decimals). Every panel has the same scale and window: the bounding box of all
/// frames' joints, all objects and the palm's top, plus 1 cm, its longer side 220 pixels (so a
/// far-away object makes the finger small). A scale bar and a link legend are drawn below the
/// grid.
///
/// Returns a standalone SVG document (ending in "</svg>\n"); coordinates in pixels with two
/// decimals, so the output is deterministic. Throws std::invalid_argument
/// ("finger drawing: ...") if `frames` is empty or a frame's g or angle is not finite.
std::string FingerDrawingSvg(const FingerGeometry& geometry, const std::vector<Obstacle>& objects,
                             const std::vector<std::pair<double, FingerConfiguration>>& frames);

/// One panel of HandDrawingSvg: the common motor position and each finger's configuration.
struct HandFrame {
  double g = 0.0;
  /// Fingers A, B and C (e.g. hand.At(f, g)).
  std::array<FingerConfiguration, 3> fingers;
};

/// Small multiples of the three-finger hand closing: one panel per frame, in the given order, at
/// most four panels per row, headed "Hand configurations (spread angle <phi> deg)".
///
/// Each panel has two views at the same scale (and the same scale in every panel):
/// - a side view of the palm's x-y plane (metres; x right, y up): the palm (a filled rectangle
///   below y = hand.finger(0).geometry().palm_y(), from 2 cm before the leftmost finger base to
///   2 cm beyond the rightmost), hand.objects() drawn as in FingerDrawingSvg, and every finger's
///   links (x and y of Hand::Points at the frame's theta) as round-capped lines, one group per
///   finger (<g class="finger A">, "finger B", "finger C", each in its own colour) holding its
///   links (<line class="link l1">, "link l2", "link l3"); finger C is drawn last, thinner and
///   dashed, so that B stays visible where the two coincide (they project onto the same lines
///   when their configurations are equal). Joints 1 to 3 of every finger are small circles
///   (class "joint"; C's smaller). The window is the bounding box of all frames' joints and
///   fingertips, all objects and the palm's top, plus 1 cm, its longer side 220 pixels.
/// - under it, labelled "from above", a view from above (<g class="top-view">; x right, z down
///   the page, as seen from +y): the palm across the finger bases (2 cm beyond them in x and z),
///   the objects as bands (they are extruded along z) and each finger's links (x and z;
///   class "top l1", "top l2", "top l3", in the same finger groups and styles), so the spread is
///   visible.
/// The caption "g = <g>" (rounded to two decimals) is under each panel, followed by a smaller
/// line with the fingers' phases ("phases A 2', B 2', C 2'"). A scale bar and a legend naming
/// fingers A, B and C are drawn below the grid. The <title> lists the frames' g and the spread
/// angle.
///
/// Returns a standalone SVG document (ending in "</svg>\n"); coordinates in pixels with two
/// decimals, so the output is deterministic. Throws std::invalid_argument ("hand drawing: ...") if
/// `frames` is empty or a frame's g or angle is not finite.
std::string HandDrawingSvg(const Hand& hand, const std::vector<HandFrame>& frames);

/// Measured samples of one run, drawn over AnglePlotSvg's curves: the position request g
/// (counts) of each sample and its angles theta1..3 (degrees; NaN where missing).
struct MeasuredSeries {
  std::vector<double> g;
  std::array<std::vector<double>, 3> theta;
};

/// The joint angles theta1, theta2, theta3 (degrees) of `closed_form` against the motor
/// position g in [0, motor_max] counts (like figures 5.2 and 5.4 of the report), titled
/// `title` (escaped for XML; control characters become spaces).
///
/// The x axis has ticks and gridlines every 50 counts, the y axis every 20 degrees over a
/// range covering [-60, 100] (widened by multiples of 20 if the angles leave it). Each angle is
/// a <polyline> (class "theta1", "theta2", "theta3") sampled at every multiple of 0.5 counts,
/// at motor_max and at every piece's end points (closed_form.pieces()), merged and sorted, so
/// the corners are exact; samples closer than 1e-9 counts to an earlier one are dropped.
/// Gridlines carry their value (data-g, data-theta). If closed_form.stop() is finite a dashed
/// vertical line (class "stop") marks it, labelled "motor stops (g = <stop>)". Every contact
/// position given to the closed form (closed_form.contacts(), the report's g_ob) within the
/// range gets a dotted vertical line (class "gob"), labelled "g_ob link <i> = <g>".
/// `measured` samples (figures 5.2 and 5.4 overlay the runs) are small dots in the joints'
/// colours (class "measured theta<k>"), at their request g; samples outside [0, motor_max] or
/// missing are left out, and the y range widens to hold the others. The legend then adds
/// "dots: measured" and "(<n> runs)".
///
/// Returns a standalone SVG document (ending in "</svg>\n"); coordinates in pixels with two
/// decimals, so the output is deterministic. Does not throw (apart from std::bad_alloc).
std::string AnglePlotSvg(const FingerClosedForm& closed_form, const std::string& title,
                         const std::vector<MeasuredSeries>& measured = {});

}  // namespace hybrid::gripper
