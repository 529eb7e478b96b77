// Tests of the trace builder (solvers/verification/trace_builder.h), with Z3 directly: a path of
// the encoding becomes a trace that starts from the initial state the path starts from, with the
// values it gives a box, and the path's input held over each flow; a path from no initial state
// has no trace; and the trace replays in the simulator.

#include "solvers/verification/trace_builder.h"

#include <gtest/gtest.h>
#include <z3++.h>

#include <string_view>
#include <vector>

#include "hybrid/automaton/parser.h"
#include "solvers/verification/query_meter.h"

namespace hybrid {
namespace {

// Two initial states: at 0, or anywhere in [2, 3].
constexpr std::string_view kModel = R"(
automaton tank {
  var x;
  input u in [0, 1];
  mode fill { x' = u; }
  init fill { x = 0; }
  init fill { x in [2, 3]; }
  property below_4: always x <= 4;
}
)";

Predicate Compare(const System& system, const std::string& name, Relation relation, double value) {
  const int slot = system.symbols().Find(name).value();
  return Predicate::Compare(
      {Expression::Symbol(name, slot), relation, Expression::Constant(value)});
}

struct Fixture {
  System system = ParseModel(kModel, "tank.ha");
  ProofJob job;
  z3::context ctx;
  std::optional<SmtEncoding> enc;
  Fixture() {
    job.automaton = &system.components()[0].automaton;
    job.component = 0;
    job.to_system = system.components()[0].global_slot;
    enc.emplace(ctx, *job.automaton);
  }
};

// A path of one flow step from the box that ends above 4: the trace starts from the second
// initial state with the path's value, holds the path's input for the flow's duration, and
// replays into a violation of below_4.
TEST(TraceBuilder, APathBecomesATraceThatReplays) {
  Fixture f;
  z3::solver s(f.ctx);
  AddWithDefinitions(
      s, *f.enc, f.enc->Initial() && f.enc->State(0) && f.enc->Transition(0) && f.enc->State(1));
  AddWithDefinitions(s, *f.enc, f.enc->Holds(Compare(f.system, "x", Relation::kGreater, 2.5), 0));
  AddWithDefinitions(s, *f.enc, f.enc->Holds(Compare(f.system, "x", Relation::kGreater, 4.5), 1));
  ASSERT_EQ(s.check(), z3::sat);
  const z3::model model = s.get_model();
  const auto path = f.enc->ReadPath(model, 1);
  ASSERT_TRUE(path[0].flow);
  TraceBuilder builder(f.system, f.job, *f.enc);
  std::optional<Trace> trace = builder.Build(model, path);
  ASSERT_TRUE(trace.has_value());
  EXPECT_EQ(trace->initial_states, (std::vector<std::pair<int, int>>{{0, 1}}));
  ASSERT_EQ(trace->initial_values.size(), 1u);
  EXPECT_EQ(trace->initial_values[0].first, "x");
  EXPECT_EQ(trace->initial_values[0].second, path[0].x[0]);
  // The flow, then a tail of 1e-6 of it with the input held.
  EXPECT_DOUBLE_EQ(trace->inputs.until, path[0].duration * (1 + 1e-6));
  ASSERT_EQ(trace->inputs.inputs.size(), 1u);
  const InputSignal& u = trace->inputs.inputs[0];
  EXPECT_EQ(u.slot, f.system.symbols().Find("u").value());
  EXPECT_EQ(u.shape, InputSignal::Shape::kStep);
  ASSERT_FALSE(u.points.empty());
  EXPECT_EQ(u.points[0], (std::pair<double, double>{0.0, path[0].input[0]}));
  EXPECT_TRUE(ReplayTrace(f.system, f.system.properties()[0], *trace));
}

TEST(TraceBuilder, APathFromNoInitialStateHasNoTrace) {
  Fixture f;
  z3::solver s(f.ctx);
  AddWithDefinitions(s, *f.enc, f.enc->State(0));
  AddWithDefinitions(s, *f.enc, f.enc->Holds(Compare(f.system, "x", Relation::kGreater, 10), 0));
  ASSERT_EQ(s.check(), z3::sat);
  const z3::model model = s.get_model();
  TraceBuilder builder(f.system, f.job, *f.enc);
  EXPECT_FALSE(builder.Build(model, f.enc->ReadPath(model, 0)).has_value());
}

}  // namespace
}  // namespace hybrid
