#include "gripper/hand.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

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

Hand::Hand(std::vector<Obstacle> objects, double spread, const std::array<double, 3>& commands,
           const HandLayout& layout)
    : objects_(std::move(objects)), layout_(layout), commands_(commands) {
  if (!(spread >= 0.0 && spread <= 255.0)) {
    throw std::invalid_argument("Hand: spread position must be in [0, 255]");
  }
  for (double c : commands) {
    if (!(c >= 0.0 && c <= 255.0)) {
      throw std::invalid_argument("Hand: motor commands must be in [0, 255]");
    }
  }
  phi_ = layout.phi_min + (layout.phi_max - layout.phi_min) * spread / 255.0;
  std::array<FingerContacts, 3> imposed;
  auto build = [&]() {
    std::vector<GeometricFinger> fingers;
    for (int f = 0; f < 3; ++f) {
      try {
        fingers.emplace_back(objects_, FingerGeometryOf(f), FingerParameters{}, imposed[f]);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("Hand: finger ") + "ABC"[f] + ": " + e.what());
      }
    }
    return fingers;
  };
  fingers_ = build();
  // Sweep g for touches between fingers.
  double g0 = 0.0;
  for (int round = 0; round < 18; ++round) {
    // Links of every finger in space at sweep position g.
    auto links_at = [&](double g) {
      std::array<std::array<Eigen::Vector3d, 4>, 3> p;
      for (int f = 0; f < 3; ++f) p[f] = Points(f, At(f, g).theta);
      return p;
    };
    auto separation = [&](const std::array<std::array<Eigen::Vector3d, 4>, 3>& p, int f1, int l1,
                          int f2, int l2) {
      return SegmentDistance3(p[f1][l1], p[f1][l1 + 1], p[f2][l2], p[f2][l2 + 1]) -
             layout_.link_width;
    };
    std::vector<double> grid;
    for (double g = g0; g < 255.0; g += GeometricFinger::kResolution) grid.push_back(g);
    grid.push_back(255.0);
    std::optional<FingerTouch> first;
    auto previous = links_at(grid[0]);
    for (size_t k = 1; k < grid.size() && !first; ++k) {
      const auto current = links_at(grid[k]);
      for (int f1 = 0; f1 < 3; ++f1) {
        for (int f2 = f1 + 1; f2 < 3; ++f2) {
          for (int l1 = 0; l1 < 3; ++l1) {
            for (int l2 = 0; l2 < 3; ++l2) {
              const double now = separation(current, f1, l1, f2, l2);
              if (now > 0.0) continue;
              double lo = grid[k - 1], hi = grid[k];
              const double before = separation(previous, f1, l1, f2, l2);
              if (before <= 0.0) {
                // Touching already where the last touch stopped the sweep (e.g. A meets B and,
                // by symmetry, C at the same g): a touch if the links move further in.
                if (now < before && (!first || lo < first->g))
                  first = FingerTouch{f1, l1, f2, l2, lo};
                continue;
              }
              while (hi - lo > 1e-10) {
                const double mid = 0.5 * (lo + hi);
                (separation(links_at(mid), f1, l1, f2, l2) <= 0.0 ? hi : lo) = mid;
              }
              if (!first || hi < first->g) first = FingerTouch{f1, l1, f2, l2, hi};
            }
          }
        }
      }
      previous = current;
    }
    if (!first) break;
    touches_.push_back(*first);
    for (auto [f, l] :
         {std::pair{first->finger_a, first->link_a}, std::pair{first->finger_b, first->link_b}}) {
      // Only a finger still moving at the touch is blocked by it.
      if (first->g < commands_[f] && imposed[f].gob[l] == FingerContacts::kNone) {
        imposed[f].gob[l] = first->g;
      }
    }
    fingers_ = build();
    g0 = first->g;
  }
}

FingerConfiguration Hand::At(int f, double g) const {
  if (!(g >= 0.0 && g <= 255.0)) {
    throw std::out_of_range("Hand::At: g = " + std::to_string(g) + " is outside [0, 255]");
  }
  return fingers_.at(f).At(std::min(g, commands_[f]));
}

System Hand::ComposedAutomata(const System& hand_model, bool shared_command) const {
  const Automaton* finger = nullptr;
  const Automaton* spread = nullptr;
  for (const Component& c : hand_model.components()) {
    if (c.source.name() == "finger") finger = &c.source;
    if (c.source.name() == "spread") spread = &c.source;
  }
  if (finger == nullptr) {
    throw std::invalid_argument("Hand::ComposedAutomata: the model '" + hand_model.name() +
                                "' has no automaton named 'finger'");
  }
  System system("hand");
  if (shared_command) system.Share("u");
  for (int f = 0; f < 3; ++f) {
    system.AddComponent(std::string(1, "ABC"[f]), fingers_[f].ContactAutomaton(*finger));
  }
  if (spread != nullptr) system.AddComponent("S", *spread);
  return system;
}

FingerGeometry Hand::FingerGeometryOf(int f) const {
  if (f == 0) return FingerGeometry({}, FingerPlacement{-layout_.half_span, 1.0});
  return FingerGeometry({}, FingerPlacement{layout_.half_span, -std::cos(phi_ * kDeg)});
}

std::array<Eigen::Vector3d, 4> Hand::Points(int f, const Eigen::Vector3d& theta) const {
  const auto local = FingerGeometry().Points(theta);
  Eigen::Vector3d origin, direction;
  const double c = std::cos(phi_ * kDeg), s = std::sin(phi_ * kDeg);
  switch (f) {
    case 0:
      origin = {-layout_.half_span, 0, 0}, direction = {1, 0, 0};
      break;
    case 1:  // B, on the +z side, turned towards z = 0 for phi > 0
      origin = {layout_.half_span, 0, layout_.lateral}, direction = {-c, 0, -s};
      break;
    default:  // C, on the -z side
      origin = {layout_.half_span, 0, -layout_.lateral}, direction = {-c, 0, s};
      break;
  }
  std::array<Eigen::Vector3d, 4> out;
  for (int k = 0; k < 4; ++k) {
    out[k] = origin + local[k].x() * direction + local[k].y() * Eigen::Vector3d::UnitY();
  }
  return out;
}

}  // namespace hybrid::gripper
