// Tests of the verdict names (solvers/check_result.h): every verdict has its own documented name,
// and a default CheckResult is an undecided `always` property.

#include "solvers/check_result.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace hybrid {
namespace {

TEST(VerdictName, NamesEveryVerdict) {
  EXPECT_EQ(VerdictName(Verdict::kProved), "proved");
  EXPECT_EQ(VerdictName(Verdict::kViolated), "violated");
  EXPECT_EQ(VerdictName(Verdict::kReachable), "reachable");
  EXPECT_EQ(VerdictName(Verdict::kUnreachable), "unreachable");
  EXPECT_EQ(VerdictName(Verdict::kUnknown), "unknown");
}

TEST(VerdictName, NamesAreDistinct) {
  std::set<std::string> names;
  for (Verdict v : {Verdict::kProved, Verdict::kViolated, Verdict::kReachable,
                    Verdict::kUnreachable, Verdict::kUnknown}) {
    names.insert(std::string(VerdictName(v)));
  }
  EXPECT_EQ(names.size(), 5u);
}

TEST(CheckResult, DefaultIsUndecidedWithoutTrace) {
  const CheckResult r;
  EXPECT_EQ(r.verdict, Verdict::kUnknown);
  EXPECT_EQ(r.kind, Property::Kind::kAlways);
  EXPECT_FALSE(r.trace.has_value());
  EXPECT_EQ(r.seconds, 0.0);
}

}  // namespace
}  // namespace hybrid
