#include "hybrid/gripper/finger_closed_form.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hybrid::gripper {
namespace {

bool IsPalm(const std::array<int, 3>& c, const std::array<int, 3>& l) {
  return l[0] == 1 && l[1] == 1 && l[2] == -1 && c[0] == 0 && c[1] == 0 && c[2] == 0;
}

// The phase of a discrete state, as tools/generate_finger.py assigns it.
FingerPhase PhaseOf(const std::array<int, 3>& c, const std::array<int, 3>& l) {
  if (c[2] == 1 || l[2] == 1 || IsPalm(c, l)) return FingerPhase::k4;
  if (c[1] == 1 || l[1] == 1) return FingerPhase::k3;
  if (c[0] == 1 || l[0] == 1) return l[2] == -1 ? FingerPhase::k2Prime : FingerPhase::k2;
  return l[2] == -1 ? FingerPhase::k1Prime : FingerPhase::k1;
}

// Links whose position in space changes in a phase (only these can newly touch an object).
bool Moves(FingerPhase phase, int link) {
  switch (phase) {
    case FingerPhase::k1:
    case FingerPhase::k1Prime:
      return true;
    case FingerPhase::k2:
    case FingerPhase::k2Prime:
      return link >= 1;
    case FingerPhase::k3:
      return link == 2;
    case FingerPhase::k4:
      return false;
  }
  return false;
}

// Throws std::invalid_argument unless the contacts and parameters are consistent (the
// constructor's contract).
void Validate(const FingerContacts& contacts, const FingerParameters& p) {
  for (int i = 0; i < 3; ++i) {
    if (std::isnan(contacts.gob[i]) || contacts.gob[i] < 0.0) {
      throw std::invalid_argument("contact position of link " + std::to_string(i + 1) +
                                  " must be >= 0 (got " + std::to_string(contacts.gob[i]) + ")");
    }
    if (!(p.theta_min[i] < p.theta_max[i]) || !std::isfinite(p.theta_min[i]) ||
        !std::isfinite(p.theta_max[i])) {
      throw std::invalid_argument("empty range for joint " + std::to_string(i + 1));
    }
  }
  if (p.theta_min[0] != 0.0 || p.theta_min[1] != 0.0 || p.theta_min[2] > 0.0 ||
      p.theta_max[2] < 0.0 || !(p.m1() > 0.0) || !(p.m2() > 0.0) || !(p.motor_max > 0.0) ||
      !std::isfinite(p.motor_max) || !(p.theta3_fraction > 0.0 && p.theta3_fraction < 1.0)) {
    throw std::invalid_argument(
        "the finger's parameters must have theta1_min = theta2_min = 0 <= theta1_max, "
        "theta2_max, theta3_min <= 0 <= theta3_max, a positive finite motor range and "
        "theta3_fraction in (0, 1)");
  }
}

// The contact positions the finger can reach: those beyond the motor range become kNone.
std::array<double, 3> ReachableContacts(const FingerContacts& contacts, const FingerParameters& p) {
  std::array<double, 3> gob;
  for (int i = 0; i < 3; ++i) {
    gob[i] = contacts.gob[i] > p.motor_max ? FingerContacts::kNone : contacts.gob[i];
  }
  return gob;
}

// The linear rate (degrees per count) of (theta1, theta2, theta3) in `phase`; zero in phase 3
// (theta3 follows the rational law; no linear rate) and phase 4 (stopped).
Eigen::Vector3d RateOf(FingerPhase phase, const FingerParameters& p) {
  switch (phase) {
    case FingerPhase::k1:
      return {p.m1(), 0.0, -p.m1()};
    case FingerPhase::k1Prime:
      return {p.m1(), 0.0, 0.0};
    case FingerPhase::k2:
      return {0.0, p.m2(), -p.m2()};
    case FingerPhase::k2Prime:
      return {0.0, p.m2(), 0.0};
    default:
      return Eigen::Vector3d::Zero();
  }
}

// The piece that starts at motor position g in configuration theta with flags c and l (its end
// g1 and span3 still to be set).
FingerClosedForm::Piece StartPiece(double g, const Eigen::Vector3d& theta,
                                   const std::array<int, 3>& c, const std::array<int, 3>& l,
                                   const FingerParameters& p) {
  FingerClosedForm::Piece piece;
  piece.g0 = g;
  piece.theta0 = theta;
  piece.c = c;
  piece.l = l;
  piece.phase = PhaseOf(c, l);
  piece.rate = RateOf(piece.phase, p);
  return piece;
}

// What can end a piece: a link touching an object, a joint reaching its upper limit, theta3
// reaching its lower limit, the end of the motor range.
enum class EventKind { kContact, kLimit, kLower, kEndOfTravel };
struct Event {
  double at;
  EventKind kind;
  int link;
};

// The candidate events of `piece` (of a finger that is not stopped) in the simulator's priority
// order: for each link, contact then limit; then theta3 reaching its lower limit (phases 1 and
// 2); the end of travel last.
std::vector<Event> CandidateEvents(const FingerClosedForm::Piece& piece,
                                   const std::array<double, 3>& gob, const FingerParameters& p) {
  const double g = piece.g0;
  const Eigen::Vector3d& theta = piece.theta0;
  const std::array<int, 3>&c = piece.c, &l = piece.l;
  std::vector<Event> events;
  for (int i = 0; i < 3; ++i) {
    if (c[i] == 0 && l[i] != 1 && Moves(piece.phase, i) && gob[i] != FingerContacts::kNone) {
      events.push_back({std::max(gob[i], g), EventKind::kContact, i});
    }
    if (c[i] != 0 || l[i] != 0) continue;
    if (piece.phase == FingerPhase::k3 && i == 2) {
      // theta3 reaches its upper limit the fraction f of the way from g to motor_max.
      if (theta[2] >= p.theta_max[2]) {
        events.push_back({g, EventKind::kLimit, 2});
      } else if (g < p.motor_max) {
        events.push_back({g + p.theta3_fraction * (p.motor_max - g), EventKind::kLimit, 2});
      }
    } else if (piece.rate[i] > 0.0) {
      events.push_back(
          {g + std::max(0.0, p.theta_max[i] - theta[i]) / piece.rate[i], EventKind::kLimit, i});
    }
  }
  if ((piece.phase == FingerPhase::k1 || piece.phase == FingerPhase::k2) && l[2] == 0) {
    events.push_back(
        {g + std::max(0.0, theta[2] - p.theta_min[2]) / -piece.rate[2], EventKind::kLower, 2});
  }
  events.push_back({p.motor_max, EventKind::kEndOfTravel, -1});
  return events;
}

// The first event (in priority order) that happens by `end`, the earliest event's position.
const Event& FirstEvent(const std::vector<Event>& events, double end) {
  for (const Event& e : events) {
    if (e.at <= end) return e;
  }
  throw std::logic_error("finger closed form: no event at the end of a piece");
}

// Takes `event` (not the end of travel): sets the flag it changes and puts a joint reaching a
// limit exactly there.
void Apply(const Event& event, const FingerParameters& p, std::array<int, 3>& c,
           std::array<int, 3>& l, Eigen::Vector3d& theta) {
  switch (event.kind) {
    case EventKind::kContact:
      c[event.link] = 1;
      break;
    case EventKind::kLimit:
      l[event.link] = 1;
      theta[event.link] = p.theta_max[event.link];
      break;
    case EventKind::kLower:
      l[2] = -1;
      theta[2] = p.theta_min[2];
      break;
    case EventKind::kEndOfTravel:
      break;
  }
  // Blocking link 2 leaves phases 1' and 2' for phase 3 (l3 = 0), except against the palm.
  if ((c[1] == 1 || l[1] == 1) && l[2] == -1 && c[2] == 0 && !IsPalm(c, l)) l[2] = 0;
}

}  // namespace

std::string PhaseName(FingerPhase phase) {
  switch (phase) {
    case FingerPhase::k1:
      return "1";
    case FingerPhase::k1Prime:
      return "1'";
    case FingerPhase::k2:
      return "2";
    case FingerPhase::k2Prime:
      return "2'";
    case FingerPhase::k3:
      return "3";
    case FingerPhase::k4:
      return "4";
  }
  return "?";
}

FingerPhase PhaseOfState(const std::array<int, 3>& c, const std::array<int, 3>& l) {
  const bool palm = l[0] == 1 && l[1] == 1 && l[2] == -1 && c == std::array<int, 3>{0, 0, 0};
  if (c[2] == 1 || l[2] == 1 || palm) return FingerPhase::k4;
  if (c[1] == 1 || l[1] == 1) return FingerPhase::k3;
  if (c[0] == 1 || l[0] == 1) return l[2] == -1 ? FingerPhase::k2Prime : FingerPhase::k2;
  return l[2] == -1 ? FingerPhase::k1Prime : FingerPhase::k1;
}

std::string FingerModeName(const FingerConfiguration& q) {
  std::string name = "c";
  auto digit = [&](int v) { name.push_back(v == -1 ? 'n' : static_cast<char>('0' + v)); };
  for (int v : q.c) digit(v);
  name += "_l";
  for (int v : q.l) digit(v);
  return name;
}

FingerClosedForm::FingerClosedForm(const FingerContacts& contacts,
                                   const FingerParameters& parameters)
    : parameters_(parameters), contacts_(contacts) {
  const FingerParameters& p = parameters_;
  Validate(contacts, p);
  const std::array<double, 3> gob = ReachableContacts(contacts, p);
  // Piece by piece from the open finger: each piece ends at its first event, which sets a flag.
  double g = 0.0;
  Eigen::Vector3d theta = Eigen::Vector3d::Zero();
  std::array<int, 3> c = {0, 0, 0}, l = {0, 0, 0};
  // At most one flag changes per event and flags only get set while closing, so a handful of
  // iterations suffices; the bound guards against a logic error.
  for (int iteration = 0; iteration < 32; ++iteration) {
    Piece piece = StartPiece(g, theta, c, l, p);
    if (piece.phase == FingerPhase::k4) {
      stop_ = g;
      piece.g1 = p.motor_max;
      pieces_.push_back(piece);
      PackEnds();
      return;
    }
    const std::vector<Event> events = CandidateEvents(piece, gob, p);
    double end = p.motor_max;
    for (const Event& e : events) end = std::min(end, e.at);
    piece.g1 = end;
    if (piece.phase == FingerPhase::k3) piece.span3 = p.theta_max[2] - theta[2];
    if (end > g || pieces_.empty()) pieces_.push_back(piece);
    theta = Evaluate(piece, end);
    g = end;
    const Event& first = FirstEvent(events, end);
    if (first.kind == EventKind::kEndOfTravel) {
      PackEnds();
      return;  // still moving at the end of the motor range
    }
    Apply(first, p, c, l, theta);
  }
  throw std::logic_error("finger closed form: too many events");
}

void FingerClosedForm::PackEnds() {
  if (pieces_.size() > ends_.size()) {
    throw std::logic_error("finger closed form: too many pieces");
  }
  ends_.fill(std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < pieces_.size(); ++k) ends_[k] = pieces_[k].g1;
}

namespace {

// std::max and std::min on values, the same expressions: on references (std::) GCC keeps a
// branch, which random g mispredicts; on values it emits maxsd/minsd.
inline double Max(double a, double b) { return a < b ? b : a; }
inline double Min(double a, double b) { return b < a ? b : a; }

// The index of g's piece: the number of piece ends below g (`ends` is sorted; unused entries
// are +inf and the last piece ends at motor_max >= g), counted without branches.
inline size_t PieceIndex(const std::array<double, 8>& ends, double g) {
  size_t k = 0;
#pragma GCC unroll 8
  for (size_t j = 0; j < ends.size(); ++j) k += g > ends[j] ? 1 : 0;
  return k;
}

// The fraction of phase 3's way done, (1 - f) / f (g - g_s) / (255 - g) clamped to [0, 1], from
// moved = g - g_s >= 0 and rest = 255 - g >= 0, without branches (At is called with random g).
// rest is 0 only at g = 255, where the fraction is 1 once anything moved and 0 otherwise: the
// division by the smallest normal double gives a huge (or infinite) ratio or 0 there; any
// positive rest (at least an ulp of 255) is itself.
inline double Phase3Fraction(double moved, double rest, double m3_scale) {
  const double ratio = (m3_scale * moved) / Max(rest, std::numeric_limits<double>::min());
  return Min(Max(ratio, 0.0), 1.0);
}

void CheckMotorRange(double g, double motor_max) {
  if (!(g >= 0.0 && g <= motor_max)) {
    throw std::out_of_range("g = " + std::to_string(g) + " is outside the motor range [0, " +
                            std::to_string(motor_max) + "]");
  }
}

}  // namespace

Eigen::Vector3d FingerClosedForm::Evaluate(const Piece& piece, double g) const {
  // Branch-free (At is called with random g): linear part plus the phase-3 term, which is 0
  // outside phase 3 (span3 = 0).
  const double moved = g - piece.g0;
  const double rest = parameters_.motor_max - g;
  // (1 - f) / f (g - g_s) / (255 - g), which reaches 1 the fraction f of the way from g_s to
  // 255; clamped there. At g = g_s = 255 nothing has moved: 0.
  Eigen::Vector3d theta = piece.theta0 + piece.rate * moved;
  theta[2] += piece.span3 * Phase3Fraction(moved, rest, parameters_.m3_scale());
  return theta;
}

const FingerClosedForm::Piece& FingerClosedForm::PieceAt(double g) const {
  return pieces_[PieceIndex(ends_, g)];
}

void FingerClosedForm::AnglesAt(std::span<const double> g, std::span<double> theta) const {
  if (theta.size() != 3 * g.size()) {
    throw std::invalid_argument("the angles need 3 places per motor position");
  }
  // Evaluate's arithmetic on the pieces laid out column by column (at most 8), so that the loop
  // below is straight-line code without branches (random g would mispredict them).
  struct Columns {
    std::array<double, 8> g0{}, g1{}, t0{}, t1{}, t2{}, r0{}, r1{}, r2{}, span3{};
  } p;
  for (size_t k = 0; k < pieces_.size(); ++k) {
    const Piece& q = pieces_[k];
    p.g0[k] = q.g0;
    p.g1[k] = q.g1;
    p.t0[k] = q.theta0[0];
    p.t1[k] = q.theta0[1];
    p.t2[k] = q.theta0[2];
    p.r0[k] = q.rate[0];
    p.r1[k] = q.rate[1];
    p.r2[k] = q.rate[2];
    p.span3[k] = q.span3;
  }
  const double motor_max = parameters_.motor_max;
  const double m3_scale = parameters_.m3_scale();
  bool in_range = true;  // checked in the same pass, without a call per position
  for (size_t i = 0; i < g.size(); ++i) {
    in_range &= (g[i] >= 0.0) & (g[i] <= motor_max);
    const size_t k = PieceIndex(ends_, g[i]);
    // As Evaluate(pieces_[k], min(g, g1)), operation for operation (the same values).
    const double x = Min(g[i], p.g1[k]);
    const double moved = x - p.g0[k];
    const double fraction = Phase3Fraction(moved, motor_max - x, m3_scale);
    theta[3 * i] = p.t0[k] + p.r0[k] * moved;
    theta[3 * i + 1] = p.t1[k] + p.r1[k] * moved;
    theta[3 * i + 2] = (p.t2[k] + p.r2[k] * moved) + p.span3[k] * fraction;
  }
  if (!in_range) {
    for (const double x : g) CheckMotorRange(x, motor_max);
  }
}

Eigen::Vector3d FingerClosedForm::VariationBound(double a, double b) const {
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  const double m3_scale = parameters_.m3_scale();
  for (const Piece& piece : pieces_) {
    const double lo = std::max(a, piece.g0), hi = std::min(b, piece.g1);
    if (!(hi > lo)) continue;
    total += piece.rate.cwiseAbs() * (hi - lo);
    if (piece.span3 != 0.0) {
      const double grown = Phase3Fraction(hi - piece.g0, parameters_.motor_max - hi, m3_scale) -
                           Phase3Fraction(lo - piece.g0, parameters_.motor_max - lo, m3_scale);
      total[2] += std::abs(piece.span3) * std::abs(grown);
    }
  }
  return total;
}

FingerConfiguration FingerClosedForm::At(double g) const {
  CheckMotorRange(g, parameters_.motor_max);
  const Piece& piece = PieceAt(g);
  FingerConfiguration out;
  out.theta = Evaluate(piece, Min(g, piece.g1));
  out.motor = std::min(g, stop_);
  out.c = piece.c;
  out.l = piece.l;
  out.phase = piece.phase;
  return out;
}

}  // namespace hybrid::gripper
