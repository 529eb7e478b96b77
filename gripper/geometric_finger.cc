#include "hybrid/gripper/geometric_finger.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "gripper/partition_index.h"

namespace hybrid::gripper {

namespace {

constexpr int kPalm = GeometricFinger::kPalm;

// Throws std::invalid_argument if an object reaches below the palm's surface or overlaps a link
// of the open finger (knuckles included).
void RequireClearOfOpenFinger(const std::vector<Obstacle>& objects,
                              const FingerGeometry& geometry) {
  const auto open_links = geometry.Links(Eigen::Vector3d::Zero());
  for (const Obstacle& o : objects) {
    const double lowest = std::min(o.a().y(), o.b().y()) - o.radius();
    if (lowest < geometry.palm_y()) {
      throw std::invalid_argument(
          "object " + o.ToString() +
          " overlaps the palm (its lowest point y = " + FormatNumber(lowest) +
          " is below the palm surface y = " + FormatNumber(geometry.palm_y()) + ")");
    }
    for (int i = 0; i < 3; ++i) {
      if (o.Distance(open_links[i]) <= 0.0) {
        throw std::invalid_argument("object " + o.ToString() + " overlaps link " +
                                    std::to_string(i + 1) + " of the open finger (g = 0)");
      }
    }
  }
}

// The search grid of one piece of a closed form's path clipped to [lo, hi]: lo, the interior
// points, hi. Outside phase 3 the interior points are every kResolution counts from lo; in phase 3,
// where theta3's rate grows without bound towards g = 255, they are every kResolution * m1 degrees
// of theta3 (uniform in phase 3's fraction F, g = (g0 + 255 phi) / (1 + phi) with phi = F /
// m3_scale), so no joint turns more than 0.045 degrees between two points.
class PieceGrid {
 public:
  PieceGrid(const FingerClosedForm::Piece& piece, const FingerParameters& parameters, double lo,
            double hi)
      : piece_(piece), parameters_(parameters), lo_(lo), hi_(hi) {
    constexpr double kResolution = GeometricFinger::kResolution;
    phase3_ = piece.phase == FingerPhase::k3 && piece.span3 > 0.0;
    if (!phase3_) {
      count_ = static_cast<long>(std::ceil((hi - lo) / kResolution)) - 1;
    } else {
      step_ = kResolution * parameters.m1() / piece.span3;
      const double f_lo = Fraction(lo), f_hi = std::min(Fraction(hi), 1.0);
      first_ = static_cast<long>(std::floor(f_lo / step_)) + 1;
      count_ = static_cast<long>(std::ceil(f_hi / step_)) - first_;
    }
    count_ = std::max(count_, 0L);
  }
  /// Number of points (at least 2: lo and hi).
  long size() const { return count_ + 2; }
  double operator[](long k) const {
    if (k <= 0) return lo_;
    if (k > count_) return hi_;
    if (!phase3_) return std::min(lo_ + static_cast<double>(k) * GeometricFinger::kResolution, hi_);
    const double phi = static_cast<double>(first_ + k - 1) * step_ / parameters_.m3_scale();
    return std::clamp((piece_.g0 + parameters_.motor_max * phi) / (1.0 + phi), lo_, hi_);
  }

 private:
  double Fraction(double g) const {
    return parameters_.m3_scale() * (g - piece_.g0) /
           std::max(parameters_.motor_max - g, std::numeric_limits<double>::min());
  }
  const FingerClosedForm::Piece& piece_;
  const FingerParameters& parameters_;
  double lo_, hi_;
  bool phase3_ = false;
  double step_ = 0.0;
  long first_ = 0, count_ = 0;
};

// The obstacles a link can touch: the objects (0, 1, ...) and the palm (kPalm).
struct Obstacles {
  // Signed distance of link i to obstacle k at motor position g of `cf`.
  double Distance(const FingerClosedForm& cf, double g, int i, int k) const {
    const auto links = geometry.ContactSegments(cf.At(g).theta);
    return (k == kPalm ? palm : objects[k]).Distance(links[i]);
  }
  const FingerGeometry& geometry;
  const std::vector<Obstacle>& objects;
  Obstacle palm;
};

// A contact: where, of which link, with which obstacle (an object, kPalm or kImposed).
struct Hit {
  double g;
  int link;
  int obstacle;
};

// Looks for link i touching obstacle k in the sample step [lo, hi] of `cf` and keeps the touch
// in `first` if it is earlier: found by bisection to 1e-10 counts, or at lo if the link already
// touches there and moves further in.
void FindTouch(const FingerClosedForm& cf, const Obstacles& obstacles, double lo, double hi, int i,
               int k, std::optional<Hit>& first) {
  const double d_hi = obstacles.Distance(cf, hi, i, k);
  if (d_hi > 0.0) return;
  const double d_lo = obstacles.Distance(cf, lo, i, k);
  if (d_lo <= 0.0) {
    // Touching already where the previous contact stopped the finger (e.g. at the joint shared
    // with the blocked link): a contact if the link moves further in.
    if (d_hi < d_lo && (!first || lo < first->g)) first = Hit{lo, i, k};
    return;
  }
  while (hi - lo > 1e-10) {
    const double mid = 0.5 * (lo + hi);
    (obstacles.Distance(cf, mid, i, k) <= 0.0 ? hi : lo) = mid;
  }
  if (!first || hi < first->g) first = Hit{hi, i, k};
}

// Per link not blocked yet (in `contacts`), its smallest signed distance to an obstacle at g;
// +inf for a blocked link.
std::array<double, 3> Slack(const FingerClosedForm& cf, const Obstacles& obstacles, double g,
                            const FingerContacts& contacts) {
  const auto links = obstacles.geometry.ContactSegments(cf.At(g).theta);
  std::array<double, 3> slack;
  slack.fill(std::numeric_limits<double>::infinity());
  for (int i = 0; i < 3; ++i) {
    if (contacts.gob[i] != FingerContacts::kNone) continue;
    slack[i] = obstacles.palm.Distance(links[i]);
    for (const Obstacle& o : obstacles.objects) slack[i] = std::min(slack[i], o.Distance(links[i]));
  }
  return slack;
}

// Whether no link can touch an obstacle anywhere in (g_eval, g]: each link either cannot move
// that far (FingerGeometry::LinkMotionBounds of FingerClosedForm::VariationBound) from its slack
// at g_eval, or does not move at all.
bool ProvedClear(const FingerClosedForm& cf, const FingerGeometry& geometry, double g_eval,
                 double g, const std::array<double, 3>& slack) {
  const std::array<double, 3> moved = geometry.LinkMotionBounds(cf.VariationBound(g_eval, g));
  for (int i = 0; i < 3; ++i) {
    if (moved[i] != 0.0 && !(moved[i] < slack[i] * (1.0 - 1e-9))) return false;
  }
  return true;
}

// The first contact of a link not blocked yet (in `contacts`) with an obstacle as g goes from g0
// to end along the search grid (PieceGrid). The grid's points that the step bound proves clear
// (ProvedClear from the last point evaluated) are skipped, so the result is the full grid's: the
// same first step with a touch, bisected by FindTouch.
std::optional<Hit> FirstGeometricContact(const FingerClosedForm& cf, const Obstacles& obstacles,
                                         double g0, double end, const FingerContacts& contacts) {
  const int num_objects = static_cast<int>(obstacles.objects.size());
  double g_eval = g0;
  std::array<double, 3> slack = Slack(cf, obstacles, g0, contacts);
  std::optional<Hit> first;
  for (const auto& piece : cf.pieces()) {
    const double lo = std::max(piece.g0, g0), hi = std::min(piece.g1, end);
    if (!(hi > lo)) continue;
    const PieceGrid grid(piece, cf.parameters(), lo, hi);
    for (long k = 1; k < grid.size(); ++k) {
      // The first grid point from k on not proved clear (the bound grows with the point).
      k = PartitionIndex(k, grid.size(), [&](long j) {
        return ProvedClear(cf, obstacles.geometry, g_eval, grid[j], slack);
      });
      if (k >= grid.size()) break;
      const std::array<double, 3> at_k = Slack(cf, obstacles, grid[k], contacts);
      if (*std::min_element(at_k.begin(), at_k.end()) <= 0.0) {
        for (int i = 0; i < 3; ++i) {
          if (contacts.gob[i] != FingerContacts::kNone) continue;
          for (int o = kPalm; o < num_objects; ++o) {
            FindTouch(cf, obstacles, grid[k - 1], grid[k], i, o, first);
          }
        }
        if (first) return first;
      }
      g_eval = grid[k];
      slack = at_k;
    }
  }
  return first;
}

// Replaces `first` by an imposed contact in [g, end] of a link not blocked yet that comes
// earlier.
void TakeEarlierImposedContact(const FingerContacts& imposed, const FingerContacts& contacts,
                               double g, double end, std::optional<Hit>& first) {
  for (int i = 0; i < 3; ++i) {
    const double at = imposed.gob[i];
    if (contacts.gob[i] == FingerContacts::kNone && at >= g && at <= end &&
        (!first || at < first->g)) {
      first = Hit{at, i, GeometricFinger::kImposed};
    }
  }
}

}  // namespace

GeometricFinger::GeometricFinger(std::vector<Obstacle> objects, const FingerGeometry& geometry,
                                 const FingerParameters& parameters, const FingerContacts& imposed,
                                 double up_to)
    : objects_(std::move(objects)),
      geometry_(geometry),
      parameters_(parameters),
      closed_form_(FingerContacts{}, parameters) {
  RequireClearOfOpenFinger(objects_, geometry_);
  const Obstacles obstacles{geometry_, objects_, palm()};
  // Contact by contact: the closed form with the contacts so far, searched from the last one.
  FingerContacts contacts;
  double g = 0.0;
  for (int round = 0; round < 3; ++round) {
    const FingerClosedForm cf(contacts, parameters_);
    const double end = std::min({cf.stop(), parameters_.motor_max, up_to});
    std::optional<Hit> first = FirstGeometricContact(cf, obstacles, g, end, contacts);
    TakeEarlierImposedContact(imposed, contacts, g, end, first);
    if (!first) break;
    // The palm touches the fingertip at the free-space stop by construction (G1): not a contact.
    if (first->obstacle == kPalm && first->g >= cf.stop() - 1e-7) break;
    contacts.gob[first->link] = first->g;
    blocked_by_[first->link] = first->obstacle;
    g = first->g;
  }
  closed_form_ = FingerClosedForm(contacts, parameters_);
}

bool GeometricFinger::touches_object() const {
  return std::any_of(blocked_by_.begin(), blocked_by_.end(),
                     [](const std::optional<int>& k) { return k && *k != kPalm; });
}

Obstacle GeometricFinger::palm() const {
  constexpr double kThickness = 0.05;
  const double y = geometry_.palm_y() - kThickness;
  return Obstacle::Bar({-0.15, y}, {0.15, y}, kThickness);
}

Automaton GeometricFinger::ContactAutomaton(const Automaton& finger) const {
  std::vector<Obstacle> all = objects_;
  all.push_back(palm());
  return WithGeometricContacts(finger, all, geometry_);
}

double GeometricFinger::Clearance(const Eigen::Vector3d& theta, int link) const {
  const Segment2 s = geometry_.ContactSegments(theta)[link];
  double d = palm().Distance(s);
  for (const Obstacle& o : objects_) d = std::min(d, o.Distance(s));
  return d;
}

Automaton WithGeometricContacts(const Automaton& finger, const std::vector<Obstacle>& obstacles,
                                const FingerGeometry& geometry) {
  if (obstacles.empty()) throw std::invalid_argument("contacts with objects need an object");
  std::array<Expression, 3> theta;
  for (int i = 0; i < 3; ++i) {
    const std::string name = "theta" + std::to_string(i + 1);
    const auto slot = finger.symbols().Find(name);
    if (!slot) throw std::invalid_argument("the finger model has no variable " + name);
    theta[i] = Expression::Symbol(name, *slot);
  }
  using E = Expression;
  const E to_rad = E::Constant(std::numbers::pi / 180.0);
  const E phi2 = (theta[0] + theta[1]) * to_rad;
  const E phi3 = (theta[0] + theta[1] + theta[2]) * to_rad;
  const auto points = geometry.LocalPointExpressions(theta);
  std::array<E, 4> x, y;
  for (int k = 0; k < 4; ++k) x[k] = points[k][0], y[k] = points[k][1];
  // Contact segments (FingerGeometry::ContactSegments): links 2 and 3 start kJointMargin after
  // their joint.
  const E margin = E::Constant(FingerGeometry::kJointMargin);
  std::array<E, 3> sx = {x[0], x[1] + margin * E::Unary(Op::kSin, phi2),
                         x[2] + margin * E::Unary(Op::kSin, phi3)};
  // Placement: x' = origin_x + x_scale * x.
  const E origin = E::Constant(geometry.placement().origin_x);
  const E scale = E::Constant(geometry.placement().x_scale);
  for (auto& v : sx) v = (origin + scale * v).FoldConstants();
  for (auto& v : x) v = (origin + scale * v).FoldConstants();
  const std::array<E, 3> sy = {y[0], y[1] + margin * E::Unary(Op::kCos, phi2),
                               y[2] + margin * E::Unary(Op::kCos, phi3)};
  std::array<E, 3> distance;
  for (int i = 0; i < 3; ++i) {
    distance[i] = obstacles[0].DistanceExpression(sx[i], sy[i], x[i + 1], y[i + 1]);
    for (size_t k = 1; k < obstacles.size(); ++k) {
      distance[i] = E::Binary(Op::kMin, distance[i],
                              obstacles[k].DistanceExpression(sx[i], sy[i], x[i + 1], y[i + 1]));
    }
  }
  Automaton out = finger;
  for (int t = 0; t < out.num_transitions(); ++t) {
    const Transition& tr = out.transitions()[t];
    if (tr.label.size() != 8 || tr.label.rfind("contact", 0) != 0) continue;
    const int i = tr.label[7] - '1';
    if (i < 0 || i > 2 || tr.guard.comparisons.empty() ||
        tr.guard.comparisons[0].lhs.ToString() != "g" ||
        tr.guard.comparisons[0].rhs.ToString() != "gob" + std::to_string(i + 1)) {
      throw std::invalid_argument("transition '" + tr.name +
                                  "' is not a contact transition of spec/finger.ha");
    }
    Constraint guard = tr.guard;
    // In millimetres: the simulator's boundary tolerance (1e-9) then means 1e-12 m, so contact
    // is located to about 1e-8 degrees instead of 1e-5.
    guard.comparisons[0] = Comparison{(E::Constant(1000.0) * distance[i]).FoldConstants(),
                                      Relation::kLessEqual, E::Constant(0.0)};
    out.SetGuard(TransitionId(t), std::move(guard));
  }
  return out;
}

}  // namespace hybrid::gripper
