// The closed form of section 4 (include/hybrid/gripper/finger_closed_form.h): the report's tables,
// the clashes found in them (docs/finger_model.md), and one truth with the simulated automaton
// spec/finger.ha.
#include "hybrid/gripper/finger_closed_form.h"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/simulation/simulator.h"
#include "tests/test_utilities/robotiq_rig.h"

namespace hybrid::gripper {
namespace {

constexpr double kM1 = 0.5, kM2 = 0.9, kTh1Max = 70, kTh2Max = 90, kTh3Min = -55, kTh3Max = 43;
constexpr double kC = kTh3Max - kTh3Min;

FingerContacts Contacts(double gob1, double gob2, double gob3) {
  FingerContacts c;
  c.gob = {gob1, gob2, gob3};
  return c;
}

// Section 4.1, the table without object, reproduced exactly at every integer motor position
// (the formulas are evaluated in the table's own form; integer g makes both sides exact).
// The batch form gives At's angles bit for bit, for every contact case, at random positions and
// at the pieces' own ends (the breakpoints, where the phase-3 fraction and the clamps act), and
// refuses what At refuses without writing anything.
RC_GTEST_PROP(FingerClosedFormTest, AnglesAtIsAtBitForBit, ()) {
  FingerContacts contacts;
  for (double& gob : contacts.gob) {
    if (*rc::gen::arbitrary<bool>()) gob = *rc::gen::inRange(0, 25500) / 100.0;
  }
  const FingerClosedForm closed(contacts);
  std::vector<double> g = {0.0, 255.0, std::nextafter(255.0, 0.0)};
  for (const auto& piece : closed.pieces()) {
    g.push_back(piece.g0);
    g.push_back(std::min(piece.g1, 255.0));
  }
  for (int k = 0; k < 50; ++k) g.push_back(*rc::gen::inRange(0, 2550000) / 10000.0);
  std::vector<double> theta(3 * g.size());
  closed.AnglesAt(g, theta);
  for (size_t k = 0; k < g.size(); ++k) {
    const Eigen::Vector3d at = closed.At(g[k]).theta;
    for (int j = 0; j < 3; ++j) RC_ASSERT(theta[3 * k + j] == at[j]);
  }
}

TEST(FingerClosedFormTest, AnglesAtRefusesWhatAtRefuses) {
  const FingerClosedForm closed;
  std::vector<double> theta(6, -1.0);
  const std::vector<double> outside = {10.0, 255.5};
  EXPECT_THROW(closed.AnglesAt(outside, theta), std::out_of_range);
  const std::vector<double> nan = {std::nan(""), 10.0};
  EXPECT_THROW(closed.AnglesAt(nan, theta), std::out_of_range);
  // The first position outside is the one named (the range is checked in the computing pass).
  const std::vector<double> two_outside = {-1.0, 300.0};
  try {
    closed.AnglesAt(two_outside, theta);
    ADD_FAILURE() << "no exception";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("g = -1"), std::string::npos) << e.what();
  }
  const std::vector<double> fine = {10.0};
  EXPECT_THROW(closed.AnglesAt(fine, theta), std::invalid_argument);  // 3 angles per position
}

// PhaseOfState against the phases tools/generate_finger.py wrote into spec/finger.ha (a "# phase
// P" comment before each mode, from the script's own rules), and against the closed form's own
// phases (every piece of every contact case).
TEST(FingerClosedFormTest, PhaseOfStateIsTheGeneratedModelsPhase) {
  std::ifstream in(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  std::string line, phase;
  int checked = 0;
  const std::regex comment(R"(^  # phase (1'?|2'?|3|4)$)");
  const std::regex mode(
      R"(^  mode \S+ \(c1 = (\d), c2 = (\d), c3 = (\d), l1 = (\d), l2 = (\d), l3 = (-?\d)\))");
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, comment)) phase = m[1];
    if (!std::regex_search(line, m, mode)) continue;
    const std::array<int, 3> c = {std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3])};
    const std::array<int, 3> l = {std::stoi(m[4]), std::stoi(m[5]), std::stoi(m[6])};
    EXPECT_EQ(PhaseName(PhaseOfState(c, l)), phase) << line;
    ++checked;
  }
  EXPECT_EQ(checked, 31);
  for (const double gob1 : {FingerContacts::kNone, 60.0, 140.0}) {
    for (const double gob2 : {FingerContacts::kNone, 50.0, 170.0}) {
      FingerContacts contacts;
      contacts.gob = {gob1, gob2, FingerContacts::kNone};
      const FingerClosedForm closed(contacts);  // pieces() views it: it must outlive the loop
      for (const auto& piece : closed.pieces()) {
        EXPECT_EQ(PhaseOfState(piece.c, piece.l), piece.phase) << gob1 << " " << gob2;
      }
    }
  }
}

TEST(FingerClosedFormTest, FreeSpaceTableOfSection41) {
  const FingerClosedForm f;
  for (int k = 0; k <= 255; ++k) {
    const double g = k;
    Eigen::Vector3d table;
    FingerPhase phase;
    if (g <= 110) {
      table = {kM1 * g, 0, -kM1 * g}, phase = FingerPhase::k1;
    } else if (g <= 140) {
      table = {kM1 * g, 0, kTh3Min}, phase = FingerPhase::k1Prime;
    } else if (g <= 240) {
      table = {kTh1Max, kM2 * (g - 140), kTh3Min}, phase = FingerPhase::k2Prime;
    } else {
      table = {kTh1Max, kTh2Max, kTh3Min}, phase = FingerPhase::k4;
    }
    const FingerConfiguration q = f.At(g);
    EXPECT_EQ(q.theta, table) << "g = " << g;
    EXPECT_EQ(q.phase, phase) << "g = " << g;
    // The report's remark: theta3 = max(-m1 g, theta3_min) in phases 1 and 1'.
    if (g <= 140) {
      EXPECT_EQ(q.theta[2], std::max(-kM1 * g, kTh3Min));
    }
    EXPECT_EQ(q.motor, std::min(g, 240.0));  // the palm stops the motor at 240 (D3)
  }
  EXPECT_EQ(f.stop(), 240.0);
  EXPECT_EQ(FingerModeName(f.At(255)), "c000_l11n");
}

// The table says phase 2 for 140 < g <= 240; with theta3 already at its lower limit that is the
// automaton's phase 2' (c000_l10n). Checked at fractional g too, within rounding.
TEST(FingerClosedFormTest, FreeSpaceBetweenIntegers) {
  const FingerClosedForm f;
  for (double g = 0.0; g <= 255.0; g += 0.37) {
    const FingerConfiguration q = f.At(g);
    EXPECT_NEAR(q.theta[0], std::min(kM1 * g, kTh1Max), 1e-12);
    EXPECT_NEAR(q.theta[1], std::clamp(kM2 * (g - 140), 0.0, kTh2Max), 1e-12);
    EXPECT_NEAR(q.theta[2], std::max(-kM1 * g, kTh3Min), 1e-12);
  }
}

// Section 4.2, contact on link 1 only (gob <= 140), both rows of the table.
TEST(FingerClosedFormTest, ContactOnLink1FollowsTheTable) {
  for (double gob : {0.0, 30.0, 70.0, 110.0, 123.4, 140.0}) {
    const FingerClosedForm f(Contacts(gob, FingerContacts::kNone, FingerContacts::kNone));
    const double g_s = gob + 100;           // link 2 reaches its limit
    const double g_stop = (255 + g_s) / 2;  // theta3 reaches its limit half way to 255
    for (double g = gob + 0.25; g <= 255; g += 0.25) {
      const FingerConfiguration q = f.At(g);
      const double th1 = kM1 * gob;
      if (g - gob <= 100) {
        const double th2 = kM2 * (g - gob);
        EXPECT_NEAR(q.theta[1], th2, 1e-12) << gob << " " << g;
        EXPECT_NEAR(q.theta[2], std::max(-(th1 + th2), kTh3Min), 1e-12) << gob << " " << g;
      } else {
        const double gg = std::min(g, g_stop);
        EXPECT_NEAR(q.theta[1], kTh2Max, 1e-12);
        EXPECT_NEAR(q.theta[2], std::min(kTh3Max, kTh3Min + kC * (gg - gob - 100) / (255 - gg)),
                    1e-9)
            << gob << " " << g;
      }
      EXPECT_NEAR(q.theta[0], th1, 1e-12);
      EXPECT_EQ(q.motor, std::min(g, g_stop));
    }
    EXPECT_NEAR(f.stop(), g_stop, 1e-12);
    EXPECT_EQ(f.At(255).l[2], 1);  // stopped with link 3 at its upper limit (phase 4)
  }
}

// Section 4.2, contact on link 2 only, second row (140 < gob): theta3 starts at its minimum.
TEST(FingerClosedFormTest, ContactOnLink2AfterLink1StoppedFollowsTheTable) {
  for (double gob : {140.5, 160.0, 200.0, 239.0}) {
    const FingerClosedForm f(Contacts(FingerContacts::kNone, gob, FingerContacts::kNone));
    const double g_stop = (255 + gob) / 2;
    for (double g = gob; g <= g_stop; g += 0.125) {
      const FingerConfiguration q = f.At(g);
      EXPECT_NEAR(q.theta[0], kTh1Max, 1e-12);
      EXPECT_NEAR(q.theta[1], kM2 * (gob - 140), 1e-12);
      EXPECT_NEAR(q.theta[2], std::min(kTh3Max, kTh3Min + kC * (g - gob) / (255 - g)), 1e-9);
    }
  }
}

// Section 4.2, contact on links 1 and 2 (gob1 <= 140, 0 < gob2 - gob1 <= 100), with theta3 at
// its minimum when link 2 is blocked (theta1 + theta2 >= 55).
TEST(FingerClosedFormTest, ContactOnLinks1And2FollowsTheText) {
  const double gob1 = 120, gob2 = 180;
  const FingerClosedForm f(Contacts(gob1, gob2, FingerContacts::kNone));
  for (double g = gob2; g <= 255; g += 0.5) {
    const FingerConfiguration q = f.At(g);
    const double gg = std::min(g, (255 + gob2) / 2);
    EXPECT_NEAR(q.theta[0], kM1 * gob1, 1e-12);
    EXPECT_NEAR(q.theta[1], kM2 * (gob2 - gob1), 1e-12);
    EXPECT_NEAR(q.theta[2], std::min(kTh3Max, kTh3Min + kC * (gg - gob2) / (255 - gg)), 1e-9);
  }
  EXPECT_EQ(FingerModeName(f.At(200)), "c110_l000");
}

// Clash C2 (inside section 4): for link 2 blocked while theta3 is above its minimum (gob2 <=
// 110 without link-1 contact, or soon after a link-1 contact), the table's theta3 = theta3_min +
// c (g - gob) / (255 - g) jumps from -m1 gob to theta3_min at gob. A joint cannot jump; the
// closed form continues from theta3_s, and so does the automaton (phase 3 starts from theta3).
TEST(FingerClosedFormTest, Clash_Link2ContactInPhase1_TableJumpsClosedFormIsContinuous) {
  const double gob = 50;
  const FingerClosedForm f(Contacts(FingerContacts::kNone, gob, FingerContacts::kNone));
  const double before = f.At(gob).theta[2];
  const double after = f.At(gob + 1e-9).theta[2];
  EXPECT_NEAR(before, -kM1 * gob, 1e-12);
  EXPECT_NEAR(after, before, 1e-6);
  const double table_after = std::min(kTh3Max, kTh3Min + kC * 1e-9 / (255 - gob - 1e-9));
  EXPECT_GT(std::abs(table_after - before), 29.0);  // the table's jump: -25 -> -55
  // Still reaches theta3_max half way between gob and 255 (figure 4.1).
  EXPECT_NEAR(f.stop(), (255 + gob) / 2, 1e-12);
  EXPECT_NEAR(f.At(255).theta[2], kTh3Max, 1e-12);
}

// Link 3 blocked: the finger stops (phase 4) wherever it is, and the motor with it.
TEST(FingerClosedFormTest, ContactOnLink3StopsTheFinger) {
  for (double gob3 : {0.0, 60.0, 125.0, 200.0, 241.0}) {
    const FingerClosedForm f(Contacts(FingerContacts::kNone, FingerContacts::kNone, gob3));
    const FingerClosedForm free;
    const double stop = std::min(gob3, 240.0);
    EXPECT_EQ(f.stop(), stop);
    EXPECT_EQ(f.At(255).theta, free.At(stop).theta);
    EXPECT_EQ(f.At(255).motor, stop);
    EXPECT_EQ(f.At(255).c[2], gob3 <= 240 ? 1 : 0);
  }
}

// Defined and finite for every g in [0, 255], including the report's singular g = 255 and a
// contact exactly there.
TEST(FingerClosedFormTest, FiniteEverywhereIncludingG255) {
  for (double gob2 : {0.0, 100.0, 200.0, 254.0, 254.999999, 255.0}) {
    const FingerClosedForm f(Contacts(FingerContacts::kNone, gob2, FingerContacts::kNone));
    for (double g : {0.0, 100.0, 254.0, 254.9999999, 255.0}) {
      const FingerConfiguration q = f.At(g);
      EXPECT_TRUE(q.theta.allFinite()) << gob2 << " " << g;
      EXPECT_GE(q.theta[2], kTh3Min);
      EXPECT_LE(q.theta[2], kTh3Max);
    }
  }
  const FingerClosedForm at_end(Contacts(FingerContacts::kNone, 255.0, FingerContacts::kNone));
  EXPECT_EQ(at_end.At(255).theta[2], kTh3Min);  // blocked at the end of travel: no motion left
}

TEST(FingerClosedFormTest, BadInputThrows) {
  const FingerClosedForm f;
  EXPECT_THROW(f.At(-0.001), std::out_of_range);
  EXPECT_THROW(f.At(255.001), std::out_of_range);
  EXPECT_THROW(f.At(std::nan("")), std::out_of_range);
  EXPECT_THROW(FingerClosedForm(Contacts(-1, 300, 300)), std::invalid_argument);
  EXPECT_THROW(FingerClosedForm(Contacts(std::nan(""), 300, 300)), std::invalid_argument);
  FingerParameters p;
  p.theta_max[1] = 0;
  EXPECT_THROW(FingerClosedForm({}, p), std::invalid_argument);
  // Above the motor range means "no object", as the model's default 256.
  EXPECT_EQ(FingerClosedForm(Contacts(256, 256, 256)).At(200).theta, f.At(200).theta);
}

// ---------------------------------------------------------------------------------------------
// One truth: the automaton spec/finger.ha, simulated, against the closed form.

System FingerWithContacts(const FingerContacts& contacts) {
  System s = ParseModelFile(std::string(HYBRID_SOURCE_DIR) + "/spec/finger.ha");
  for (int i = 0; i < 3; ++i) {
    s.SetParameter("gob" + std::to_string(i + 1), std::min(contacts.gob[i], 256.0));
  }
  return s;
}

double Contact() {
  // No object, or an object anywhere along the motor range.
  return *rc::gen::oneOf(
      rc::gen::just(FingerContacts::kNone),
      rc::gen::map(rc::gen::inRange(0, 2550001), [](int k) { return k / 10000.0; }));
}

// Close at u = 1 to g = 255 and open at u = -1 until the motor is back at 0 (the controller
// stops the motor at the requested position; driving it past 0 would leave the motor range;
// here it stops at 0.25):
// at every recorded state, the simulated joint
// angles equal the closed form at the simulated motor position within 1e-6 degrees (closing and
// reopening: the quasistatic finger retraces), the motor position while closing is min(t,
// stop), and the discrete state equals the closed form's away from breakpoints.
RC_GTEST_PROP(FingerClosedFormProperty, SimulationEqualsClosedForm, ()) {
  const double gob1 = Contact();
  const double gob2 = Contact();
  const double gob3 = Contact();
  const FingerContacts contacts = Contacts(gob1, gob2, gob3);
  const FingerClosedForm closed(contacts);
  const System system = FingerWithContacts(contacts);
  const Simulator sim(system);
  const int u = *system.symbols().Find("u");
  SimulationOptions o;
  o.until = 520.0;
  o.sample_step = *rc::gen::element(0.37, 1.0, 2.5);
  // Back to g = 0.25: ending exactly at g = 0 would put the motor's range end, the input's
  // change and a release at g = 0 (an object at gob = 0) at one instant.
  const double opened = 255.0 + std::max(0.0, std::min(closed.stop(), 255.0) - 0.25);
  InputSignal signal{u, InputSignal::Shape::kStep, {{0.0, 1.0}, {255.0, -1.0}, {opened, 0.0}}};
  if (opened == 255.0) signal.points = {{0.0, 1.0}, {255.0, 0.0}};
  const SimulationResult r = sim.Run(o, {&signal, 1});
  RC_LOG() << r.message << "\n";
  RC_ASSERT(r.status == SimulationStatus::kCompleted);
  const auto& names = sim.variable_names();
  const auto index = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  const int th1 = index("theta1"), th2 = index("theta2"), th3 = index("theta3"), g = index("g");
  const auto near_breakpoint = [&](double motor) {
    for (const auto& piece : closed.pieces()) {
      if (std::abs(piece.g0 - motor) < 1e-6 || std::abs(piece.g1 - motor) < 1e-6) return true;
    }
    return false;
  };
  double worst = 0.0;
  for (const StateSample& s : r.samples) {
    const double motor = s.x[g];
    RC_ASSERT(motor >= -1e-9);
    RC_ASSERT(motor <= 255.0 + 1e-9);
    const FingerConfiguration q = closed.At(std::clamp(motor, 0.0, 255.0));
    for (int k = 0; k < 3; ++k) {
      const double error = std::abs(s.x[std::array{th1, th2, th3}[k]] - q.theta[k]);
      if (error > worst && error > 1e-6) {
        RC_LOG() << "t = " << s.time << " g = " << motor << " mode " << sim.ModeName(0, s.modes[0])
                 << ": theta" << k + 1 << " = " << s.x[std::array{th1, th2, th3}[k]]
                 << ", closed form " << q.theta[k] << " (" << FingerModeName(q) << ")\n";
      }
      worst = std::max(worst, error);
    }
    if (s.time <= 255.0) {
      RC_ASSERT(std::abs(motor - std::min(s.time, closed.stop())) <= 1e-6);
      if (!near_breakpoint(motor) && s.kind == StateSample::Kind::kSample) {
        RC_ASSERT(sim.ModeName(0, s.modes[0]) == FingerModeName(q));
      }
    }
  }
  RC_ASSERT(worst <= 1e-6);
  // Reopened at the end. (While opening only the angles are compared: the flags may differ,
  // e.g. a link-1 contact with theta2 at its minimum is released as soon as the motor reverses.)
  RC_ASSERT(std::abs(r.samples.back().x[g] - std::min(0.25, closed.stop())) <= 1e-6);
}

}  // namespace
}  // namespace hybrid::gripper

namespace hybrid::gripper {
namespace {

// One truth with the independent rig simulator (tests/test_utilities/robotiq_rig.h, written
// from the report apart from gripper/): for no object or an object on link 1 or link 2 anywhere,
// any g, and joint ranges and phase-3 fraction drawn around the report's, the closed form's
// angles equal the rig's, and both stop the finger at the same position. (Objects on link 3 and
// on two links at once are not in the rig.)
RC_GTEST_PROP(FingerClosedFormProperty, EqualsTheIndependentRig, ()) {
  const auto count = [] {
    return *rc::gen::map(rc::gen::inRange(0, 2550001), [](int k) { return k / 1e4; });
  };
  const int link = *rc::gen::inRange(0, 3);  // 0: no object
  const double gob = count();
  const double g = count();
  const bool report = *rc::gen::arbitrary<bool>();  // the report's constants, or others
  FingerParameters p;
  testing::RigFinger finger;
  if (!report) {
    finger.theta1_max = p.theta_max[0] = *rc::gen::inRange(50, 81);
    finger.theta2_max = p.theta_max[1] = *rc::gen::inRange(70, 101);
    finger.theta3_max = p.theta_max[2] = *rc::gen::inRange(30, 51);
    finger.theta3_fraction = p.theta3_fraction = *rc::gen::inRange(20, 81) / 100.0;
  }
  FingerContacts contacts;
  testing::RigObject object;
  if (link == 1) object.gob1 = contacts.gob[0] = gob;
  if (link == 2) object.gob2 = contacts.gob[1] = gob;
  const FingerClosedForm closed(contacts, p);
  RC_LOG() << "link " << link << " gob " << gob << " g " << g << " theta_max "
           << p.theta_max.transpose() << " f " << p.theta3_fraction << "\n";
  RC_ASSERT(std::abs(std::min(closed.stop(), 255.0) - testing::RigStopPosition(finger, object)) <
            1e-9);
  const Eigen::Vector3d theta = closed.At(g).theta;
  const std::array<double, 3> rig = testing::RigAngles(g, finger, object);
  for (int j = 0; j < 3; ++j) RC_ASSERT(std::abs(theta[j] - rig[j]) < 1e-9);
}

}  // namespace
}  // namespace hybrid::gripper

namespace hybrid::gripper {
namespace {

// VariationBound against the total variation measured by differencing At on a fine grid: never
// below it, and equal to it (the report's pieces are monotone in every angle) within what the
// grid can miss at a turn (twice its largest step).
RC_GTEST_PROP(FingerClosedFormVariation, BoundsAndMatchesTheSampledVariation, ()) {
  FingerContacts contacts;
  for (int i = 0; i < 3; ++i) {
    if (*rc::gen::inRange(0, 2)) contacts.gob[i] = *rc::gen::inRange(0, 2550) / 10.0;
  }
  const FingerClosedForm cf(contacts);
  const double a = *rc::gen::inRange(0, 2550) / 10.0;
  const double b = std::min(255.0, a + *rc::gen::inRange(0, 1000) / 10.0);
  constexpr int kSamples = 20000;
  Eigen::Vector3d sampled = Eigen::Vector3d::Zero(), largest = Eigen::Vector3d::Zero();
  Eigen::Vector3d before = cf.At(a).theta;
  for (int k = 1; k <= kSamples; ++k) {
    const Eigen::Vector3d now = cf.At(a + (b - a) * k / kSamples).theta;
    sampled += (now - before).cwiseAbs();
    largest = largest.cwiseMax((now - before).cwiseAbs());
    before = now;
  }
  const Eigen::Vector3d bound = cf.VariationBound(a, b);
  for (int i = 0; i < 3; ++i) {
    RC_ASSERT(bound[i] >= sampled[i] - 1e-9);
    RC_ASSERT(bound[i] <= sampled[i] + 2.0 * largest[i] + 1e-9);
  }
  RC_ASSERT(cf.VariationBound(b, a).isZero());
}

}  // namespace
}  // namespace hybrid::gripper
