#include "hybrid/gripper/obstacle.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "automaton/number_syntax.h"
#include "hybrid/automaton/expression.h"

namespace hybrid::gripper {
namespace {

bool Finite(const Eigen::Vector2d& v) { return v.allFinite(); }

struct Number {
  double value;
  int column;  // 1-based column of its first character
};

}  // namespace

Obstacle::Obstacle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius)
    : a_(a), b_(b), radius_(radius) {}

Obstacle Obstacle::Circle(const Eigen::Vector2d& centre, double radius) {
  if (!Finite(centre) || !(radius >= kMinimumRadius) || !std::isfinite(radius)) {
    throw std::invalid_argument("a circle needs a finite centre and a radius of at least 0.0001 m");
  }
  return Obstacle(centre, centre, radius);
}

Obstacle Obstacle::Bar(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius) {
  if (!Finite(a) || !Finite(b) || !(radius >= kMinimumRadius) || !std::isfinite(radius)) {
    throw std::invalid_argument("a segment needs finite ends and a radius of at least 0.0001 m");
  }
  return Obstacle(a, b, radius);
}

Obstacle Obstacle::Parse(std::string_view text) {
  const size_t colon = text.find(':');
  const std::string_view kind = text.substr(0, colon);
  if (colon == std::string_view::npos || (kind != "circle" && kind != "segment")) {
    throw ObstacleParseError(1, "expected 'circle:X,Y,R' or 'segment:X1,Y1,X2,Y2[,R]'");
  }
  std::vector<Number> numbers;
  size_t at = colon + 1;
  while (true) {
    const char* field = text.data() + at;
    const char* end = text.data() + text.size();
    const char* stop = std::find(field, end, ',');
    // The number itself, without surrounding spaces, in the decimal syntax of
    // automaton/number_syntax.h.
    const char* begin = field;
    while (begin < stop && *begin == ' ') ++begin;
    const char* last = stop;
    while (last > begin && last[-1] == ' ') --last;
    const int column = static_cast<int>(begin - text.data()) + 1;
    const std::string_view number(begin, static_cast<size_t>(last - begin));
    const NumberRead<double> read = ReadDecimal(number);
    if (read.error == NumberError::kEmpty) throw ObstacleParseError(column, "expected a number");
    if (read.error == NumberError::kSyntax) {
      throw ObstacleParseError(column + static_cast<int>(read.stop),
                               "malformed number '" + std::string(number) + "'");
    }
    if (read.error == NumberError::kOverflow) {
      throw ObstacleParseError(
          column, "number '" + std::string(number) + "' is out of the range of a double");
    }
    if (!read.ok()) throw ObstacleParseError(column, NumberErrorMessage(number, read.error));
    const double value = read.value;
    numbers.push_back({value, column});
    if (stop == end) break;
    at = static_cast<size_t>(stop - text.data()) + 1;
  }
  const int end_column = static_cast<int>(text.size()) + 1;
  auto radius_of = [&](const Number& r) {
    if (!(r.value > 0.0)) throw ObstacleParseError(r.column, "radius must be > 0");
    if (r.value < kMinimumRadius) {
      throw ObstacleParseError(r.column,
                               "radius must be at least 0.0001 m (0.1 mm: thinner objects could "
                               "be crossed between two samples of the contact search)");
    }
    return r.value;
  };
  if (kind == "circle") {
    if (numbers.size() != 3) {
      throw ObstacleParseError(
          numbers.size() > 3 ? numbers[3].column : end_column,
          "a circle takes 3 numbers X,Y,R (got " + std::to_string(numbers.size()) + ")");
    }
    return Circle({numbers[0].value, numbers[1].value}, radius_of(numbers[2]));
  }
  if (numbers.size() != 4 && numbers.size() != 5) {
    throw ObstacleParseError(numbers.size() > 5 ? numbers[5].column : end_column,
                             "a segment takes 4 or 5 numbers X1,Y1,X2,Y2[,R] (got " +
                                 std::to_string(numbers.size()) + ")");
  }
  const double r = numbers.size() == 5 ? radius_of(numbers[4]) : kDefaultBarRadius;
  return Bar({numbers[0].value, numbers[1].value}, {numbers[2].value, numbers[3].value}, r);
}

std::string Obstacle::ToString() const {
  auto n = [](double v) { return FormatNumber(v); };
  if (is_circle()) return "circle:" + n(a_.x()) + "," + n(a_.y()) + "," + n(radius_);
  return "segment:" + n(a_.x()) + "," + n(a_.y()) + "," + n(b_.x()) + "," + n(b_.y()) + "," +
         n(radius_);
}

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double length2 = d.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

double SegmentDistance(const Segment2& s, const Segment2& t) {
  // Proper crossing: the ends of each segment lie strictly on both sides of the other.
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(s.b - s.a, t.a - s.a), d2 = cross(s.b - s.a, t.b - s.a);
  const double d3 = cross(t.b - t.a, s.a - t.a), d4 = cross(t.b - t.a, s.b - t.a);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    return 0.0;
  }
  return std::min({PointSegmentDistance(s.a, t.a, t.b), PointSegmentDistance(s.b, t.a, t.b),
                   PointSegmentDistance(t.a, s.a, s.b), PointSegmentDistance(t.b, s.a, s.b)});
}

double Obstacle::Distance(const Segment2& link) const {
  if (is_circle()) return PointSegmentDistance(a_, link.a, link.b) - radius_;
  return SegmentDistance(link, Segment2{a_, b_}) - radius_;
}

namespace {

using E = Expression;

// |p - [a, b]| as an expression; the clamp of the projection parameter uses min and max.
E PointSegmentExpression(const E& px, const E& py, const E& ax, const E& ay, const E& bx,
                         const E& by) {
  const E dx = bx - ax, dy = by - ay;
  const E t = E::Binary(Op::kMax, E::Constant(0.0),
                        E::Binary(Op::kMin, E::Constant(1.0),
                                  ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)));
  const E qx = px - (ax + t * dx), qy = py - (ay + t * dy);
  return E::Unary(Op::kSqrt, qx * qx + qy * qy);
}

}  // namespace

Expression Obstacle::DistanceExpression(const Expression& ax, const Expression& ay,
                                        const Expression& bx, const Expression& by) const {
  const E cx = E::Constant(a_.x()), cy = E::Constant(a_.y());
  const E r = E::Constant(radius_);
  if (is_circle()) return PointSegmentExpression(cx, cy, ax, ay, bx, by) - r;
  const E dx = E::Constant(b_.x()), dy = E::Constant(b_.y());
  E d = E::Binary(Op::kMin, PointSegmentExpression(cx, cy, ax, ay, bx, by),
                  PointSegmentExpression(dx, dy, ax, ay, bx, by));
  d = E::Binary(Op::kMin, d, PointSegmentExpression(ax, ay, cx, cy, dx, dy));
  d = E::Binary(Op::kMin, d, PointSegmentExpression(bx, by, cx, cy, dx, dy));
  return d - r;
}

}  // namespace hybrid::gripper
