// Objects by geometry: the contact positions found on the closed-form path, and the automaton
// whose contact guards are distances finding the same ones by simulation.
#include "hybrid/gripper/geometric_finger.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::gripper {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Vector2d Polar(double rho, double alpha_deg) {
  return rho * Eigen::Vector2d(std::sin(alpha_deg * kDeg), std::cos(alpha_deg * kDeg));
}

// A circle met by link 1 in phase 1: the perpendicular distance from its centre (rho, alpha) to
// link 1 equals the radius when theta1 = alpha - asin(r / rho), so gob1 = theta1 / m1.
TEST(GeometricFingerTest, CircleOnLink1AtTheAnalyticMotorPosition) {
  const double rho = 0.04, alpha = 40, r = 0.005;
  const GeometricFinger f({Obstacle::Circle(Polar(rho, alpha), r)});
  const double theta1 = alpha - std::asin(r / rho) / kDeg;
  EXPECT_NEAR(f.contacts().gob[0], theta1 / 0.5, 1e-8);
  EXPECT_EQ(f.blocked_by()[0], 0);
  EXPECT_TRUE(f.touches_object());
  // After the contact link 1 stays put and never penetrates.
  for (double g = 0; g <= 255; g += 0.5) {
    for (int i = 0; i < 3; ++i) EXPECT_GE(f.Clearance(f.At(g).theta, i), -1e-9) << g << " " << i;
  }
}

TEST(GeometricFingerTest, FreeSpaceIsTheFreeClosedForm) {
  const GeometricFinger f({Obstacle::Circle({-0.2, 0.1}, 0.01)});  // behind the finger
  EXPECT_FALSE(f.touches_object());
  EXPECT_EQ(f.closed_form().stop(), 240.0);
  EXPECT_EQ(f.At(255).theta, FingerClosedForm().At(255).theta);
}

// Link 1 blocked at theta1 = 60 (gob1 = 120): link 2 closes to 90 (g = 220), then phase 3 turns
// link 3 down into the palm, which blocks it (c3) near theta3 = -25, long before theta3_max.
TEST(GeometricFingerTest, ThePalmBlocksLink3) {
  const double r = 0.005, rho = 0.03;
  const GeometricFinger f({Obstacle::Circle(Polar(rho, 60 + std::asin(r / rho) / kDeg), r)});
  EXPECT_NEAR(f.contacts().gob[0], 120.0, 1e-8);
  ASSERT_TRUE(f.blocked_by()[2].has_value());
  EXPECT_EQ(*f.blocked_by()[2], GeometricFinger::kPalm);
  EXPECT_EQ(f.At(255).c[2], 1);
  EXPECT_NEAR(f.At(255).theta[2], -25.1, 0.1);
  EXPECT_GT(f.contacts().gob[2], 220.0);
  // The fingertip is on the palm surface.
  EXPECT_NEAR(f.geometry().Points(f.At(255).theta)[3].y(), f.geometry().palm_y(), 1e-6);
}

TEST(GeometricFingerTest, BadObjects) {
  EXPECT_THROW(GeometricFinger({Obstacle::Circle({0.05, -0.03}, 0.01)}), std::invalid_argument);
  EXPECT_THROW(GeometricFinger({Obstacle::Circle({0.0, 0.05}, 0.01)}), std::invalid_argument);
  try {
    GeometricFinger({Obstacle::Circle({0.05, -0.02}, 0.01)});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("overlaps the palm"), std::string::npos);
  }
}

// One truth with geometry: the automaton with distance guards, simulated closing at u = 1 and
// reopening at u = -1, passes through the closed form of the contacts found geometrically: at
// every recorded state the joint angles equal the closed form at the simulated motor position
// within 1e-6 degrees, the motor stops where the closed form stops (within 1e-6 counts), and no
// link is inside an object or the palm by more than 1e-9 m.
RC_GTEST_PROP(GeometricFingerProperty, SimulationFindsTheSameContacts, ()) {
  const double radius = *rc::gen::inRange(30, 300) / 10000.0;  // 3 mm .. 3 cm
  // Centres where the closing finger can reach (some objects are still missed).
  const Eigen::Vector2d centre(*rc::gen::inRange(0, 1300) / 10000.0,
                               *rc::gen::inRange(-150, 1300) / 10000.0);
  const Obstacle object = Obstacle::Circle(centre, radius);
  std::optional<GeometricFinger> maybe;
  try {
    maybe.emplace(std::vector<Obstacle>{object});
  } catch (const std::invalid_argument&) {
    RC_DISCARD("overlaps the palm or the open finger");
  }
  const GeometricFinger& finger = *maybe;
  RC_TAG(finger.touches_object() ? "touches" : "misses");
  static const System parsed = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  const System system = System::Of(finger.ContactAutomaton(parsed.components()[0].automaton));
  const Simulator sim(system);
  SimulationOptions o;
  // Close for 255 s, then reopen at u = -1 until the motor is back at g = 0.25 (contacts are
  // released by transition 2 and the finger retraces the closed form).
  const double stop = std::min(255.0, finger.closed_form().stop());
  const double reopened = 255.0 + std::max(0.0, stop - 0.25);
  o.until = reopened + 1.0;
  o.sample_step = 2.5;
  const InputSignal u{*system.symbols().Find("u"),
                      InputSignal::Shape::kStep,
                      {{0.0, 1.0}, {255.0, -1.0}, {reopened, 0.0}}};
  const SimulationResult r = sim.Run(o, {&u, 1});
  RC_LOG() << object.ToString() << ": " << r.message << "\n";
  RC_ASSERT(r.status == SimulationStatus::kCompleted);
  const auto& names = sim.variable_names();
  auto index = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  const std::array<int, 3> th = {index("theta1"), index("theta2"), index("theta3")};
  const int g = index("g");
  for (const StateSample& s : r.samples) {
    const FingerConfiguration q = finger.At(std::clamp(s.x[g], 0.0, 255.0));
    Eigen::Vector3d theta;
    for (int k = 0; k < 3; ++k) {
      theta[k] = s.x[th[k]];
      RC_ASSERT(std::abs(theta[k] - q.theta[k]) <= 1e-6);
    }
    for (int k = 0; k < 3; ++k) RC_ASSERT(finger.Clearance(theta, k) >= -1e-9);
  }
  for (const StateSample& s : r.samples) {
    if (s.time <= 255.0) RC_ASSERT(std::abs(s.x[g] - std::min(s.time, stop)) <= 1e-6);
  }
  RC_ASSERT(std::abs(r.samples.back().x[g] - std::min(0.25, stop)) <= 1e-6);
}

}  // namespace
}  // namespace hybrid::gripper
