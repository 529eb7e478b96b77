// Tests of the flowpipe engine's compiled model (solvers/flowpipe/flowpipe_model.h): which
// comparisons it reads through their affine forms, and the affine-arithmetic value of a reset.
#include "solvers/flowpipe/flowpipe_model.h"

#include <gtest/gtest.h>

#include "hybrid/automaton/parser.h"

namespace hybrid::flowpipe_internal {
namespace {

System Load(const std::string& text) { return ParseModel(text, "test.ha"); }

// A comparison is read through its affine form only when the form's coefficients are the
// expression's exactly: (x + y) / 3 has the rounded 1/3, so it is read by intervals alone.
TEST(FlowpipeModel, AffineFormsOnlyWithExactCoefficients) {
  const System s = Load(R"(automaton a {
  var x in [0, 10];
  var y in [0, 10];
  mode m { x' = 1; inv (x + y) / 3 <= 1 and 0.5 * x + y / 4 <= 2 and 2 * (x - 0.1) <= 3 and 2 * (x - 0.5) <= 3; }
  init m { x = 0; y = 0; }
})");
  FlowpipeModel model(s);
  const int mode = model.Initials().at(0).mode;
  const auto& invariant = model.Mode(mode).invariant;
  ASSERT_EQ(invariant.size(), 4u);
  EXPECT_FALSE(invariant[0].affine.has_value());
  ASSERT_TRUE(invariant[1].affine.has_value());
  EXPECT_EQ(invariant[1].affine->terms.size(), 2u);
  // 2 (x - 0.1) - 3: the constant 2 * 0.1 + 3 is rounded in binary floating point.
  EXPECT_FALSE(invariant[2].affine.has_value());
  // 2 (x - 0.5) - 3: every coefficient exact.
  ASSERT_TRUE(invariant[3].affine.has_value());
  EXPECT_EQ(invariant[3].affine->constant, -4.0);
}

// A reset mixing two variables keeps their correlation in affine arithmetic: v := v - w over
// forms v = 1 + e0, w = 1 + e0 is exactly 0, while the interval value is [-2, 2].
TEST(FlowpipeModel, FormValueKeepsCorrelations) {
  const System s = Load(R"(automaton a {
  var v in [-10, 10];
  var w in [-10, 10];
  mode m { v' = 0; w' = 0; }
  transition j: m -> m { guard v >= 5; reset v := v - w, w := (v + w) / 3; }
  init m { v = 0; w = 0; }
})");
  FlowpipeModel model(s);
  const int mode = model.Initials().at(0).mode;
  model.MakeJumps(mode);
  const auto& jump = model.Mode(mode).jumps.at(0);
  ASSERT_EQ(jump.resets.size(), 2u);
  const std::vector<AffineForm> x = {AffineForm::Symbol(1.0, 0, 1.0),
                                     AffineForm::Symbol(1.0, 0, 1.0)};
  const std::vector<TightInterval> box = {TightInterval(0.0, 2.0), TightInterval(0.0, 2.0)};
  for (const auto& [component, value] : jump.resets) {
    const AffineForm f = model.FormValue(value, x, model.Mode(mode).env);
    const TightInterval interval = model.Value(value, box, model.Mode(mode).env);
    if (component == 0) {
      EXPECT_EQ(f.Range().lo, 0.0);
      EXPECT_EQ(f.Range().hi, 0.0);
      EXPECT_EQ(interval.lo, -2.0);
    } else {
      // (v + w) / 3 = 2/3 (1 + e0): the rounding of 1/3 goes into the error term.
      EXPECT_TRUE(f.Range().Contains(TightInterval(0.0, 4.0 / 3)));
      EXPECT_NEAR(f.coefficient(0), 2.0 / 3, 1e-15);
      EXPECT_LT(f.err(), 1e-15);
    }
  }
}

}  // namespace
}  // namespace hybrid::flowpipe_internal
