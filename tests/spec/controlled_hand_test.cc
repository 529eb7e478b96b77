// The hand behind its controllers (spec/controlled_hand.ha: three driven fingers, a controller
// bound to each, the spread actuator): simulated, every finger's motor stops where the
// independent rig (tests/test_utilities/robotiq_rig.h) stops that finger, with an object of its
// own, and its angles are the rig's; with one request per finger each follows its own; the
// controllers' invariants are proved per finger (the product of a finger and its controller,
// never of the whole hand), a proof serving for another finger only where the two are alike,
// and a false property comes back violated with a trace the simulator replays.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/checking/trace.h"
#include "hybrid/simulation/simulator.h"
#include "hybrid/verification/property_prover.h"
#include "tests/test_utilities/models.h"
#include "tests/test_utilities/robotiq_rig.h"

namespace hybrid {
namespace {

const std::string kSource = HYBRID_SOURCE_DIR;
const std::array<std::string, 3> kFingers = {"A", "B", "C"};

System ControlledHand() { return ParseModelFile(kSource + "/spec/controlled_hand.ha"); }

// The value of each named variable at each sample time of a run of `system` under step inputs
// `inputs` (input name -> points).
std::map<std::string, std::vector<double>> Samples(
    const System& system,
    const std::map<std::string, std::vector<std::pair<double, double>>>& inputs, double until,
    const std::vector<double>& times) {
  const Simulator simulator(system);
  SimulationOptions options;
  options.until = until;
  options.sample_times = times;
  std::vector<InputSignal> signals;
  for (const auto& [name, points] : inputs) {
    signals.push_back({*system.symbols().Find(name), InputSignal::Shape::kStep, points});
  }
  const SimulationResult r = simulator.Run(options, signals);
  EXPECT_EQ(r.status, SimulationStatus::kCompleted) << r.message;
  const auto& names = simulator.variable_names();
  std::map<std::string, std::vector<double>> out;
  for (const StateSample& s : r.samples) {
    if (s.kind != StateSample::Kind::kSample) continue;
    for (std::size_t i = 0; i < names.size(); ++i) out[names[i]].push_back(s.x[i]);
  }
  return out;
}

// One request for the three fingers, each with its own object: finger A free (the palm stops
// it at 240), B against an object on link 2 at 100, C on link 1 at 60. Every settled sample of
// every finger is the rig's for that finger.
TEST(ControlledHandTest, EachFingerStopsWhereTheRigStopsIt) {
  System hand = ControlledHand();
  hand.SetParameter("B.gob2", 100);
  hand.SetParameter("C.gob1", 60);
  std::map<std::string, testing::RigObject> objects = {{"A", {}}, {"B", {}}, {"C", {}}};
  objects["B"].gob2 = 100;
  objects["C"].gob1 = 60;
  const std::vector<double> requests = {100, 255, 250, 150, 0};
  std::vector<std::pair<double, double>> points;
  std::vector<double> times;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    points.emplace_back(2.0 * static_cast<double>(k), requests[k]);
    times.push_back(2.0 * static_cast<double>(k + 1) - 1e-3);
  }
  const auto x =
      Samples(hand, {{"request", points}}, 2.0 * static_cast<double>(requests.size()), times);
  const testing::RigFinger rig;
  for (const std::string& f : kFingers) {
    const double stop = testing::RigStopPosition(rig, objects[f]);
    ASSERT_EQ(x.at(f + ".g").size(), requests.size());
    for (std::size_t k = 0; k < requests.size(); ++k) {
      const double motor = std::min(requests[k], stop);
      EXPECT_NEAR(x.at(f + ".g")[k], motor, 1e-6) << f << " request " << requests[k];
      const auto expected = testing::RigAngles(motor, rig, objects[f]);
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(x.at(f + ".theta" + std::to_string(j + 1))[k], expected[j], 1e-4)
            << f << " request " << requests[k] << " theta" << j + 1;
      }
    }
  }
  // The three stop at different places: the fingers are not driven as one.
  EXPECT_LT(testing::RigStopPosition(rig, objects["B"]), 240);
  EXPECT_NEAR(x.at("A.g")[1], 240, 1e-6);
}

// Without `share request`, each controller reads a request of its own.
TEST(ControlledHandTest, OneRequestPerFinger) {
  std::string text =
      testing::ReplaceOnce(testing::SpecText("controlled_hand"), "  share request;\n", "");
  text = testing::ReplaceOnce(text, "request = step(0: 255, 2: 0);", "ctlA.request = 255;");
  const System hand = ParseModel(text, kSource + "/spec/controlled_hand.ha");
  ASSERT_FALSE(hand.symbols().Find("request").has_value());
  const auto x = Samples(hand,
                         {{"ctlA.request", {{0, 200}}},
                          {"ctlB.request", {{0, 100}, {1.5, 30}}},
                          {"ctlC.request", {{0, 255}}}},
                         3, {1.4, 2.9});
  EXPECT_NEAR(x.at("A.g")[1], 200, 1e-9);
  EXPECT_NEAR(x.at("B.g")[0], 100, 1e-9);
  EXPECT_NEAR(x.at("B.g")[1], 30, 1e-9);
  EXPECT_NEAR(x.at("C.g")[1], 240, 1e-9);  // the palm stop
}

// The 12 declared invariants (3 per finger's controller, 1 per finger of the system's own) are
// proved with the default budget, each on the product of one finger and its controller (the
// hand's whole product has far more than the 2000 modes allowed); fingers B and C take finger A's
// proof: their automata are A's, bound alike.
TEST(ControlledHandTest, EveryDeclaredInvariantIsProvedFingerByFinger) {
  const System hand = ControlledHand();
  const std::vector<Property> invariants = DeclaredProperties(hand);
  ASSERT_EQ(invariants.size(), 12u);
  const auto results = PropertyProver(PropertyProver::Options{}).Check(hand, invariants);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kProved) << r.property << ": " << r.reason;
    const bool a = r.property.find("A") != std::string::npos;
    EXPECT_EQ(r.reason.find("the proof for instances A, ctlA") != std::string::npos, !a)
        << r.property << ": " << r.reason;
  }
}

// With an object in finger B's way, B's product differs from A's: B is proved on its own.
TEST(ControlledHandTest, AFingerUnlikeTheOthersIsProvedOnItsOwn) {
  System hand = ControlledHand();
  hand.SetParameter("B.gob2", 100);
  std::vector<Property> invariants;
  for (const Property& p : DeclaredProperties(hand)) {
    const bool a = p.name.ends_with("_A") || p.name.starts_with("ctlA.");
    const bool b = p.name.ends_with("_B") || p.name.starts_with("ctlB.");
    if (a || b) invariants.push_back(p);
  }
  ASSERT_EQ(invariants.size(), 8u);
  PropertyProver::Options options;
  options.budget = 120;  // two products to prove; headroom for sanitized builds
  const auto results = PropertyProver(options).Check(hand, invariants);
  for (const CheckResult& r : results) {
    EXPECT_EQ(r.verdict, Verdict::kProved) << r.property << ": " << r.reason;
    EXPECT_EQ(r.reason.find("the proof for"), std::string::npos) << r.reason;
  }
}

// A false property of one finger comes back violated, with a trace that the simulator replays
// on the whole hand; the same question of finger C takes B's trace, renamed, which replays for C.
TEST(ControlledHandTest, AFalsePropertyOfOneFingerIsViolatedWithATraceOfTheWholeHand) {
  const System hand = ControlledHand();
  std::vector<Property> properties;
  for (const std::string& f : {"B", "C"}) {
    properties.push_back(
        {"below_200_" + f,
         Property::Kind::kAlways,
         Predicate::Compare({Expression::Symbol(f + ".g", *hand.symbols().Find(f + ".g")),
                             Relation::kLessEqual, Expression::Constant(200)}),
         {}});
  }
  const auto results = PropertyProver(PropertyProver::Options{}).Check(hand, properties);
  for (std::size_t i = 0; i < results.size(); ++i) {
    const CheckResult& r = results[i];
    ASSERT_EQ(r.verdict, Verdict::kViolated) << r.property << ": " << r.reason;
    ASSERT_TRUE(r.trace.has_value());
    Trace trace = *r.trace;
    EXPECT_TRUE(ReplayTrace(hand, properties[i], trace)) << r.property;
    EXPECT_EQ(r.reason.find("the proof for instances B, ctlB") != std::string::npos, i == 1)
        << r.reason;
  }
}

}  // namespace
}  // namespace hybrid
