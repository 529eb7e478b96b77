// Tests of the product of interaction groups (solvers/reachability/group_product.h), through
// PolyhedralReachability::Check, on composed models whose verdicts are known analytically: what
// the product proves (a mode no group reaches, a relation the groups' shared parameter keeps),
// and what it must leave to the exact exploration (a relation only the common time keeps, a
// violation, a property with a horizon).

#include "solvers/reachability/group_product.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "hybrid/reachability/polyhedral_reachability.h"
#include "tests/test_utilities/properties.h"

namespace hybrid {
namespace {

using testing::Named;

// What the exact exploration and the product say in their reasons.
constexpr std::string_view kByGroups = "interaction groups alone";
constexpr std::string_view kExact = "fixpoint of exact polyhedral reachability:";

// Property `property` of model `text`, checked with the groups' turn first by default (these
// models are small: with the default turns the exact exploration would decide them before the
// groups' first turn); `turn_units`: Options::group_turn_units. No hulls.
CheckResult CheckOne(std::string_view text, const std::string& property,
                     std::uint64_t turn_units = 0) {
  const System system = ParseModel(text, "test.ha");
  PolyhedralReachability::Options options;
  options.group_turn_units = turn_units;
  options.hull_units = 0;  // the groups' product, not the hulls, is tested here
  return PolyhedralReachability(options).Check(system, {Named(system, property)}).at(0);
}

bool Says(const CheckResult& r, std::string_view what) {
  return r.reason.find(what) != std::string::npos;
}

// Expects `property` of model `text` to be `verdict`, decided by the groups' product.
void ExpectByGroups(std::string_view text, const std::string& property, Verdict verdict) {
  const CheckResult r = CheckOne(text, property);
  EXPECT_EQ(r.verdict, verdict) << property << ": " << r.reason;
  EXPECT_TRUE(Says(r, kByGroups)) << property << ": " << r.reason;
}

// Two copies of a three-cell corridor: x' = 1 from cell c0 to c1 (at x = 1); c1 turns x back
// (x' = -1) and returns to c0 at x = 1/2, so c2 (past x = 2) is never reached. Two instances
// share nothing: the product of their reachable sets lies in {c0, c1} x {c0, c1}.
constexpr std::string_view kCorridors = R"(
automaton corridor {
  var x;
  mode c0 { x' = 1; inv x <= 1; }
  mode c1 { x' = -1; inv x >= 0.5 and x <= 2; }
  mode c2 { x' = 0; }
  transition c0 -> c1 { guard x == 1; }
  transition c1 -> c0 { guard x == 0.5; }
  transition c1 -> c2 { guard x == 2; }
  init c0 { x = 0; }
}
system corridors {
  instance A = corridor;
  instance B = corridor;
  property both_out: reach in A.c2 and in B.c2;
  property one_out: reach in A.c2 or in B.c1;
  property in_range: always A.x <= 1 and B.x >= 0;
}
)";

TEST(GroupProduct, ProvesWhatNoGroupReaches) {
  ExpectByGroups(kCorridors, "both_out", Verdict::kUnreachable);
  ExpectByGroups(kCorridors, "in_range", Verdict::kProved);
}

TEST(GroupProduct, LeavesWhatItsProductMeetsToTheExactExploration) {
  // B reaches c1 at t = 1: the product meets it, the exploration finds and replays the run, also
  // when it explores in turns of a few units (a state met at the end of a turn is still sought).
  for (const std::uint64_t turn_units : {0, 1, 1000}) {
    const CheckResult r = CheckOne(kCorridors, "one_out", turn_units);
    EXPECT_EQ(r.verdict, Verdict::kReachable) << r.reason;
    EXPECT_FALSE(Says(r, kByGroups)) << r.reason;
    EXPECT_TRUE(r.trace.has_value());
    // Unreachable whichever finishes first, the groups or the exact exploration.
    const CheckResult both = CheckOne(kCorridors, "both_out", turn_units);
    EXPECT_EQ(both.verdict, Verdict::kUnreachable) << both.reason;
  }
}

// Two clocks in two instances, started together: x == y along every run, which only the common
// time keeps (each group alone reaches every x in [0, 5]); their product does not know it.
constexpr std::string_view kTwoClocks = R"(
automaton clock {
  var x;
  mode run { x' = 1; inv x <= 5; }
  init run { x = 0; }
}
system clocks {
  instance A = clock;
  instance B = clock;
  property equal: always A.x == B.x;
  property equal_soon: always A.x == B.x within 2;
}
)";

TEST(GroupProduct, ARelationOnlyTimeKeepsIsProvedByTheExactExploration) {
  const CheckResult r = CheckOne(kTwoClocks, "equal");
  EXPECT_EQ(r.verdict, Verdict::kProved) << r.reason;
  EXPECT_TRUE(Says(r, kExact)) << r.reason;
  const CheckResult bounded = CheckOne(kTwoClocks, "equal_soon");  // a horizon: never on groups
  EXPECT_EQ(bounded.verdict, Verdict::kProved) << bounded.reason;
  EXPECT_FALSE(Says(bounded, kByGroups)) << bounded.reason;
}

// Both instances start at the uncertain parameter p and stay there: x == y == p. Each group's set
// relates its variable to p, and the product keeps p one dimension: it proves x == y alone.
constexpr std::string_view kSharedParameter = R"(
automaton still {
  var x;
  param p = 0.5 in [0, 1];
  mode rest { x' = 0; inv x <= 2; }
  init rest { x = p; }
}
system stills {
  share p;
  instance A = still;
  instance B = still;
  property equal: always A.x == B.x;
  property apart: reach A.x >= B.x + 0.5;
}
)";

TEST(GroupProduct, AParameterBothGroupsReadIsOneDimensionOfTheProduct) {
  ExpectByGroups(kSharedParameter, "equal", Verdict::kProved);
  const CheckResult apart = CheckOne(kSharedParameter, "apart");
  EXPECT_EQ(apart.verdict, Verdict::kUnreachable) << apart.reason;
}

}  // namespace
}  // namespace hybrid
