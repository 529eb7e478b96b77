// The hand (include/hybrid/gripper/hand.h): layout and spread, fingers closing on extruded objects,
// fingers blocking each other, and the quasistatic hand against the composed automata.
#include "hybrid/gripper/hand.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::gripper {
namespace {

constexpr std::array<double, 3> kClose = {255, 255, 255};

// The deepest violation at sweep position g of "no two fingers' link centre lines closer than
// the link width, no link inside an object or the palm": the most negative of (distance - width)
// over pairs of links of different fingers and of every link's clearance; >= 0 when none.
double WorstOverlap(const Hand& hand, double g) {
  double worst = std::numeric_limits<double>::infinity();
  std::array<std::array<Eigen::Vector3d, 4>, 3> p;
  for (int f = 0; f < 3; ++f) {
    const Eigen::Vector3d theta = hand.At(f, g).theta;
    p[f] = hand.Points(f, theta);
    for (int l = 0; l < 3; ++l) worst = std::min(worst, hand.finger(f).Clearance(theta, l));
  }
  for (int f1 = 0; f1 < 3; ++f1) {
    for (int f2 = f1 + 1; f2 < 3; ++f2) {
      for (int l1 = 0; l1 < 3; ++l1) {
        for (int l2 = 0; l2 < 3; ++l2) {
          worst =
              std::min(worst, SegmentDistance3(p[f1][l1], p[f1][l1 + 1], p[f2][l2], p[f2][l2 + 1]) -
                                  hand.layout().link_width);
        }
      }
    }
  }
  return worst;
}

// SegmentDistance3 against a brute-force minimum over a fine grid of both segments (a law on
// random segments): never above it, and within the grid's resolution of it.
RC_GTEST_PROP(HandProperty, SegmentDistance3IsTheMinimumDistance, ()) {
  auto point = [] {
    return Eigen::Vector3d(*rc::gen::inRange(-100, 100) / 100.0,
                           *rc::gen::inRange(-100, 100) / 100.0,
                           *rc::gen::inRange(-100, 100) / 100.0);
  };
  const Eigen::Vector3d p = point(), q = point(), r = point(), s = point();
  const double d = SegmentDistance3(p, q, r, s);
  double brute = std::numeric_limits<double>::infinity();
  constexpr int kN = 200;
  for (int i = 0; i <= kN; ++i) {
    for (int j = 0; j <= kN; ++j) {
      const Eigen::Vector3d a = p + (q - p) * i / kN, b = r + (s - r) * j / kN;
      brute = std::min(brute, (a - b).norm());
    }
  }
  RC_ASSERT(d <= brute + 1e-12);
  // The grid point next to the true closest points is at most half a grid step away on each.
  RC_ASSERT(brute - d <= 0.5 * ((q - p).norm() + (s - r).norm()) / kN + 1e-12);
}

TEST(HandTest, SpreadModesSetTheAngle) {
  EXPECT_NEAR(Hand({}, Hand::SpreadPosition(SpreadMode::kBasic), kClose).spread_angle(),
              -17 + 34 * 137.0 / 255, 1e-12);
  EXPECT_EQ(Hand({}, Hand::SpreadPosition(SpreadMode::kWide), kClose).spread_angle(), -17);
  EXPECT_EQ(Hand({}, Hand::SpreadPosition(SpreadMode::kPinch), kClose).spread_angle(), 17);
  EXPECT_EQ(SpreadModeByName("scissor"), SpreadMode::kScissor);
  EXPECT_THROW(SpreadModeByName("claw"), std::invalid_argument);
}

// Free closing in basic mode: every finger follows table 4.1 and stops at the palm at 240; the
// fingers pass each other (B and C are 7.2 cm apart, A between them) without touching.
TEST(HandTest, FreeClosingInBasicMode) {
  const Hand hand({}, Hand::SpreadPosition(SpreadMode::kBasic), kClose);
  EXPECT_TRUE(hand.touches().empty());
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(hand.At(f, 255).theta, Eigen::Vector3d(70, 90, -55)) << f;
    EXPECT_EQ(hand.finger(f).closed_form().stop(), 240.0);
  }
}

// Layout: A opposite B and C, which mirror each other across z = 0; the open fingers stand
// straight up from the palm.
TEST(HandTest, FingerPlacement) {
  const Hand hand({}, Hand::SpreadPosition(SpreadMode::kPinch), kClose);
  const Eigen::Vector3d theta(30, 20, -10);
  const auto a = hand.Points(0, theta), b = hand.Points(1, theta), c = hand.Points(2, theta);
  EXPECT_NEAR(a[0].x(), -0.045, 1e-15);
  EXPECT_GT(a[3].x(), a[0].x());  // A closes towards +x
  EXPECT_LT(b[3].x(), b[0].x());  // B towards -x
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(b[k].x(), c[k].x(), 1e-15);
    EXPECT_NEAR(b[k].y(), c[k].y(), 1e-15);
    EXPECT_NEAR(b[k].z(), -c[k].z(), 1e-15);
  }
  EXPECT_LT(b[3].z(), b[0].z());  // pinch turns B towards the centre plane
  // The placement used for objects is the projection of Points onto x-y.
  const auto projected = hand.FingerGeometryOf(1).Points(theta);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(projected[k].x(), b[k].x(), 1e-15);
    EXPECT_NEAR(projected[k].y(), b[k].y(), 1e-15);
  }
}

// In pinch mode with finger A stopped at 100, fingers touch each other. The law: at every sweep
// position no two fingers' link centre lines come closer than the link width (beyond the
// bisection tolerance), and no link enters the object or the palm.
TEST(HandTest, FingersBlockEachOtherAndNeverInterpenetrate) {
  const Hand hand({Obstacle::Circle({0.0, 0.06}, 0.02)}, Hand::SpreadPosition(SpreadMode::kPinch),
                  {100, 255, 255});
  ASSERT_FALSE(hand.touches().empty());
  for (const auto& t : hand.touches()) {
    EXPECT_NE(t.finger_a, t.finger_b);
    EXPECT_EQ(*hand.finger(t.finger_a).blocked_by()[t.link_a] == GeometricFinger::kImposed ||
                  hand.At(t.finger_a, t.g).motor <= t.g,
              true);
  }
  EXPECT_LE(hand.At(0, 255).motor, 100.0);
  for (double g = 0; g <= 255; g += 0.25) EXPECT_GE(WorstOverlap(hand, g), -1e-7) << "g = " << g;
}

// The same law on random hands: a cylinder anywhere above the palm, any spread, any commands.
RC_GTEST_PROP(HandProperty, NoInterpenetrationOnRandomHands, ()) {
  const double radius = *rc::gen::inRange(50, 300) / 10000.0;
  const Eigen::Vector2d centre(*rc::gen::inRange(-600, 600) / 10000.0,
                               *rc::gen::inRange(0, 1300) / 10000.0);
  // Half the cases in pinch, where fingers B and C turn towards A and each other.
  const double spread = *rc::gen::oneOf(rc::gen::just(255), rc::gen::inRange(0, 256));
  const std::array<double, 3> commands = {static_cast<double>(*rc::gen::inRange(0, 256)),
                                          static_cast<double>(*rc::gen::inRange(0, 256)),
                                          static_cast<double>(*rc::gen::inRange(0, 256))};
  std::optional<Hand> maybe;
  try {
    maybe.emplace(std::vector<Obstacle>{Obstacle::Circle(centre, radius)}, spread, commands);
  } catch (const std::invalid_argument&) {
    RC_DISCARD("the object overlaps the palm or an open finger");
  }
  const Hand& hand = *maybe;
  RC_TAG(hand.touches().empty() ? "no finger touches" : "fingers touch");
  for (double g = 0; g <= 255; g += 0.5) {
    for (int f = 0; f < 3; ++f) RC_ASSERT(hand.At(f, g).motor <= commands[f]);
    RC_ASSERT(WorstOverlap(hand, g) >= -1e-7);
  }
}

// A finger commanded to 30 never reaches the cylinder (its link 2 would meet it near 43): no
// contact is found beyond the command, and the finger stays at its command.
TEST(HandTest, ContactsAreSearchedUpToTheCommand) {
  const Hand hand({Obstacle::Circle({0.0, 0.06}, 0.02)}, Hand::SpreadPosition(SpreadMode::kBasic),
                  {30, 255, 255});
  EXPECT_FALSE(hand.finger(0).touches_object());
  EXPECT_EQ(hand.At(0, 255).motor, 30.0);
  EXPECT_TRUE(hand.finger(1).touches_object());
}

TEST(HandTest, BadInput) {
  EXPECT_THROW(Hand({}, -1, kClose), std::invalid_argument);
  EXPECT_THROW(Hand({}, 137, {0, 256, 0}), std::invalid_argument);
  EXPECT_THROW(Hand({}, 137, {0, std::nan(""), 0}), std::invalid_argument);
  try {
    Hand({Obstacle::Circle({0.0, -0.02}, 0.02)}, 137, kClose);
    ADD_FAILURE() << "an object in the palm was accepted";
  } catch (const std::invalid_argument& e) {
    // In the words of the hand (which finger), without C++ names ("Hand: ", "GeometricFinger: ").
    const std::string what = e.what();
    EXPECT_TRUE(what.starts_with("finger A: object ")) << what;
    EXPECT_NE(what.find("overlaps the palm"), std::string::npos) << what;
  }
  try {
    Hand({}, -1, kClose);
    ADD_FAILURE() << "a spread of -1 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "the spread position must be in [0, 255]");
  }
  EXPECT_THROW(Hand({}, 137, kClose).At(0, 256), std::out_of_range);
}

// The composition: three finger automata with distance guards (objects, palm and the other
// fingers) and the spread automaton of spec/hand.ha, one shared command u, simulated closing:
// every finger follows the quasistatic hand within 1e-6 degrees and stops where it stops (random
// cylinders across the hand, random spread, half of them in pinch where fingers touch).
RC_GTEST_PROP(HandProperty, ComposedAutomataFollowTheQuasistaticHand, ()) {
  const double radius = *rc::gen::inRange(50, 300) / 10000.0;
  const Eigen::Vector2d centre(*rc::gen::inRange(-400, 400) / 10000.0,
                               *rc::gen::inRange(0, 1300) / 10000.0);
  const double spread = *rc::gen::oneOf(rc::gen::just(255), rc::gen::inRange(0, 256));
  std::optional<Hand> maybe;
  try {
    maybe.emplace(std::vector<Obstacle>{Obstacle::Circle(centre, radius)}, spread, kClose);
  } catch (const std::invalid_argument&) {
    RC_DISCARD("the object overlaps the palm or an open finger");
  }
  const Hand& hand = *maybe;
  static const System model = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/hand.ha");
  const System system = hand.ComposedAutomata(model, /*shared_command=*/true);
  const Simulator sim(system);
  SimulationOptions o;
  o.until = 255.0;
  o.sample_step = 5.0;
  const InputSignal u{*system.symbols().Find("u"), InputSignal::Shape::kStep, {{0.0, 1.0}}};
  const SimulationResult r = sim.Run(o, {&u, 1});
  RC_LOG() << r.message << "\n";
  RC_ASSERT(r.status == SimulationStatus::kCompleted);
  RC_TAG(hand.touches().empty() ? "no finger touches" : "fingers touch");
  const auto& names = sim.variable_names();
  auto index = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  for (int f = 0; f < 3; ++f) {
    const std::string p = std::string(1, "ABC"[f]) + ".";
    const int g = index(p + "g");
    for (const StateSample& s : r.samples) {
      RC_ASSERT(std::abs(s.x[g] - std::min(s.time, hand.finger(f).closed_form().stop())) <= 1e-6);
      const FingerConfiguration q = hand.finger(f).At(std::clamp(s.x[g], 0.0, 255.0));
      for (int k = 0; k < 3; ++k) {
        RC_ASSERT(std::abs(s.x[index(p + "theta" + std::to_string(k + 1))] - q.theta[k]) <= 1e-6);
      }
    }
  }
}

}  // namespace
}  // namespace hybrid::gripper
