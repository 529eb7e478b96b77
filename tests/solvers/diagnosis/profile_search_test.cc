#include "solvers/diagnosis/profile_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hybrid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Profile, AddKeepsValuesSortedAndDistinct) {
  Profile p;
  p.Add(2.0, {2});
  p.Add(1.0, {1});
  p.Add(3.0, {3});
  p.Add(2.0, {99});  // already recorded: kept as it was
  EXPECT_EQ(p.grid, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(p.losses[1], std::vector<double>{2});
}

// Two runs whose losses are parabolas with minima at 1 and 3: all runs give 2, each run alone
// its own minimum; the parabola refines between close points only.
TEST(Minimise, PicksTheFoldMinimumOnUnevenPoints) {
  Profile p;
  p.coarse_step = 1.0;
  for (double x : {0.0, 1.0, 1.7, 1.9, 2.3, 3.0, 4.0}) {
    p.Add(x, {(x - 1) * (x - 1), (x - 3) * (x - 3)});
  }
  EXPECT_NEAR(*Minimise(p, {1, 1}), 2.0, 1e-9);  // neighbours 1.9 and 2.3: the exact vertex
  EXPECT_DOUBLE_EQ(*Minimise(p, {1, 0}), 1.0);   // neighbours 0 and 1.7: too far apart
  EXPECT_DOUBLE_EQ(*Minimise(p, {0, 1}), 3.0);
}

TEST(Minimise, IgnoresInfiniteLossesAndSaysWhenNothingIsFinite) {
  Profile p;
  p.coarse_step = 1.0;
  p.Add(0.0, {kInf});
  p.Add(1.0, {5.0});
  p.Add(2.0, {kInf});
  EXPECT_DOUBLE_EQ(*Minimise(p, {1}), 1.0);
  Profile none;
  none.Add(0.0, {kInf});
  EXPECT_FALSE(Minimise(none, {1}));
  EXPECT_FALSE(Minimise(Profile{}, {1}));
}

TEST(BracketSearch, ConvergesOnAVShapeWithinItsBudget) {
  std::vector<double> tried;
  BracketSearch(0.0, 10.0, {{5.0, std::abs(5.0 - 3.21)}}, 12, [&](double x) {
    tried.push_back(x);
    return std::abs(x - 3.21);
  });
  EXPECT_EQ(tried.size(), 12u);
  double best = kInf;
  for (double x : tried) best = std::min(best, std::abs(x - 3.21));
  EXPECT_LT(best, 0.05);
  for (double x : tried) EXPECT_TRUE(x > 0.0 && x < 10.0);
}

// A narrow basin (|x - 6.3| < 0.2) that no coarse point hits, inside a wide one at the short
// horizon: the short horizon's best point starts the bracketing, which finds the narrow one.
TEST(SearchProfile, FindsANarrowBasinThroughAShortHorizon) {
  const auto full = [](double x) { return std::abs(x - 6.3) < 0.2 ? std::abs(x - 6.3) : 1.0; };
  const auto shortened = [](double x) { return std::min(1.0, std::abs(x - 6.3) / 3.0); };
  SearchSettings s;
  s.lo = 0.0;
  s.hi = 16.0;
  s.coarse = 9;  // 0, 2, 4, ..., 16
  s.horizons = 2;
  s.evaluations = 8;
  const Profile p = SearchProfile(s, [&](const std::vector<double>& values) {
    HorizonLosses out;
    for (double x : values) out.push_back({{shortened(x)}, {full(x)}});
    return out;
  });
  EXPECT_DOUBLE_EQ(p.coarse_step, 2.0);
  EXPECT_EQ(p.grid.size(), 9u + 2u * 8u);  // two starts: 6 (short horizon) and 0 (full, flat)
  EXPECT_NEAR(*Minimise(p, {1}), 6.3, 0.063);
  s.horizons = 1;  // the full horizon alone: every coarse point is flat, the basin is missed
  const Profile alone = SearchProfile(s, [&](const std::vector<double>& values) {
    HorizonLosses out;
    for (double x : values) out.push_back({{full(x)}});
    return out;
  });
  EXPECT_GT(std::abs(*Minimise(alone, {1}) - 6.3), 0.2);
}

TEST(SearchProfile, ExtraStartsSearchFurtherLocalMinima) {
  // Two basins: the coarse grid's best is the shallow one at 2; the deeper one at 12.6 is narrow,
  // seen on the grid only as a local minimum at 12.
  const auto f = [](double x) {
    const double d = std::abs(x - 12.6);
    return std::min(0.5 + 0.1 * std::abs(x - 2.0), d < 0.3 ? d : 0.8 + 0.05 * d);
  };
  SearchSettings s;
  s.lo = 0.0;
  s.hi = 16.0;
  s.coarse = 9;
  s.extra_starts = 1;
  const auto evaluate = [&](const std::vector<double>& values) {
    HorizonLosses out;
    for (double x : values) out.push_back({{f(x)}});
    return out;
  };
  EXPECT_NEAR(*Minimise(SearchProfile(s, evaluate), {1}), 12.6, 0.1);
  // With two horizons that choose the same start, the extra start is the second (a case that
  // once read past the starts' horizons).
  s.horizons = 2;
  const auto twice = [&](const std::vector<double>& values) {
    HorizonLosses out;
    for (double x : values) out.push_back({{f(x)}, {f(x)}});
    return out;
  };
  EXPECT_NEAR(*Minimise(SearchProfile(s, twice), {1}), 12.6, 0.1);
  s.horizons = 1;
  s.extra_starts = 0;
  EXPECT_NEAR(*Minimise(SearchProfile(s, evaluate), {1}), 2.0, 0.1);
}

}  // namespace
}  // namespace hybrid
