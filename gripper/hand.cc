#include "hybrid/gripper/hand.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "gripper/partition_index.h"

namespace hybrid::gripper {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace

std::string SpreadModeName(SpreadMode mode) {
  switch (mode) {
    case SpreadMode::kBasic:
      return "basic";
    case SpreadMode::kWide:
      return "wide";
    case SpreadMode::kPinch:
      return "pinch";
    case SpreadMode::kScissor:
      return "scissor";
  }
  return "?";
}

SpreadMode SpreadModeByName(const std::string& name) {
  for (SpreadMode m :
       {SpreadMode::kBasic, SpreadMode::kWide, SpreadMode::kPinch, SpreadMode::kScissor}) {
    if (SpreadModeName(m) == name) return m;
  }
  throw std::invalid_argument("unknown operating mode '" + name +
                              "' (expected basic, wide, pinch or scissor)");
}

double Hand::SpreadPosition(SpreadMode mode, const HandLayout& layout) {
  switch (mode) {
    case SpreadMode::kWide:
      return layout.s_wide;
    case SpreadMode::kPinch:
      return layout.s_pinch;
    default:
      return layout.s_basic;
  }
}

double SegmentDistance3(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                        const Eigen::Vector3d& r, const Eigen::Vector3d& s) {
  // Closest points p + u (q - p) and r + v (s - r), u, v in [0, 1]: minimise over u for the
  // unconstrained optimum, clamp, re-solve for v, clamp, re-solve for u.
  const Eigen::Vector3d d1 = q - p, d2 = s - r, w = p - r;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(w);
  constexpr double kTiny = 1e-30;
  double u = 0.0, v = 0.0;
  if (a <= kTiny && e <= kTiny) return w.norm();
  if (a <= kTiny) {
    v = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(w);
    if (e <= kTiny) {
      u = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denominator = a * e - b * b;
      u = denominator > kTiny ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      v = (b * u + f) / e;
      if (v < 0.0) {
        v = 0.0;
        u = std::clamp(-c / a, 0.0, 1.0);
      } else if (v > 1.0) {
        v = 1.0;
        u = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p + u * d1 - (r + v * d2)).norm();
}

namespace {

// Joints 1 to 3 and the fingertip of fingers A, B and C in space.
using HandLinks = std::array<std::array<Eigen::Vector3d, 4>, 3>;
// [f1][l1][f2][l2]: a distance between link l1 of finger f1 and link l2 of finger f2.
using ClosestLinks = std::array<std::array<std::array<std::array<double, 3>, 3>, 3>, 3>;

// Throws std::invalid_argument unless the spread position and the motor commands are in
// [0, 255].
void ValidateMotors(double spread, const std::array<double, 3>& commands) {
  if (!(spread >= 0.0 && spread <= 255.0)) {
    throw std::invalid_argument("the spread position must be in [0, 255]");
  }
  for (double c : commands) {
    if (!(c >= 0.0 && c <= 255.0)) {
      throw std::invalid_argument("the motor commands must be in [0, 255]");
    }
  }
}

// The three fingers of `hand` (its objects, placements and commands) with the finger-finger
// contacts `imposed`; an invalid finger's message names it ("finger B: ...").
std::vector<GeometricFinger> BuildFingers(const Hand& hand,
                                          const std::array<FingerContacts, 3>& imposed) {
  std::vector<GeometricFinger> fingers;
  for (int f = 0; f < 3; ++f) {
    try {
      fingers.emplace_back(hand.objects(), hand.FingerGeometryOf(f), FingerParameters{}, imposed[f],
                           hand.commands()[f]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("finger ") + "ABC"[f] + ": " + e.what());
    }
  }
  return fingers;
}

// Every finger's links in space at sweep position g.
HandLinks LinksAt(const Hand& hand, double g) {
  HandLinks p;
  for (int f = 0; f < 3; ++f) p[f] = hand.Points(f, hand.At(f, g).theta);
  return p;
}

// How far link l1 of finger f1 and link l2 of finger f2 are from touching (their centre lines'
// distance minus the link width; <= 0 touching).
double Separation(const HandLinks& p, int f1, int l1, int f2, int l2, double link_width) {
  return SegmentDistance3(p[f1][l1], p[f1][l1 + 1], p[f2][l2], p[f2][l2 + 1]) - link_width;
}

// Looks for the touch of link l1 of finger f1 and link l2 of finger f2 in the sweep step
// [lo, hi] (links `previous` at lo, `current` at hi) and keeps it in `first` if it is earlier:
// found by bisection to 1e-10 counts, or at lo if the links already touched there and move
// further in.
void FindPairTouch(const Hand& hand, const HandLinks& previous, const HandLinks& current, double lo,
                   double hi, int f1, int l1, int f2, int l2,
                   std::optional<Hand::FingerTouch>& first) {
  const double width = hand.layout().link_width;
  const double now = Separation(current, f1, l1, f2, l2, width);
  if (now > 0.0) return;
  const double before = Separation(previous, f1, l1, f2, l2, width);
  if (before <= 0.0) {
    // Touching already where the last touch stopped the sweep (e.g. A meets B and, by symmetry,
    // C at the same g): a touch if the links move further in.
    if (now < before && (!first || lo < first->g)) first = Hand::FingerTouch{f1, l1, f2, l2, lo};
    return;
  }
  while (hi - lo > 1e-10) {
    const double mid = 0.5 * (lo + hi);
    (Separation(LinksAt(hand, mid), f1, l1, f2, l2, width) <= 0.0 ? hi : lo) = mid;
  }
  if (!first || hi < first->g) first = Hand::FingerTouch{f1, l1, f2, l2, hi};
}

// Separations of every pair of links of different fingers at `p` (<= 0: touching), indexed
// [f1][l1][f2][l2] (both orders).
ClosestLinks Separations(const HandLinks& p, double link_width) {
  ClosestLinks out{};
  for (int f1 = 0; f1 < 3; ++f1) {
    for (int f2 = f1 + 1; f2 < 3; ++f2) {
      for (int l1 = 0; l1 < 3; ++l1) {
        for (int l2 = 0; l2 < 3; ++l2) {
          out[f1][l1][f2][l2] = out[f2][l2][f1][l1] = Separation(p, f1, l1, f2, l2, link_width);
        }
      }
    }
  }
  return out;
}

// Whether no two links of different fingers can touch anywhere in (a, b]: for each pair, the
// links cannot move that far (FingerGeometry::LinkMotionBounds of each finger's
// FingerClosedForm::VariationBound up to its command) from their separation at a, or neither
// moves.
bool ProvedApart(const Hand& hand, double a, double b, const ClosestLinks& separation) {
  std::array<std::array<double, 3>, 3> moved;
  for (int f = 0; f < 3; ++f) {
    const double command = hand.commands()[f];
    moved[f] = hand.finger(f).geometry().LinkMotionBounds(
        hand.finger(f).closed_form().VariationBound(std::min(a, command), std::min(b, command)));
  }
  for (int f1 = 0; f1 < 3; ++f1) {
    for (int f2 = f1 + 1; f2 < 3; ++f2) {
      for (int l1 = 0; l1 < 3; ++l1) {
        for (int l2 = 0; l2 < 3; ++l2) {
          const double m = moved[f1][l1] + moved[f2][l2];
          if (m != 0.0 && !(m < separation[f1][l1][f2][l2] * (1.0 - 1e-9))) return false;
        }
      }
    }
  }
  return true;
}

// The first touch between links of different fingers as the sweep goes on from g0, on the grid
// of every GeometricFinger::kResolution counts up to 255; nullopt if none. Grid points that
// ProvedApart from the last point evaluated are skipped, so the result is the full grid's.
std::optional<Hand::FingerTouch> FirstTouch(const Hand& hand, double g0) {
  const long count = static_cast<long>(std::ceil((255.0 - g0) / GeometricFinger::kResolution));
  const auto at = [&](long j) {
    return std::min(g0 + static_cast<double>(j) * GeometricFinger::kResolution, 255.0);
  };
  const double width = hand.layout().link_width;
  std::optional<Hand::FingerTouch> first;
  HandLinks previous = LinksAt(hand, g0);
  double g_eval = g0;
  ClosestLinks separation = Separations(previous, width);
  for (long k = 1; k <= count && !first; ++k) {
    const long next = PartitionIndex(
        k, count + 1, [&](long j) { return ProvedApart(hand, g_eval, at(j), separation); });
    if (next > count) break;
    if (next > k) previous = LinksAt(hand, at(next - 1));
    k = next;
    const HandLinks current = LinksAt(hand, at(k));
    separation = Separations(current, width);
    g_eval = at(k);
    for (int f1 = 0; f1 < 3; ++f1) {
      for (int f2 = f1 + 1; f2 < 3; ++f2) {
        for (int l1 = 0; l1 < 3; ++l1) {
          for (int l2 = 0; l2 < 3; ++l2) {
            if (separation[f1][l1][f2][l2] > 0.0) continue;
            FindPairTouch(hand, previous, current, at(k - 1), at(k), f1, l1, f2, l2, first);
          }
        }
      }
    }
    previous = current;
  }
  return first;
}

// Blocks both touching links at the touch, each only if its finger is still moving there and
// the link is not blocked already.
void BlockTouchingLinks(const Hand::FingerTouch& touch, const std::array<double, 3>& commands,
                        std::array<FingerContacts, 3>& imposed) {
  for (auto [f, l] :
       {std::pair{touch.finger_a, touch.link_a}, std::pair{touch.finger_b, touch.link_b}}) {
    if (touch.g < commands[f] && imposed[f].gob[l] == FingerContacts::kNone) {
      imposed[f].gob[l] = touch.g;
    }
  }
}

// The closest approach of every pair of links of different fingers over the closing, sampled
// every 0.25 counts.
ClosestLinks ClosestApproaches(const Hand& hand) {
  ClosestLinks closest;
  for (auto& a : closest) {
    for (auto& b : a) {
      for (auto& c : b) c.fill(std::numeric_limits<double>::infinity());
    }
  }
  for (double g = 0.0; g <= 255.0; g += 0.25) {
    const HandLinks p = LinksAt(hand, g);
    for (int f1 = 0; f1 < 3; ++f1) {
      for (int l1 = 0; l1 < 3; ++l1) {
        for (int f2 = 0; f2 < 3; ++f2) {
          for (int l2 = 0; l2 < 3; ++l2) {
            if (f1 == f2) continue;
            double& d = closest[f1][l1][f2][l2];
            d = std::min(d, SegmentDistance3(p[f1][l1], p[f1][l1 + 1], p[f2][l2], p[f2][l2 + 1]));
          }
        }
      }
    }
  }
  return closest;
}

}  // namespace

Hand::Hand(std::vector<Obstacle> objects, double spread, const std::array<double, 3>& commands,
           const HandLayout& layout)
    : objects_(std::move(objects)), layout_(layout), commands_(commands) {
  ValidateMotors(spread, commands);
  phi_ = layout.phi_min + (layout.phi_max - layout.phi_min) * spread / 255.0;
  std::array<FingerContacts, 3> imposed;
  fingers_ = BuildFingers(*this, imposed);
  // Sweep g for touches between fingers: each blocks both links, and the fingers are rebuilt.
  double g0 = 0.0;
  for (int round = 0; round < 18; ++round) {
    const std::optional<FingerTouch> first = FirstTouch(*this, g0);
    if (!first) break;
    touches_.push_back(*first);
    BlockTouchingLinks(*first, commands_, imposed);
    fingers_ = BuildFingers(*this, imposed);
    g0 = first->g;
  }
}

FingerConfiguration Hand::At(int f, double g) const {
  if (!(g >= 0.0 && g <= 255.0)) {
    throw std::out_of_range("g = " + std::to_string(g) + " is outside [0, 255]");
  }
  return fingers_.at(f).At(std::min(g, commands_[f]));
}

namespace {

using E = Expression;
using Point3 = std::array<E, 3>;

E Dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point3 Minus(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
E Clamp01(const E& v) {
  return E::Binary(Op::kMax, E::Constant(0.0), E::Binary(Op::kMin, E::Constant(1.0), v));
}

E Norm(const Point3& a) { return E::Unary(Op::kSqrt, Dot(a, a)); }

// Distance from point p to segment [a, b] in space.
E PointSegmentExpression(const Point3& p, const Point3& a, const Point3& b) {
  const Point3 d = Minus(b, a);
  const E t = Clamp01(Dot(Minus(p, a), d) / Dot(d, d));
  return Norm(Point3{p[0] - (a[0] + t * d[0]), p[1] - (a[1] + t * d[1]), p[2] - (a[2] + t * d[2])});
}

// SegmentDistance3 as an expression, without nesting one clamp inside another (the expression
// grows with the nesting): the distance is the smallest of the four end-point-to-segment
// distances (the minimum on the border of [0, 1]^2) and, when the lines' closest points (u*, v*)
// lie inside both segments, the distance between the lines |w . n| / |n|, n = d1 x d2. Outside,
// that candidate gets a penalty of 1 m (sign() of how far outside), so the minimum is exact;
// it is continuous because on the border the line distance equals the border's. For parallel
// segments the ends decide, which is exact for them.
E SegmentDistanceExpression(const Point3& p, const Point3& q, const Point3& r, const Point3& s) {
  const Point3 d1 = Minus(q, p), d2 = Minus(s, r), w = Minus(p, r);
  const E a = Dot(d1, d1), e = Dot(d2, d2), b = Dot(d1, d2), c = Dot(d1, w), f = Dot(d2, w);
  // (a e - b^2 = |n|^2, floored so that parallel links give finite u, v.)
  const E denominator = E::Binary(Op::kMax, a * e - b * b, E::Constant(1e-30));
  const E u = (b * f - c * e) / denominator;
  const E v = (a * f - b * c) / denominator;
  const Point3 n = {d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2],
                    d1[0] * d2[1] - d1[1] * d2[0]};
  const E length = Norm(n);
  const E line = E::Unary(Op::kAbs, Dot(w, n)) / E::Binary(Op::kMax, length, E::Constant(1e-9));
  const E zero = E::Constant(0.0), one = E::Constant(1.0);
  auto positive = [&](const E& x) { return E::Unary(Op::kSign, E::Binary(Op::kMax, zero, x)); };
  auto outside = [&](const E& x) { return positive(zero - x) + positive(x - one); };
  // Penalties of 1 m: (u*, v*) outside the segments, or the links (nearly) parallel
  // (|n| < 1e-9 m^2, an angle below about 1e-6 rad for these links), where the ends decide.
  const E interior = line + outside(u) + outside(v) + positive(E::Constant(1e-9) - length);
  E d = E::Binary(Op::kMin, PointSegmentExpression(p, r, s), PointSegmentExpression(q, r, s));
  d = E::Binary(Op::kMin, d, PointSegmentExpression(r, p, q));
  d = E::Binary(Op::kMin, d, PointSegmentExpression(s, p, q));
  return E::Binary(Op::kMin, d, interior);
}

}  // namespace

std::array<std::array<Expression, 3>, 4> Hand::PointExpressions(
    int f, const std::array<Expression, 3>& theta) const {
  const auto local = FingerGeometry().LocalPointExpressions(theta);
  const auto [origin, direction] = Frame(f);
  std::array<std::array<Expression, 3>, 4> out;
  for (int k = 0; k < 4; ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      // origin + x_local * direction + y_local * unit y
      E v = E::Constant(origin[axis]) + local[k][0] * E::Constant(direction[axis]);
      if (axis == 1) v = v + local[k][1];
      out[k][axis] = v.FoldConstants();
    }
  }
  return out;
}

System Hand::ComposedAutomata(const System& hand_model, bool shared_command) const {
  const Automaton* finger = nullptr;
  const Automaton* spread = nullptr;
  for (const Component& c : hand_model.components()) {
    if (c.source.name() == "finger") finger = &c.source;
    if (c.source.name() == "spread") spread = &c.source;
  }
  if (finger == nullptr) {
    throw std::invalid_argument("the model '" + hand_model.name() +
                                "' has no automaton named 'finger'");
  }
  const std::string names = "ABC";
  const ClosestLinks closest = ClosestApproaches(*this);
  System system("hand");
  if (shared_command) system.Share("u");
  for (int o = 0; o < 3; ++o) {
    for (int k = 1; k <= 3; ++k)
      system.Share(std::string(1, names[o]) + ".theta" + std::to_string(k));
  }
  for (int f = 0; f < 3; ++f) {
    Automaton a = fingers_[f].ContactAutomaton(*finger);
    // Each finger reads the other fingers' joint angles: variables named "B.theta1", ...,
    // shared, without flow here (their own instance gives it).
    std::array<std::array<Expression, 3>, 3> theta;
    for (int o = 0; o < 3; ++o) {
      for (int k = 0; k < 3; ++k) {
        const std::string local = "theta" + std::to_string(k + 1);
        if (o == f) {
          theta[o][k] = E::Symbol(local, *a.symbols().Find(local));
        } else {
          const std::string name = std::string(1, names[o]) + "." + local;
          const int slot = a.AddVariable(name, "deg");
          // Every finger starts open; the owner's initial state gives the same value.
          a.SetInitialValue(slot, InitialValue{slot, Range{E::Constant(0.0), E::Constant(0.0)}});
          theta[o][k] = E::Symbol(name, slot);
        }
      }
    }
    std::array<std::array<std::array<Expression, 3>, 4>, 3> points;
    for (int o = 0; o < 3; ++o) points[o] = PointExpressions(o, theta[o]);
    // Clearance of link i to the other fingers' links, in millimetres like the object guards.
    // Only pairs that come within kCandidateMargin of touching on the quasistatic closing are
    // included (the guards grow by thousands of nodes per pair): while the simulated path agrees
    // with the quasistatic one, the others stay that far apart and cannot touch.
    std::array<std::optional<E>, 3> clearance;
    for (int i = 0; i < 3; ++i) {
      std::optional<E> nearest;
      for (int o = 0; o < 3; ++o) {
        if (o == f) continue;
        for (int j = 0; j < 3; ++j) {
          if (closest[f][i][o][j] > layout_.link_width + kCandidateMargin) continue;
          const E d = SegmentDistanceExpression(points[f][i], points[f][i + 1], points[o][j],
                                                points[o][j + 1]);
          nearest = nearest ? E::Binary(Op::kMin, *nearest, d) : d;
        }
      }
      if (nearest) {
        clearance[i] = E::Constant(1000.0) * (*nearest - E::Constant(layout_.link_width));
      }
    }
    for (int t = 0; t < a.num_transitions(); ++t) {
      const Transition& tr = a.transitions()[t];
      if (tr.label.size() != 8 || tr.label.rfind("contact", 0) != 0) continue;
      const int i = tr.label[7] - '1';
      if (!clearance[i]) continue;
      Constraint guard = tr.guard;
      guard.comparisons[0].lhs = E::Binary(Op::kMin, guard.comparisons[0].lhs, *clearance[i]);
      a.SetGuard(TransitionId(t), std::move(guard));
    }
    system.AddComponent(std::string(1, names[f]), a);
  }
  if (spread != nullptr) system.AddComponent("S", *spread);
  return system;
}

FingerGeometry Hand::FingerGeometryOf(int f) const {
  // The projection of the finger's frame onto the x-y plane.
  const auto [origin, direction] = Frame(f);
  return FingerGeometry({}, FingerPlacement{origin.x(), direction.x()});
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> Hand::Frame(int f) const {
  const double c = std::cos(phi_ * kDeg), s = std::sin(phi_ * kDeg);
  switch (f) {
    case 0:
      return {{-layout_.half_span, 0, 0}, {1, 0, 0}};
    case 1:  // B, on the +z side, turned towards z = 0 for phi > 0
      return {{layout_.half_span, 0, layout_.lateral}, {-c, 0, -s}};
    default:  // C, on the -z side
      return {{layout_.half_span, 0, -layout_.lateral}, {-c, 0, s}};
  }
}

std::array<Eigen::Vector3d, 4> Hand::Points(int f, const Eigen::Vector3d& theta) const {
  const auto local = FingerGeometry().Points(theta);
  const auto [origin, direction] = Frame(f);
  std::array<Eigen::Vector3d, 4> out;
  for (int k = 0; k < 4; ++k) {
    out[k] = origin + local[k].x() * direction + local[k].y() * Eigen::Vector3d::UnitY();
  }
  return out;
}

}  // namespace hybrid::gripper
