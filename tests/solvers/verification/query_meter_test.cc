// Tests of the query meter (solvers/verification/query_meter.h), with Z3 directly: what the
// encoding's steps and paths are charged; a query is charged what Z3 counts; a query or a
// charge past the ceiling is refused and counted as starved; a query is written to the dump
// directory first; each query is logged.

#include "solvers/verification/query_meter.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <z3++.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "hybrid/automaton/log.h"
#include "hybrid/automaton/parser.h"

namespace hybrid {
namespace {

// Two modes, two transitions (one from each mode).
constexpr std::string_view kModel = R"(
automaton two {
  var x;
  mode a { x' = 1; }
  mode b { x' = -1; }
  transition up: a -> b { guard x >= 1; }
  transition down: b -> a { guard x <= 0; }
  init a { x = 0; }
}
)";

TEST(QueryMeter, EncodingChargesFollowTheModesAndTransitions) {
  const Automaton a = ParseAutomaton(kModel, "two.ha");
  EXPECT_EQ(StepUnits(a), kUnitsPerEncodedElement * (2 + 2 + 1));
  // k + 1 states of (modes + 1), k - 1 full steps, and the last step.
  EXPECT_EQ(PathUnits(a, 1, -1), kUnitsPerEncodedElement * (2 * 3 + 0 + 5));
  EXPECT_EQ(PathUnits(a, 2, -1), kUnitsPerEncodedElement * (3 * 3 + 5 + 5));
  // From mode a: its flow and its one outgoing transition.
  EXPECT_EQ(PathUnits(a, 1, 0), kUnitsPerEncodedElement * (2 * 3 + 0 + 2));
}

TEST(QueryMeter, AQueryIsChargedWhatZ3Counts) {
  z3::context ctx;
  SolverBudget budget(1.0);
  QueryMeter meter(ctx, budget);
  z3::solver s = MakeIncremental(ctx);
  const z3::expr x = ctx.real_const("x");
  s.add(x > 0 && x < 1);
  EXPECT_EQ(meter.Check(s, 1'000'000, budget.total(), "test"), z3::sat);
  EXPECT_GT(budget.used(), 0u);
  EXPECT_EQ(budget.used(), ResourceCount(s));
  EXPECT_EQ(meter.starved(), 0);
  // A second query is charged only what it adds.
  const std::uint64_t first = budget.used();
  s.add(x > 2);
  EXPECT_EQ(meter.Check(s, 1'000'000, budget.total(), "test"), z3::unsat);
  EXPECT_EQ(budget.used(), ResourceCount(s));
  EXPECT_GE(budget.used(), first);
}

TEST(QueryMeter, NothingRunsPastTheCeiling) {
  z3::context ctx;
  SolverBudget budget(1.0);
  QueryMeter meter(ctx, budget);
  z3::solver s = MakeIncremental(ctx);
  s.add(ctx.real_const("x") > 0);
  EXPECT_EQ(meter.Check(s, 1'000'000, 0, "test"), z3::unknown);
  EXPECT_EQ(budget.used(), 0u);
  EXPECT_EQ(meter.starved(), 1);
  EXPECT_FALSE(meter.Afford(10, 9));
  EXPECT_EQ(meter.starved(), 2);
  EXPECT_EQ(budget.used(), 0u);
  EXPECT_TRUE(meter.Afford(10, 10));
  EXPECT_EQ(budget.used(), 10u);
  EXPECT_EQ(meter.starved(), 2);
}

TEST(QueryMeter, QueriesAreDumpedInOrder) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hybrid_meter_dump_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  z3::context ctx;
  SolverBudget budget(1.0);
  int count = 0;
  QueryMeter meter(ctx, budget, {dir.string(), &count});
  z3::solver s = MakeIncremental(ctx);
  s.add(ctx.real_const("x") > 0);
  meter.Check(s, 1'000'000, budget.total(), "test");
  meter.Check(s, 1'000'000, budget.total(), "test");
  EXPECT_EQ(count, 2);
  std::ifstream q0(dir / "q0.smt2");
  std::string line;
  std::getline(q0, line);
  EXPECT_EQ(line, "; rlimit 1000000");
  std::stringstream rest;
  rest << q0.rdbuf();
  EXPECT_NE(rest.str().find("(declare-fun x () Real)"), std::string::npos) << rest.str();
  EXPECT_TRUE(std::filesystem::exists(dir / "q1.smt2"));
  std::filesystem::remove_all(dir);
}

TEST(QueryMeter, EachQueryIsLogged) {
  std::vector<std::string> info, debug;
  SetLogSink(
      [&](LogLevel level, std::string_view topic, std::string_view message) {
        EXPECT_EQ(topic, "prove");
        (level == LogLevel::kInfo ? info : debug).emplace_back(message);
      },
      LogLevel::kDebug);
  {
    z3::context ctx;
    SolverBudget budget(1.0);
    QueryMeter meter(ctx, budget);
    z3::solver s = MakeIncremental(ctx);
    s.add(ctx.real_const("x") > 0);
    meter.Check(s, 1'000'000, budget.total(), "test");
    meter.Check(s, 1'000'000, 0, "refused");
  }
  SetLogSink(nullptr);
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].rfind("query (test): sat, ", 0), 0u) << info[0];
  EXPECT_NE(info[0].find(" units, "), std::string::npos) << info[0];
  EXPECT_EQ(debug, (std::vector<std::string>{"query start (test)",
                                             "query (refused) not run: budget spent"}));
}

// CheckApart: the query solved in a context of its own decides as Check does (linear and
// nonlinear), reads the watched formulas off its model on sat, is charged what that context
// counted (the same for the same query in a new group, whatever ran before) and runs nothing
// past the ceiling.
TEST(QueryMeter, AQueryAskedApartDecidesAndIsCharged) {
  z3::context ctx;
  SolverBudget budget(1.0);
  QueryMeter meter(ctx, budget);
  const z3::expr x = ctx.real_const("x");
  const z3::expr y = ctx.real_const("y");
  z3::expr_vector sat(ctx);
  sat.push_back(x > 0 && x < 1);
  std::vector<bool> holds;
  EXPECT_EQ(meter.CheckApart(sat, 1'000'000, budget.total(), "test", {x<2, x> 3}, holds, 1),
            z3::sat);
  EXPECT_EQ(holds, (std::vector<bool>{true, false}));
  // Nonlinear: x y = 1 with x > 0 and y < 0 has no solution (nlsat).
  z3::expr_vector unsat(ctx);
  unsat.push_back(x * y == 1 && x > 0 && y < 0);
  std::uint64_t before = budget.used();
  EXPECT_EQ(meter.CheckApart(unsat, 1'000'000, budget.total(), "test", {x > 0}, holds, 2),
            z3::unsat);
  EXPECT_TRUE(holds.empty());
  const std::uint64_t alone = budget.used() - before;
  EXPECT_GT(alone, 0u);
  // The meter's own context is not touched: a query there is charged from its own count.
  z3::solver s = MakeSolver(ctx);
  s.add(x * x < 0);
  EXPECT_EQ(meter.Check(s, 1'000'000, budget.total(), "test"), z3::unsat);
  // The same query in a new group costs the same.
  before = budget.used();
  EXPECT_EQ(meter.CheckApart(unsat, 1'000'000, budget.total(), "test", {}, holds, 3), z3::unsat);
  EXPECT_EQ(budget.used() - before, alone);
  // Past the ceiling nothing runs.
  before = budget.used();
  EXPECT_EQ(meter.CheckApart(unsat, 1'000'000, 0, "test", {}, holds, 4), z3::unknown);
  EXPECT_EQ(budget.used(), before);
  EXPECT_EQ(meter.starved(), 1);
}

}  // namespace
}  // namespace hybrid
