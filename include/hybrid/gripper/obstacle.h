#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hybrid/automaton/expression.h"
#include "hybrid/gripper/finger_geometry.h"

namespace hybrid::gripper {

/// A malformed object description: `column` (1-based) points at the offending character.
class ObstacleParseError : public std::invalid_argument {
 public:
  ObstacleParseError(int column, const std::string& message)
      : std::invalid_argument(message), column_(column) {}
  int column() const { return column_; }

 private:
  int column_;
};

/// A fixed object in the finger plane: the set of points within `radius` of a core segment
/// [a, b] (a capsule). A circle is a capsule with a = b; a bar is a segment with a thickness.
///
/// Contact is Distance(link) reaching 0: the distance from the link (a segment) to the core,
/// minus the radius. It is negative when the link is inside the object. The radius must be at
/// least kMinimumRadius: so that a link moving into the object makes it cross 0 (not only touch
/// it), and so that no link can cross the object between two samples of the contact search
/// (GeometricFinger moves every point of the finger by at most 0.105 mm per sample, less than
/// the 0.2 mm diameter).
class Obstacle {
 public:
  static constexpr double kMinimumRadius = 1e-4;
  /// Throws std::invalid_argument ("a circle needs ...") unless the centre is finite and the radius
  /// finite and >= kMinimumRadius.
  static Obstacle Circle(const Eigen::Vector2d& centre, double radius);
  /// Throws std::invalid_argument ("a segment needs ...") unless the ends are finite and the radius
  /// finite and >= kMinimumRadius.
  static Obstacle Bar(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius);

  /// Parses "circle:X,Y,R" or "segment:X1,Y1,X2,Y2[,R]" (metres, finger frame; R of a segment
  /// defaults to kDefaultBarRadius). Each number is in the decimal syntax of
  /// automaton/number_syntax.h (one optional sign, no hexadecimal, no inf or nan), with spaces
  /// around it allowed. Throws ObstacleParseError naming the column (of the first character
  /// that does not fit, for a malformed number).
  static Obstacle Parse(std::string_view text);
  static constexpr double kDefaultBarRadius = 0.005;

  bool is_circle() const { return a_ == b_; }
  const Eigen::Vector2d& a() const { return a_; }
  const Eigen::Vector2d& b() const { return b_; }
  double radius() const { return radius_; }

  /// Signed distance from `link` to the object (metres): distance to the core minus radius.
  double Distance(const Segment2& link) const;
  /// The same distance as an expression over the link's end points (for guards). For a bar the
  /// expression is the minimum of the four end-point-to-segment distances, which equals the
  /// segment distance whenever the segments do not cross; the first contact of a moving link is
  /// always at such a configuration (the radius is positive).
  Expression DistanceExpression(const Expression& ax, const Expression& ay, const Expression& bx,
                                const Expression& by) const;
  /// The description Parse accepts.
  std::string ToString() const;
  friend bool operator==(const Obstacle&, const Obstacle&) = default;

 private:
  Obstacle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius);
  Eigen::Vector2d a_, b_;
  double radius_;
};

/// Distance from point p to segment [a, b].
double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b);
/// Distance between segments [a, b] and [c, d] (0 when they cross).
double SegmentDistance(const Segment2& s, const Segment2& t);

}  // namespace hybrid::gripper
